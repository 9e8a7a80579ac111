#pragma once
/// @file The contacts of a case on several MPI ranks divided in horizontal bands
/// (dem/parallel/README.md): the ContactSplit of MoreauJean::use_split on each rank.

#include "dem/engine/contact_split.h"
#include "dem/parallel/band_partition.h"
#include "dem/parallel/grain_ownership.h"

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
  /// - while a rank holds its share (Share::own), the state is split too (GrainOwnership,
  ///   with the margin given): the rank owns the grains of its band and holds its ghosts,
  ///   its copies of the other grains stale (their discs' heights NaN in own_band(), so that
  ///   no pair of theirs is found); the whole state is gathered (make_whole()) before every
  ///   pair is detected;
  /// - with fewer than min_contacts_per_rank contacts per rank, every rank holds every
  ///   contact and body (Share::whole), and the next step detects every pair again.
  /// Sums over the ranks are reduced on rank 0 and broadcast, so that every rank has the
  /// same bits (an all-reduce may add in a different order on each).
  class BandSplit : public ContactSplit
  {
  public:
    static constexpr unsigned int min_contacts_per_rank = 64;

    /// Collective over @p comm; @p margin (m): how far beyond its band a rank holds grains
    /// (GrainOwnership); @p rebalance_at > 1.
    BandSplit(MPI_Comm comm, double margin, double rebalance_at = 1.05);

    std::optional<PairBand> own_band(const ParticleSystem &system) override;
    Share                   divide(const ParticleSystem &system, std::vector<Contact> &pairs, bool all) override;
    bool keeps_boundary_contacts() const override { return rank + 1 == ranks; }
    void sum(double *values, std::size_t n) const override;
    void min(double *values, std::size_t n) const override;
    std::vector<KeyedImpulse> all_gathered(const std::vector<KeyedImpulse> &mine) const override;
    const std::vector<unsigned int> *held() const override { return ownership ? &ownership->held() : nullptr; }
    bool holds(unsigned int body) const override { return !ownership || ownership->holds(body); }
    bool advances(unsigned int body) const override { return !ownership || ownership->advances(body); }
    bool counts(unsigned int body) const override { return !ownership || ownership->counts(body); }
    void sum_on_owners(std::vector<Eigen::Vector3d> &force) const override { ownership->sum_on_owners(force); }
    const std::vector<unsigned int> &send_states(ParticleSystem &system) override { return ownership->send_states(system); }
    void settle(const ParticleSystem &system) override { ownership->settle(system); }
    void make_whole(ParticleSystem &system) const override;
    void keep() override;
    void go_back() override;
    /// The grains' owners while the state is split (nullptr: whole).
    const GrainOwnership *grain_ownership() const { return ownership ? &*ownership : nullptr; }

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
    /// Who owns and holds which grain while this rank holds a share (Share::own); its margin:
    /// 2 r_max + the detection distance beyond the band (a pair's reach from its midpoint,
    /// with the disc motions' widening) plus r_max for a step's motion.
    std::optional<GrainOwnership> ownership;
    double                        margin;
    /// keep()'s copy of the partition, the ownership and the last share.
    struct Kept
    {
      std::optional<BandPartition>  partition;
      std::optional<GrainOwnership> ownership;
      Share                         last;
    };
    std::optional<Kept> kept;
    std::vector<double>          heights; ///< of the discs at the last own_band() or recut, m
    Share                        last   = Share::whole;
    unsigned long                n_cuts = 0;
  };
} // namespace tribo::dem::parallel
