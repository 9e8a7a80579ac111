// The own Delassus block of a contact and the exchange of impulses through
// body velocities, against a dense W = H^T M^-1 H.
#include "dem/solvers/nlgs.h"
#include "dem/engine/moreau_jean.h"

#include <Eigen/Dense>

#include <gtest/gtest.h>

#include <random>

using namespace tribo::dem;

namespace
{
  /// Dense H^T (2 x 3 nb) of contact c: rows n and t, columns (vx, vy, w) per body.
  Eigen::MatrixXd dense_HT(const Contact &c, std::size_t nb)
  {
    Eigen::MatrixXd HT = Eigen::MatrixXd::Zero(2, 3 * nb);
    const Vec2      t(-c.normal.y(), c.normal.x());
    for (int s = 0; s < 2; ++s)
      {
        const double sign = s == 0 ? -1 : 1;
        const auto   b    = 3 * c.body[s];
        HT(0, b) += sign * c.normal.x();
        HT(0, b + 1) += sign * c.normal.y();
        HT(0, b + 2) += sign * c.arm_n[s];
        HT(1, b) += sign * t.x();
        HT(1, b + 1) += sign * t.y();
        HT(1, b + 2) += sign * c.arm_t[s];
      }
    return HT;
  }

  Eigen::MatrixXd dense_inverse_mass(const BodyState &s)
  {
    const std::size_t nb = s.inverse_mass.size();
    Eigen::MatrixXd   M  = Eigen::MatrixXd::Zero(3 * nb, 3 * nb);
    for (std::size_t b = 0; b < nb; ++b)
      for (int k = 0; k < 3; ++k)
        M(3 * b + k, 3 * b + k) = s.inverse_mass[b][k];
    return M;
  }

  /// A free disc, a clump of three discs and a fixed wall clump, touching.
  struct Scene
  {
    ParticleSystem       system;
    std::vector<Contact> contacts;
    BodyState            state;

    Scene()
    {
      const double r = 0.5e-6, rho = 7800;
      system.add_disc({0.0, 0.0}, r, rho);
      system.add_clump({{1.0e-6, 0.3e-6}, {1.9e-6, 0.1e-6}, {1.5e-6, 0.9e-6}}, {r, 0.6e-6, 0.4e-6}, rho);
      system.add_clump({{-0.2e-6, -1.0e-6}, {0.8e-6, -1.0e-6}}, {r, r}, rho);
      for (auto &d : system.bodies[2].drive)
        d = Drive::velocity;
      system.bodies[1].angle = 0.05;
      MoreauJean mj(0.5, ContactLaw{}, SolverParameters{}, 0.5e-6);
      mj.step(system, 1e-12); // builds the contacts with their arms
      contacts = mj.contacts();
      state    = BodyState::of(system);
    }
  };
} // namespace

TEST(Delassus, OwnBlocksEqualTheDenseOperator)
{
  Scene s;
  ASSERT_GE(s.contacts.size(), 3u); // disc-clump, disc-wall, clump-wall
  const auto Minv = dense_inverse_mass(s.state);
  bool disc_clump = false, disc_wall = false;
  for (const auto &c : s.contacts)
    {
      const auto            HT    = dense_HT(c, s.system.bodies.size());
      const Eigen::MatrixXd dense = HT * Minv * HT.transpose();
      const Eigen::Matrix2d own   = s.state.delassus_block(c);
      EXPECT_LT((dense - own).norm(), 1e-12 * dense.norm());
      disc_clump |= (c.body[0] == 0 && c.body[1] == 1);
      disc_wall |= (c.body[0] == 0 && c.body[1] == 2) || (c.body[0] == 2 && c.body[1] == 0);
    }
  EXPECT_TRUE(disc_clump);
  EXPECT_TRUE(disc_wall);
}

TEST(Delassus, ImpulsesExchangeThroughBodiesLikeTheOffDiagonalBlocks)
{
  Scene s;
  const std::size_t nb   = s.system.bodies.size();
  const auto        Minv = dense_inverse_mass(s.state);
  std::mt19937      rng(3);
  std::normal_distribution<double> n01;
  for (std::size_t a = 0; a < s.contacts.size(); ++a)
    for (std::size_t b = 0; b < s.contacts.size(); ++b)
      {
        BodyState             st = s.state;
        const Eigen::Vector2d before = st.local_velocity(s.contacts[a]);
        const Eigen::Vector2d r(n01(rng) * 1e-9, n01(rng) * 1e-9);
        st.apply_impulse(s.contacts[b], r);
        const Eigen::Vector2d change = st.local_velocity(s.contacts[a]) - before;
        const Eigen::MatrixXd W_ab   = dense_HT(s.contacts[a], nb) * Minv *
                                     dense_HT(s.contacts[b], nb).transpose();
        EXPECT_LT((change - W_ab * r).norm(), 1e-12 * (W_ab * r).norm() + 1e-300);
      }
}
