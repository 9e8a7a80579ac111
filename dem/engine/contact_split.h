#pragma once
/// @file How the contacts and the bodies of a step are divided among the processes that run
/// one case together (a case on several MPI ranks: dem/parallel/band_split.h). MoreauJean
/// without a split holds every contact and body. With one, each process searches, solves
/// and measures only its own share of the contacts; while it holds a share (Share::own) the
/// state is split too: it advances only the bodies it owns (its grains, and the replicated
/// walls), holds current copies of the grains near its share (ghosts), and its copies of
/// the other grains are stale until make_whole().

#include "dem/engine/contact.h"
#include "dem/engine/particle_system.h"

#include <Eigen/Core>

#include <cstdint>
#include <optional>
#include <vector>

namespace tribo::dem
{
  /// A contact's warm-start impulse as sent between processes: its key (Contact::key()) and
  /// (r_n, r_t), N s/m.
  struct KeyedImpulse
  {
    std::uint64_t key;
    double        r[2];
  };

  class ContactSplit
  {
  public:
    virtual ~ContactSplit() = default;

    /// What divide() made of a step's contacts.
    enum class Share
    {
      own,       ///< this process holds its share; the others, theirs
      whole,     ///< every process holds every contact (too few to divide)
      search_all ///< the share could not be kept: detect every pair and divide again
    };

    /// The pairs this process owns this step, by their midpoints' heights in @p system
    /// (ContactDetector::detect keeps only those); nothing: not known yet, detect every pair.
    virtual std::optional<PairBand> own_band(const ParticleSystem &system) = 0;
    /// Collective. @p pairs: the disc pairs of own_band() (with @p all, every pair, the same
    /// on every process); keeps this process's share of them and says what it did. With
    /// Share::search_all, @p pairs is left as it was.
    virtual Share divide(const ParticleSystem &system, std::vector<Contact> &pairs, bool all) = 0;
    /// With Share::own: whether this process keeps the half-disc contacts (one process
    /// holds them all: a deformable body's compliance couples them).
    virtual bool keeps_boundary_contacts() const = 0;

    /// Collective: @p values (@p n) summed over the processes, the same bits on every one.
    virtual void sum(double *values, std::size_t n) const = 0;
    /// Collective: the least of @p values (@p n) over the processes.
    virtual void min(double *values, std::size_t n) const = 0;
    /// Collective: every process's @p mine, on every process.
    virtual std::vector<KeyedImpulse> all_gathered(const std::vector<KeyedImpulse> &mine) const = 0;

    /// The bodies this process holds current while the state is split (owned and ghost
    /// grains, the replicated bodies), in serial order; nullptr: the state is whole.
    virtual const std::vector<unsigned int> *held() const = 0;
    /// With a split state: whether this process holds @p body current, whether it advances it
    /// (a grain it owns, or a replicated body), and whether it counts it in sums over the
    /// processes (a grain it owns, a replicated body on one process).
    virtual bool holds(unsigned int body) const    = 0;
    virtual bool advances(unsigned int body) const = 0;
    virtual bool counts(unsigned int body) const  = 0;
    /// Collective, with a split state: @p force (one entry per body) summed where each body
    /// is advanced (a ghost's entry added to its owner's, a replicated body's over the processes).
    virtual void sum_on_owners(std::vector<Eigen::Vector3d> &force) const = 0;
    /// Collective, with a split state, after the owners advanced their bodies: their states to
    /// the processes that hold them, or will; the bodies whose state this process received.
    virtual const std::vector<unsigned int> &send_states(ParticleSystem &system) = 0;
    /// With a split state, once a step stands: the grains owned and held again from their
    /// new places (a grain that crossed into another process's share is owned there).
    virtual void settle(const ParticleSystem &system) = 0;
    /// Collective: every body's current state on every process (for the outputs, a
    /// checkpoint, or before every pair is detected); a split state stays split.
    virtual void make_whole(ParticleSystem &system) const = 0;
    /// What a step taken again needs: keep() the split's state at the step's start, go_back() to it.
    virtual void keep()    = 0;
    virtual void go_back() = 0;
  };
} // namespace tribo::dem
