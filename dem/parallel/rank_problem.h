#pragma once
/// @file One rank's share of a step's contact problem under horizontal bands
/// (dem/parallel/README.md): the contacts it owns, its own grains, the ghost grains its
/// contacts touch and the replicated bodies (the walls).

#include "dem/engine/body_state.h"
#include "dem/engine/contact.h"
#include "dem/engine/particle_system.h"
#include "dem/parallel/band_partition.h"
#include "dem/parallel/grain_ownership.h"

#include <cstdint>
#include <vector>

namespace tribo::dem::parallel
{
  /// The contacts a rank owns and the bodies they act on, numbered locally.
  ///
  /// Grains (bodies of one disc) are owned by the band of their centre's height and
  /// numbered globally band by band (band 0's grains first, each band's in serial order),
  /// so that each rank owns one contiguous range, as deal.II's partitioner wants. A contact
  /// is owned by the band of the midpoint of its two discs' centres, which is the band of
  /// one of its grains. Clumps (the walls: a few degrees of freedom) are replicated on
  /// every rank. The half-disc contacts of the deformable first bodies all belong to the
  /// top band, whose rank alone holds the bodies' node velocities and compliance (the
  /// contacts couple through it); their unused side 0 names their grain.
  struct RankProblem
  {
    /// The owned contacts in serial (detection) order, their bodies numbered locally.
    std::vector<Contact> contacts;
    /// Local bodies: owned grains (by global number), ghost grains (by global number),
    /// replicated bodies (in serial order). Velocities m/s and rad/s.
    BodyState    state;
    unsigned int n_owned = 0, n_ghost = 0;
    /// Serial index of each local body and of each owned contact.
    std::vector<unsigned int> serial_body, serial_contact;
    /// Local number of each serial body that is a local body (undefined for the others).
    std::vector<unsigned int> local_body;
    /// Global number of each owned and ghost grain (local bodies 0 .. n_owned + n_ghost).
    std::vector<std::uint64_t> global_grain;
    std::uint64_t              n_grains = 0; ///< grains on all ranks

    unsigned int n_replicated() const { return static_cast<unsigned int>(serial_body.size()) - n_owned - n_ghost; }
  };

  /// The height of disc @p d's centre, m (a grain's: its body's position).
  double disc_height(const ParticleSystem &system, unsigned int d);
  /// The height of each disc's centre, m (a grain's: its body's position).
  std::vector<double> disc_heights(const ParticleSystem &system);
  /// The height of each contact's midpoint between its two disc centres (a half-disc
  /// contact's: its grain's centre), m.
  std::vector<double> contact_heights(const ParticleSystem &system, const std::vector<Contact> &contacts);
  /// Bands of equal contact counts for @p n ranks, by the contacts' midpoint heights.
  BandPartition contact_bands(const ParticleSystem &system, const std::vector<Contact> &contacts, unsigned int n);

  /// Rank @p rank's share of the serial problem @p contacts on @p state (a BodyState over
  /// @p system's bodies, consistent with the contacts' impulses) under @p bands. Every rank
  /// calls it with the same serial problem.
  RankProblem share_of(const ParticleSystem &system, const std::vector<Contact> &contacts, const BodyState &state,
                       const BandPartition &bands, unsigned int rank);
  /// The same, with the contacts' @p heights (contact_heights) already computed.
  RankProblem share_of(const ParticleSystem &system, const std::vector<Contact> &contacts,
                       const std::vector<double> &heights, const BodyState &state, const BandPartition &bands,
                       unsigned int rank);
  /// Rank @p rank's problem of its own @p contacts (all of them in its band: a step held in
  /// shares, dem/parallel/band_split.h), which it takes over without a copy (@p contacts is
  /// left empty); give_back() returns them, with their impulses, in serial numbers.
  /// With @p ownership (a split state, dem/parallel/grain_ownership.h), the grains' owners
  /// and global numbers are its own: this rank's copies of the grains it does not hold are stale.
  RankProblem own_share(const ParticleSystem &system, std::vector<Contact> &contacts, const BodyState &state,
                        const BandPartition &bands, unsigned int rank, const GrainOwnership *ownership = nullptr);
  /// @p p's contacts back into @p contacts (the one own_share() emptied), their bodies in
  /// serial numbers (a half-disc contact's unused side 0 naming its grain).
  void give_back(RankProblem &p, std::vector<Contact> &contacts);
} // namespace tribo::dem::parallel
