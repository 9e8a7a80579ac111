#pragma once
/// @file Contacts between discs of different bodies and their detection.

#include "dem/engine/particle_system.h"

#include <Eigen/Core>

#include <cstdint>
#include <optional>
#include <vector>

namespace tribo::dem
{
  /// A contact (or near contact) between disc 0 and disc 1 of two bodies, in
  /// the frame of contact_law.h: normal n from disc 0 to disc 1, t = (-n_y, n_x).
  struct Contact
  {
    unsigned int disc[2] = {0, 0};
    unsigned int body[2] = {0, 0};
    Vec2   normal = Vec2::Zero(); ///< unit normal, disc 0 -> disc 1
    Vec2   branch = Vec2::Zero(); ///< centre of disc 1 minus centre of disc 0 (periodic image), m
    double gap    = 0;            ///< at the predicted configuration, m (negative: overlap)
    /// Moment arms of the unit normal and tangent about each body centre,
    /// (contact point - body centre) x n and x t, m. They make the rows of H:
    /// u = H_1^T qdot_1 - H_0^T qdot_0 with H_b^T = [n^T, an_b; t^T, at_b].
    double arm_n[2] = {0, 0}, arm_t[2] = {0, 0};
    Eigen::Matrix2d W      = Eigen::Matrix2d::Zero(); ///< own Delassus block sum_b H_b^T M_b^-1 H_b, m/s per N s/m
    Eigen::Vector2d r      = Eigen::Vector2d::Zero(); ///< impulse, N s/m
    Eigen::Vector2d u_free = Eigen::Vector2d::Zero(); ///< local velocity of the free motion (no impulses), m/s
    double cohesion_impulse = 0, shift = 0, compliance = 0; ///< law terms (ContactLaw::Terms)
    /// Against a half-disc element of a BoundaryBody (dem/engine/boundary.h): its index, else -1.
    /// Side 0 is then the half-disc, a rigid body carried by the chain edge that holds
    /// its anchor (nodes node[0] = A, node[1] = B) of boundary body @p boundary_body. With
    /// several bodies attached to a MoreauJean, their half-discs and nodes are numbered one
    /// body after another (BodyState::node_blocks). The velocity of its material point at
    /// the contact point is v_P = J_A v_A + J_B v_B with J = node_map (2x2, the centre's
    /// interpolation plus the edge's rotation, dem/engine/boundary.h); an impulse r on the grain
    /// puts -J_A^T f and -J_B^T f (f = r_n n + r_t t) on the nodes. body[0] and the
    /// side-0 arms are unused.
    int             half_disc = -1;
    unsigned int    boundary_body = 0;
    unsigned int    node[2]   = {0, 0};
    Eigen::Matrix2d node_map[2] = {Eigen::Matrix2d::Zero(), Eigen::Matrix2d::Zero()};

    bool on_boundary() const { return half_disc >= 0; }

    /// Key of the disc pair (smaller index first), or of the half-disc and the disc,
    /// for warm starts.
    std::uint64_t key() const
    {
      if (on_boundary())
        return (std::uint64_t(1) << 63) | (std::uint64_t(half_disc) << 32) | disc[1];
      return (std::uint64_t(disc[0]) << 32) | disc[1];
    }
  };

  /// The pairs whose midpoint lies in [lowest, highest): the mean of the two discs' @p heights
  /// (m, one per disc).
  struct PairBand
  {
    double                     lowest, highest;
    const std::vector<double> *heights;

    bool holds(unsigned int i, unsigned int j) const
    {
      const double y = 0.5 * ((*heights)[i] + (*heights)[j]);
      return y >= lowest && y < highest;
    }
  };

  /// Cell-list detection of disc pairs closer than a detection distance,
  /// linear in the number of discs, with minimum-image pairs across an
  /// x-periodic boundary. Discs of the same body are never paired.
  class ContactDetector
  {
  public:
    /// Contacts (geometry only) for disc centres @p centres (already wrapped
    /// into [0, period) if periodic) with gap <= @p distance. With @p threads > 1
    /// the rows of cells are searched in 4 @p threads chunks concurrently (TBB through
    /// deal.II); the contacts and their order do not depend on @p threads.
    ///
    /// With @p motion (one vector per disc, m: how far its centre may move before the next
    /// detection), a pair further apart than @p distance is a contact too when that motion
    /// closes it: gap <= -(motion_j - motion_i).n, n the unit normal from i to j. Fast
    /// discs then meet their new neighbours as contacts with a positive gap, which the laws
    /// close exactly, instead of passing into them undetected (docs/laws.md, "Detection"),
    /// as long as the relative motion is at most max_motion_reach largest radii.
    /// Into @p contacts (cleared; its capacity is kept, so that a caller detecting every
    /// step does not allocate and fault in tens of MB of fresh pages each time at 64 000 grains).
    /// With @p band, only the pairs whose midpoint height lies in it (a process's share of a
    /// case on several MPI ranks, dem/engine/contact_split.h), searched in the rows of cells
    /// within one cell of the band (at @p centres; the band's heights may be taken elsewhere,
    /// e.g. at the start of the step: a pair is found unless its discs moved by more than a
    /// cell in between).
    void detect(const ParticleSystem &system, const std::vector<Vec2> &centres, double distance,
                unsigned int threads, const std::vector<Vec2> &motion, std::vector<Contact> &contacts,
                const std::optional<PairBand> &band = std::nullopt);
    /// The same, returned.
    std::vector<Contact> detect(const ParticleSystem &system, const std::vector<Vec2> &centres,
                                double distance, unsigned int threads = 1,
                                const std::vector<Vec2> &motion = {})
    {
      std::vector<Contact> contacts;
      detect(system, centres, distance, threads, motion, contacts);
      return contacts;
    }
    /// The motions widen the cells by at most this many largest radii (at most twice the
    /// cells without motion, four times the candidate pairs); pairs closed by a larger
    /// relative motion are not looked for.
    static constexpr double max_motion_reach = 2;

  private:
    std::vector<unsigned int>         cell_start, cell_items, cell_of;
    std::vector<std::vector<Contact>> chunk_contacts; ///< the threads' chunks, kept between calls
  };
} // namespace tribo::dem
