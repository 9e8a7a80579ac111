#pragma once
/// @file How the contacts of a step are divided among the processes that run one case
/// together (a case on several MPI ranks: dem/parallel/band_split.h). MoreauJean without a
/// split holds every contact. With one, each process keeps the bodies whole (every process
/// updates every body, from the contact forces summed over the processes, so that their
/// states stay the same bits), but searches, solves and measures only its own share of the
/// contacts.

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
  };
} // namespace tribo::dem
