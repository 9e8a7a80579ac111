#pragma once
/// @file Verlet neighbour list built with cell lists (cost linear in N).

#include "mlp/particles.h"

#include <utility>
#include <vector>

namespace tribo::mlp
{
  /// All pairs (i < j) closer than cutoff + skin when the list was built, found
  /// by binning the particles into cells of side >= cutoff + skin (in the
  /// sheared frame x - tilt y/ly for a tilted periodic box) and testing the 3x3
  /// neighbouring cells. The list stays valid while no pair separation can have
  /// changed by more than the skin: it is rebuilt when
  /// 2 max_i |x_i - x_i(build)| + |change of lx, ly, tilt| > skin.
  ///
  /// Also keeps, per particle, the pairs it belongs to (incidence lists) so that
  /// forces can be gathered per particle without a racing scatter.
  class NeighbourList
  {
  public:
    /// One incidence: pair index and the sign of its force on this particle
    /// (+1 for the first particle of the pair, -1 for the second).
    struct Incidence
    {
      unsigned int pair;
      int          sign;
      /// Boost.Serialization, either direction.
      template <class Archive>
      void serialize(Archive &ar, const unsigned int /*version*/)
      {
        ar &pair &sign;
      }
    };

    /// A list for interactions of range @p cutoff (m) with Verlet skin @p skin (m).
    NeighbourList(double cutoff, double skin);

    /// Builds the list now. Throws InputError if a periodic length is shorter
    /// than 2 (cutoff + skin) (the minimum image would not be unique).
    void build(const Particles &particles, const Box &box);
    /// True if the skin criterion (see class documentation) asks for a rebuild,
    /// or if the number of particles changed.
    bool needs_rebuild(const Particles &particles, const Box &box) const;
    /// Rebuilds if needed; returns true if it did.
    bool update(const Particles &particles, const Box &box);

    /// Candidate pairs (i, j), i < j.
    const std::vector<std::pair<unsigned int, unsigned int>> &pairs() const { return pair_list; }
    /// Incidences of particle @p i: [begin, end).
    const Incidence *incidence_begin(unsigned int i) const
    {
      return incidences.data() + incidence_offset[i];
    }
    /// End of the incidences of particle @p i.
    const Incidence *incidence_end(unsigned int i) const
    {
      return incidences.data() + incidence_offset[i + 1];
    }
    /// Number of builds so far.
    unsigned int n_builds() const { return builds; }
    /// Interaction range, m.
    double cutoff() const { return range; }
    /// Verlet skin, m.
    double skin() const { return skin_width; }
    /// Checkpoint: the pairs in their order, the incidences and the positions and box of
    /// the last build (a list rebuilt at another time would sum the forces in another order).
    void save(CheckpointOut &ar) const;
    void load(CheckpointIn &ar);

  private:
    double                                             range;
    double                                             skin_width;
    std::vector<std::pair<unsigned int, unsigned int>> pair_list;
    std::vector<unsigned int>                          incidence_offset;
    std::vector<Incidence>                             incidences;
    std::vector<Vec2>                                  build_positions;
    Box                                                build_box;
    unsigned int                                       builds = 0;
  };
} // namespace tribo::mlp
