#pragma once
/// @file The bodies' velocities and inverse masses as the contact solve sees them, with the
/// local velocity of a contact (u = H^T v), the application of an impulse (v += M^-1 H dr)
/// and a contact's own Delassus block.

#include "dem/engine/contact.h"
#include "dem/engine/particle_system.h"

#include <Eigen/Core>

#include <array>
#include <vector>

namespace tribo::dem
{
  /// Velocities and inverse masses of the bodies as the solver sees them:
  /// (v_x, v_y, spin) and (1/m, 1/m, 1/I), with 0 for imposed-velocity dofs.
  struct BodyState
  {
    std::vector<Eigen::Vector3d>       velocity;
    std::vector<std::array<double, 3>> inverse_mass;
    /// Velocities of the boundary nodes of the attached BoundaryBody's (dem/engine/boundary.h),
    /// the bodies' nodes one after another (2 per node: x, y), m/s; empty without one.
    Eigen::VectorXd node_velocity;
    /// Where one BoundaryBody's nodes are in node_velocity: from node @p first_node on, as
    /// many as its compliance G has node pairs of rows (2n x 2n, m/s per N s/m). Two bodies'
    /// nodes are coupled only through the grains, so the compliance of all the nodes over a
    /// step is block-diagonal, one block per body: Contact::boundary_body indexes them.
    struct NodeBlock
    {
      unsigned int           first_node = 0;
      const Eigen::MatrixXd *compliance = nullptr;
    };
    std::vector<NodeBlock> node_blocks;

    /// The 2x2 compliance between nodes @p a and @p b (indices into node_velocity's nodes) of
    /// boundary body @p body: the velocity change of node a per unit impulse on node b.
    Eigen::Matrix2d node_compliance(unsigned int body, unsigned int a, unsigned int b) const
    {
      const NodeBlock &block = node_blocks[body];
      return block.compliance->block<2, 2>(2 * (a - block.first_node), 2 * (b - block.first_node));
    }

    /// The current velocities and inverse masses of @p system's bodies (no boundary body).
    static BodyState of(const ParticleSystem &system)
    {
      BodyState state;
      for (const auto &b : system.bodies)
        {
          state.velocity.push_back({b.velocity.x(), b.velocity.y(), b.spin});
          state.inverse_mass.push_back(b.inverse_mass());
        }
      return state;
    }

    /// Local velocity of contact @p c from the current body velocities.
    Eigen::Vector2d local_velocity(const Contact &c) const
    {
      if (c.on_boundary())
        return boundary_local_velocity(c);
      const Eigen::Vector3d &v0 = velocity[c.body[0]], &v1 = velocity[c.body[1]];
      const Vec2             t(-c.normal.y(), c.normal.x());
      return {c.normal.dot(v1.head<2>() - v0.head<2>()) + c.arm_n[1] * v1.z() - c.arm_n[0] * v0.z(),
              t.dot(v1.head<2>() - v0.head<2>()) + c.arm_t[1] * v1.z() - c.arm_t[0] * v0.z()};
    }

    /// Apply impulse @p dr of contact @p c: v_1 += M_1^-1 H_1 dr, v_0 -= M_0^-1 H_0 dr.
    void apply_impulse(const Contact &c, const Eigen::Vector2d &dr)
    {
      if (c.on_boundary())
        return apply_boundary_impulse(c, dr);
      const Vec2 t(-c.normal.y(), c.normal.x());
      const Vec2 f = dr.x() * c.normal + dr.y() * t;
      for (int s = 0; s < 2; ++s)
        {
          const double           sign = s == 0 ? -1.0 : 1.0;
          const auto            &im   = inverse_mass[c.body[s]];
          Eigen::Vector3d       &v    = velocity[c.body[s]];
          v.x() += sign * im[0] * f.x();
          v.y() += sign * im[1] * f.y();
          v.z() += sign * im[2] * (c.arm_n[s] * dr.x() + c.arm_t[s] * dr.y());
        }
    }

    /// The own Delassus block of @p c, sum over its two bodies of H^T M^-1 H (for a
    /// half-disc contact: the grain's part plus B^T G_AB B, with B the 4x2 map from
    /// (r_n, r_t) to the impulses -J_A^T f, -J_B^T f on its two nodes, dem/engine/boundary.h).
    Eigen::Matrix2d delassus_block(const Contact &c) const;

    /// Side 0 of a half-disc contact: velocity of the half-disc's material point at the
    /// contact point, J_A v_A + J_B v_B (Contact::node_map), m/s.
    Vec2 half_disc_velocity(const Contact &c) const
    {
      return c.node_map[0] * node_velocity.segment<2>(2 * c.node[0]) +
             c.node_map[1] * node_velocity.segment<2>(2 * c.node[1]);
    }

  private:
    Eigen::Vector2d boundary_local_velocity(const Contact &c) const;
    void            apply_boundary_impulse(const Contact &c, const Eigen::Vector2d &dr);
  };
} // namespace tribo::dem
