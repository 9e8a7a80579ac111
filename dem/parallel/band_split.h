#pragma once
/// @file The contacts of a case on several MPI ranks divided in horizontal bands
/// (dem/parallel/README.md): the ContactSplit of MoreauJean::use_split on each rank.

#include "dem/engine/contact_split.h"
#include "dem/parallel/band_partition.h"

#include <mpi.h>

#include <optional>

namespace tribo::dem::parallel
{
  /// Bands of equal contact counts, kept from step to step and cut again when they drift.
  /// A contact belongs to the band of the midpoint of its discs' centres (contact_heights);
  /// a half-disc contact to the top band. Each step:
  /// - a rank searches only the rows of its band and keeps the pairs whose midpoint lies in
  ///   it (own_band(): the discs' heights, disc_heights());
  /// - the ranks' counts are compared (one MPI_Allgather of a count): when the largest
  ///   exceeds @p rebalance_at times the mean, every rank detects every pair and the bands
  ///   are cut again at the quantiles of the contacts' heights (BandPartition::balanced);
  /// - with fewer than min_contacts_per_rank contacts per rank, every rank holds every
  ///   contact (Share::whole), and the next step detects every pair again.
  /// Sums over the ranks are reduced on rank 0 and broadcast, so that every rank has the
  /// same bits (an all-reduce may add in a different order on each).
  class BandSplit : public ContactSplit
  {
  public:
    static constexpr unsigned int min_contacts_per_rank = 64;

    /// Collective over @p comm; @p rebalance_at > 1.
    explicit BandSplit(MPI_Comm comm, double rebalance_at = 1.05);

    std::optional<PairBand> own_band(const ParticleSystem &system) override;
    Share                   divide(const ParticleSystem &system, std::vector<Contact> &pairs, bool all) override;
    bool keeps_boundary_contacts() const override { return rank + 1 == ranks; }
    void sum(double *values, std::size_t n) const override;
    void min(double *values, std::size_t n) const override;
    std::vector<KeyedImpulse> all_gathered(const std::vector<KeyedImpulse> &mine) const override;

    /// True when the last divide() kept this rank's share (Share::own).
    bool holds_share() const { return last == Share::own; }
    /// The bands of the last divide() that kept shares.
    const BandPartition &bands() const { return *partition; }
    /// How many times the bands were cut, the first time included.
    unsigned long cuts() const { return n_cuts; }
    MPI_Comm      communicator() const { return comm; }

  private:
    MPI_Comm                     comm;
    unsigned int                 rank, ranks;
    double                       rebalance_at;
    std::optional<BandPartition> partition;
    std::vector<double>          heights; ///< of the discs at the last own_band() or recut, m
    Share                        last   = Share::whole;
    unsigned long                n_cuts = 0;
  };
} // namespace tribo::dem::parallel
