#pragma once
/// @file Which rank holds which grain when the state of a case on several MPI ranks is split
/// over them (dem/parallel/README.md): a rank owns the grains whose centre lies in its band,
/// holds as ghosts the grains whose centre lies within a margin of its band, and the walls
/// (clumps: a few degrees of freedom) are replicated. Each rank advances only what it owns;
/// send_states() then sends the owners' states to the ranks that hold them as ghosts, and
/// once the step stands (settle()) a grain that crossed into another band, that band's ghost
/// until then, is owned there (migration: no grain lost or held twice as owned). BandSplit
/// (dem/parallel/band_split.h) keeps one while a rank holds its share of a case's contacts.

#include "dem/engine/particle_system.h"
#include "dem/parallel/band_partition.h"

#include <Eigen/Core>

#include <mpi.h>

#include <cstdint>
#include <utility>
#include <vector>

namespace tribo::dem::parallel
{
  /// Whether each body is a grain (a body of one disc), not a clump (the walls).
  std::vector<bool> grains_of(const ParticleSystem &system);
  class GrainOwnership
  {
  public:
    /// Collective over @p comm. @p margin (m): how far beyond its band a rank holds grains. A
    /// contact belongs to the band of its discs' midpoint, so a rank's contacts reach r_max +
    /// (detection distance) / 2 beyond its band; the margin adds the farthest a grain moves
    /// between two exchanges (a step moves no disc more than r_min / 4: docs/laws.md, "Retakes").
    GrainOwnership(MPI_Comm comm, double margin);

    /// Every rank holds the whole of @p system with the same bits (at the start of a run, or
    /// after gather()): each grain is owned by the band of its centre's height under @p bands
    /// and numbered (global_number()).
    void start(const ParticleSystem &system, const BandPartition &bands);

    /// Collective, after each rank has advanced the grains it owns: each owned grain's state
    /// (position, angle, velocity, spin) goes to the ranks that hold it as a ghost and to every
    /// other rank whose band widened by the margin holds its new centre, which overwrite their
    /// copies. Who owns and holds what is kept (a step that fails its checks is taken again
    /// from its start, with the ownership it started with); the bodies received are returned.
    const std::vector<unsigned int> &send_states(ParticleSystem &system);
    /// Once the step stands: every rank owns the grains it holds or received whose centre
    /// lies in its band, holds those in its widened band, and they are numbered again. A grain
    /// that crossed into another band, that band's ghost until then, is owned there now. The
    /// states of the grains a rank does not hold are left as they were (stale).
    void settle(const ParticleSystem &system);
    /// send_states() and settle().
    void exchange(ParticleSystem &system)
    {
      send_states(system);
      settle(system);
    }

    /// Collective: @p per_body (one entry per body, e.g. the contact forces of this rank's
    /// contacts) summed where each body is advanced: a ghost grain's entry is added to its
    /// owner's and zeroed here; a replicated body's entries are summed over the ranks (reduced
    /// on rank 0 and broadcast: the same bits on every rank).
    void sum_on_owners(std::vector<Eigen::Vector3d> &per_body) const;

    /// Collective: every grain's state from its owner onto every rank (the whole state again,
    /// as at start(), for the outputs; who owns and holds what is kept).
    void gather(ParticleSystem &system) const;

    /// Whether @p body is a grain (a body of one disc), not a replicated clump.
    bool is_grain(unsigned int body) const { return grain[body]; }
    /// Whether this rank owns grain @p body (false for a replicated body).
    bool owns(unsigned int body) const { return grain[body] && held_flag[body] && owner_of[body] == rank; }
    /// Whether this rank advances @p body: a grain it owns, or a replicated body (every rank).
    bool advances(unsigned int body) const { return !grain[body] || owns(body); }
    /// Whether this rank counts @p body in a sum over the ranks: a grain it owns, or a
    /// replicated body on rank 0.
    bool counts(unsigned int body) const { return grain[body] ? owns(body) : rank == 0; }
    /// Whether this rank's copy of @p body is current: an owned or ghost grain, or a replicated body.
    bool holds(unsigned int body) const { return held_flag[body] != 0; }
    /// The rank that owns held grain @p body.
    unsigned int owner(unsigned int body) const { return owner_of[body]; }
    /// The global number of held grain @p body: the grains of band 0 first, each band's in
    /// serial order (each rank owns one contiguous range, as deal.II's partitioner wants).
    std::uint64_t global_number(unsigned int body) const { return global[body]; }
    /// The held bodies in serial order.
    const std::vector<unsigned int> &held() const { return held_bodies; }
    /// The grains this rank owns, in serial order.
    const std::vector<unsigned int> &owned() const { return owned_grains; }
    /// Grains on all ranks.
    std::uint64_t n_grains() const { return total; }
    /// The bands whose band widened by the margin holds height @p y: first to last (this
    /// rank's among them when it holds the grain).
    std::pair<unsigned int, unsigned int> widened_bands(double y) const
    {
      return {bands.band_of(y - margin), bands.band_of(y + margin)};
    }
    /// Whether this rank's band widened by the margin holds height @p y (its own band among it).
    bool in_widened_band(double y) const
    {
      const auto [first, last] = widened_bands(y);
      return first <= rank && rank <= last;
    }

  private:
    MPI_Comm                   comm;
    unsigned int               rank, ranks;
    double                     margin;
    BandPartition              bands;
    std::vector<bool>          grain;        ///< bodies of one disc
    std::vector<char>          held_flag;    ///< per body
    std::vector<unsigned int>  owner_of;     ///< per held grain
    std::vector<std::uint64_t> global;       ///< per held grain
    std::vector<unsigned int>  held_bodies, owned_grains, received;
    /// The ranks each owned grain's state was last sent to, (body, rank) by body: they hold it.
    std::vector<std::pair<unsigned int, unsigned int>> holders;
    std::uint64_t              total = 0;

    /// The owned and held lists from held_flag and owner_of; the owned grains' global
    /// numbers, then the ghosts' from their owners (one message to each rank holding them).
    void number(const ParticleSystem &system);
  };
} // namespace tribo::dem::parallel
