#include "dem/engine/body_state.h"

namespace tribo::dem
{
  Eigen::Vector2d BodyState::boundary_local_velocity(const Contact &c) const
  {
    const Eigen::Vector3d &v1 = velocity[c.body[1]];
    const Vec2             t(-c.normal.y(), c.normal.x());
    const Vec2             dv = v1.head<2>() - half_disc_velocity(c);
    return {c.normal.dot(dv) + c.arm_n[1] * v1.z(), t.dot(dv) + c.arm_t[1] * v1.z()};
  }

  void BodyState::apply_boundary_impulse(const Contact &c, const Eigen::Vector2d &dr)
  {
    const Vec2 t(-c.normal.y(), c.normal.x());
    const Vec2 f = dr.x() * c.normal + dr.y() * t;
    const auto &im = inverse_mass[c.body[1]];
    Eigen::Vector3d &v = velocity[c.body[1]];
    v.x() += im[0] * f.x();
    v.y() += im[1] * f.y();
    v.z() += im[2] * (c.arm_n[1] * dr.x() + c.arm_t[1] * dr.y());
    // The nodes receive -J_A^T f and -J_B^T f: two column pairs of their body's compliance.
    const NodeBlock       &block = node_blocks[c.boundary_body];
    const Eigen::MatrixXd &G     = *block.compliance;
    for (int k = 0; k < 2; ++k)
      node_velocity.segment(2 * block.first_node, G.rows()).noalias() -=
        G.middleCols<2>(2 * (c.node[k] - block.first_node)) * (c.node_map[k].transpose() * f);
  }

  Eigen::Matrix2d BodyState::delassus_block(const Contact &c) const
  {
    const Vec2      t(-c.normal.y(), c.normal.x());
    Eigen::Matrix2d W = Eigen::Matrix2d::Zero();
    if (c.on_boundary())
      {
        // B: (r_n, r_t) -> impulses on the two nodes (4 components).
        Eigen::Matrix<double, 4, 2> B;
        for (int k = 0; k < 2; ++k)
          {
            B.block<2, 1>(2 * k, 0) = -c.node_map[k].transpose() * c.normal;
            B.block<2, 1>(2 * k, 1) = -c.node_map[k].transpose() * t;
          }
        Eigen::Matrix4d G;
        for (int a = 0; a < 2; ++a)
          for (int b = 0; b < 2; ++b)
            G.block<2, 2>(2 * a, 2 * b) = node_compliance(c.boundary_body, c.node[a], c.node[b]);
        W = B.transpose() * G * B;
      }
    for (int s = c.on_boundary() ? 1 : 0; s < 2; ++s)
      {
        const auto &im = inverse_mass[c.body[s]];
        // Columns of H_b: generalized impulse (Fx, Fy, torque) of a unit r_n and r_t.
        const Eigen::Vector3d hn(c.normal.x(), c.normal.y(), c.arm_n[s]);
        const Eigen::Vector3d ht(t.x(), t.y(), c.arm_t[s]);
        const Eigen::Vector3d m(im[0], im[1], im[2]);
        W(0, 0) += hn.cwiseProduct(m).dot(hn);
        W(0, 1) += hn.cwiseProduct(m).dot(ht);
        W(1, 1) += ht.cwiseProduct(m).dot(ht);
      }
    W(1, 0) = W(0, 1);
    return W;
  }
} // namespace tribo::dem
