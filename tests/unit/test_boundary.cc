// Half-disc elements and the BoundaryBody coupling interface (dem/engine/boundary.h),
// against a chain of lumped point masses whose compliance is diagonal.
#include "dem/engine/boundary.h"
#include "dem/engine/moreau_jean.h"
#include "dem/linalg/delassus.h"
#include "tests/unit/lumped_chain.h"

#include <gtest/gtest.h>

#include <random>

using namespace tribo::dem;
using tribo::dem::test::LumpedChain;

namespace
{
  constexpr double L = 8e-6, l = 1e-6, y_face = 5e-6, rho = 7800;

  /// Contacts of one grain of radius r at @p x with half-discs of diameter D on a chain.
  std::vector<Contact> contacts_of_grain(const Vec2 &x, double r, double D, double distance = 1e-7)
  {
    LumpedChain    chain(8, L, y_face, 1e-8);
    ParticleSystem s;
    s.period = L;
    s.add_disc(x, r, rho);
    HalfDiscs hd(chain, D, {0, -1}, L);
    return hd.detect(s, {s.wrap(x)}, {0.0}, chain.x, distance);
  }
} // namespace

TEST(HalfDiscs, PlacementFollowsTheDiameter)
{
  LumpedChain chain(8, L, y_face, 1e-8);
  EXPECT_EQ(HalfDiscs(chain, l, {0, -1}, L).count(), 8u);     // D = l: one per edge
  EXPECT_EQ(HalfDiscs(chain, 2 * l, {0, -1}, L).count(), 4u); // D > l: spans two edges
  EXPECT_EQ(HalfDiscs(chain, 0.5 * l, {0, -1}, L).count(), 16u); // D < l: two per edge
  // D = l: centres at the edge midpoints (node i at i l, edge i ends at node i + 1).
  const auto c = HalfDiscs(chain, l, {0, -1}, L).centres(chain.x);
  EXPECT_NEAR(c[3].x(), 3.5 * l, 1e-18);
  EXPECT_NEAR(c[3].y(), y_face, 1e-18);
}

TEST(HalfDiscs, ContactBelowAnEdgeMidpointSplitsTheForceEvenly)
{
  // Half-disc 2 is centred at x = 2.5 l; a grain straight below it at gap 2e-8.
  const double r = 0.6e-6;
  const auto   cs = contacts_of_grain({2.5 * l, y_face - 0.5 * l - r - 2e-8}, r, l);
  ASSERT_EQ(cs.size(), 1u);
  const Contact &c = cs[0];
  EXPECT_EQ(c.half_disc, 2);
  EXPECT_NEAR(c.gap, 2e-8, 1e-15);
  EXPECT_NEAR(c.normal.y(), -1.0, 1e-12); // from the half-disc to the grain
  EXPECT_EQ(c.node[0], 2u);               // edge 2: nodes 2 and 3
  EXPECT_EQ(c.node[1], 3u);
  // A normal force through the centre has no moment: half of it on each node.
  for (int k = 0; k < 2; ++k)
    EXPECT_NEAR((c.node_map[k].transpose() * c.normal - 0.5 * c.normal).norm(), 0.0, 1e-12);
}

TEST(HalfDiscs, OffCentreContactLoadsTheAnchorEdgeWithForceAndMoment)
{
  // A grain below and to the right of half-disc 1 along 45 degrees, D = 2 l: the
  // half-disc (centre at x = 3 l, anchored on edge 3 at xi = 0) overhangs edges 2 and 3,
  // and its contact point lies above edge 3 at 3.71 l. The force goes to the anchor
  // edge's nodes; they receive the whole force and its moment about the centre.
  const double r = 0.5e-6, D = 2 * l, gap = 1e-8;
  const double a = (0.5 * D + r + gap) / std::sqrt(2.0);
  const auto   cs = contacts_of_grain({3 * l + a, y_face - a}, r, D, 2e-8);
  unsigned     found = 0;
  for (const auto &c : cs)
    if (c.half_disc == 1)
      {
        ++found;
        EXPECT_NEAR(c.gap, gap, 1e-15);
        EXPECT_EQ(c.node[0], 3u);
        EXPECT_EQ(c.node[1], 4u);
        const Vec2 centre(3 * l, y_face), A(3 * l, y_face), B(4 * l, y_face);
        const Vec2 arm = (0.5 * D + 0.5 * gap) * c.normal; // centre -> contact point
        const Vec2 F(0.3, -1.1);                           // a force on the half-disc
        const Vec2 FA = c.node_map[0].transpose() * F, FB = c.node_map[1].transpose() * F;
        EXPECT_NEAR((FA + FB - F).norm(), 0.0, 1e-12);
        EXPECT_NEAR(cross(A - centre, FA) + cross(B - centre, FB), cross(arm, F), 1e-18);
      }
  EXPECT_EQ(found, 1u);
}

TEST(HalfDiscs, DetectedAcrossThePeriodicBoundary)
{
  // A grain at x = 0.05 l touches half-disc 0 (x = 0.5 l) and, across the boundary,
  // half-disc 7 (x = 7.5 l, image at -0.5 l), carried by the wrapping edge 7
  // (node 7 -> node 0).
  const double r = 0.5e-6;
  const auto   cs = contacts_of_grain({0.05 * l, y_face - 0.5 * l - r}, r, l, 0.3e-6);
  std::vector<int> seen;
  for (const auto &c : cs)
    seen.push_back(c.half_disc);
  EXPECT_NE(std::find(seen.begin(), seen.end(), 0), seen.end());
  ASSERT_NE(std::find(seen.begin(), seen.end(), 7), seen.end());
  for (const auto &c : cs)
    if (c.half_disc == 7)
      {
        EXPECT_GT(c.normal.x(), 0.0); // the grain is to the right of half-disc 7's image
        EXPECT_NEAR(c.branch.x(), 0.55 * l, 1e-15);
        EXPECT_EQ(c.node[0], 7u);
        EXPECT_EQ(c.node[1], 0u);
      }
}

TEST(HalfDiscs, ThePairsTheMotionsCloseAreDetected)
{
  // Half-disc 2 (centre x = 2.5 l, edge 2: nodes 2 and 3) and a grain straight below it at
  // gap 0.3 l, beyond the distance 0.01 l. Motions until the next detection (m) of 0.2 l
  // each: the nodes down and the grain up close the pair (0.4 l > 0.3 l); either alone
  // does not; the nodes up (away) do not; the node motions of another edge do not.
  LumpedChain    chain(8, L, y_face, 1e-8);
  const double   r = 0.6e-6, distance = 0.01 * l;
  ParticleSystem s;
  s.period = L;
  s.add_disc({2.5 * l, y_face - 0.5 * l - r - 0.3 * l}, r, rho);
  const HalfDiscs hd(chain, l, {0, -1}, L);
  const std::vector<Vec2> centres{s.wrap(s.discs[0].offset + s.bodies[0].position)};
  auto count_with = [&](const Vec2 &grain, const Vec2 &nodes_2_3, const Vec2 &others) {
    std::vector<Vec2> node_motion(8, others);
    node_motion[2] = node_motion[3] = nodes_2_3;
    unsigned int found = 0;
    for (const Contact &c : hd.detect(s, centres, {0.0}, chain.x, distance, {grain}, node_motion))
      if (c.half_disc == 2)
        {
          ++found;
          EXPECT_NEAR(c.gap, 0.3 * l, 1e-15); // the gap now, not the predicted one
        }
    return found;
  };
  const Vec2 up(0, 0.2 * l), zero(0, 0);
  EXPECT_EQ(count_with(up, -up, zero), 1u);
  EXPECT_EQ(count_with(up, zero, zero), 0u);
  EXPECT_EQ(count_with(zero, -up, zero), 0u);
  EXPECT_EQ(count_with(up, up, zero), 0u);
  EXPECT_EQ(count_with(up, zero, -up), 0u);
  EXPECT_EQ(hd.detect(s, centres, {0.0}, chain.x, distance).size(), 0u); // no motions: as before
  try
    {
      hd.detect(s, centres, {0.0}, chain.x, distance, {up, up}, {});
      FAIL() << "two disc motions for one disc were accepted";
    }
  catch (const std::exception &e)
    {
      EXPECT_STREQ(e.what(), "half-disc detection: 2 disc motions for 1 discs and 0 node motions for 8 nodes");
    }
}

TEST(HalfDiscs, GapRateIsTheGeometricRateOnATurnedAndStretchedFace)
{
  // Nodes displaced and moving with a rotation, a stretch and a random part; grains
  // around the half-discs, moving too. The solver's normal velocity u_n (BodyState) must
  // be the time derivative of the gap that detection measures (central difference),
  // for D < l, D = l and D > l (the paper's Fig. 4 c, b, a).
  std::mt19937                           gen(5);
  std::uniform_real_distribution<double> U(-1, 1);
  const unsigned int                     n = 8;
  const double                           dt = 1e-12;
  unsigned int                           checked = 0;
  for (const double D : {0.5 * l, l, 2 * l})
    for (int trial = 0; trial < 40; ++trial)
      {
        LumpedChain       chain(n, L, y_face, 1e-8);
        HalfDiscs         hd(chain, D, {0, -1}, L);
        std::vector<Vec2> x(n), v(n);
        const double      spin = 2e6 * U(gen), stretch = 3e6 * U(gen); // 1/s
        for (unsigned int i = 0; i < n; ++i)
          {
            const Vec2 rel = chain.x[i] - Vec2(0.5 * L, y_face);
            x[i] = chain.x[i] + 0.05 * l * Vec2(U(gen), U(gen));
            v[i] = spin * Vec2(-rel.y(), rel.x()) + stretch * Vec2(rel.x(), 0) + 0.5 * Vec2(U(gen), U(gen));
          }
        // A grain near a random half-disc, below it at a random angle.
        const auto   centres = hd.centres(x);
        const double r = 0.5e-6, phi = 0.45 * M_PI * U(gen);
        const Vec2   c = centres[trial % hd.count()];
        const Vec2   xg = c + (0.5 * D + r + 0.02 * l) * Vec2(std::sin(phi), -std::cos(phi));
        const Vec2   vg(U(gen), U(gen));
        const auto   at = [&](double t, int k) -> std::vector<Contact> {
          ParticleSystem s;
          s.period = L;
          s.add_disc(xg + t * vg, r, rho);
          std::vector<Vec2> xt(n);
          for (unsigned int i = 0; i < n; ++i)
            xt[i] = x[i] + t * v[i];
          std::vector<Contact> out;
          for (const Contact &ct : hd.detect(s, {s.wrap(xg + t * vg)}, {0.0}, xt, 0.1 * l))
            if (ct.half_disc == k)
              out.push_back(ct);
          return out;
        };
        const int  k   = trial % hd.count();
        const auto now = at(0, k), before = at(-dt, k), after = at(dt, k);
        ASSERT_EQ(now.size(), 1u);
        ASSERT_EQ(before.size(), 1u);
        ASSERT_EQ(after.size(), 1u);
        BodyState state;
        state.velocity      = {Eigen::Vector3d(vg.x(), vg.y(), 0)};
        state.inverse_mass  = {{{1, 1, 1}}};
        state.node_velocity = Eigen::VectorXd(2 * n);
        for (unsigned int i = 0; i < n; ++i)
          state.node_velocity.segment<2>(2 * i) = v[i];
        const double rate = (after[0].gap - before[0].gap) / (2 * dt);
        EXPECT_NEAR(state.local_velocity(now[0]).x(), rate, 1e-6 * (std::abs(rate) + 1))
          << "D = " << D / l << " l, trial " << trial;
        ++checked;
      }
  EXPECT_EQ(checked, 120u);
}

TEST(HalfDiscs, VelocityMapIsTheTransposeOfTheForceMap)
{
  // u . r = qdot . (H r) for random velocities and impulses: the half-disc side's
  // interpolated velocity and its split impulse are adjoint, and so is the grain's side.
  std::mt19937                           gen(3);
  std::uniform_real_distribution<double> U(-1, 1);
  for (int trial = 0; trial < 20; ++trial)
    {
      const double r  = 0.6e-6;
      const double dx = 0.4e-6 * U(gen), D = (trial % 3 + 1) * 0.5 * l;
      const auto   cs = contacts_of_grain({4.25 * l + dx, y_face - 0.5 * D - r + 0.2 * r * U(gen)}, r, D, 0.4e-6);
      ASSERT_FALSE(cs.empty());
      Contact c = cs[0];
      c.body[0] = c.body[1] = 0;
      c.arm_n[1] = 1e-7 * U(gen); // some moment arm for the grain's spin
      c.arm_t[1] = 1e-7 * U(gen);
      const unsigned int n = 8;
      // Random velocities: u = H^T qdot.
      BodyState vel;
      vel.velocity        = {Eigen::Vector3d(U(gen), U(gen), 1e6 * U(gen))};
      vel.inverse_mass    = {{{1, 1, 1}}};
      vel.node_velocity   = Eigen::VectorXd::NullaryExpr(2 * n, [&]() { return U(gen); });
      Eigen::MatrixXd I   = Eigen::MatrixXd::Identity(2 * n, 2 * n);
      vel.node_blocks     = {{0, &I}};
      const Eigen::Vector2d u = vel.local_velocity(c);
      // H r: with unit inverse masses and compliance, apply_impulse adds H r to zero velocities.
      const Eigen::Vector2d rr(U(gen), U(gen));
      BodyState imp;
      imp.velocity        = {Eigen::Vector3d::Zero()};
      imp.inverse_mass    = {{{1, 1, 1}}};
      imp.node_velocity   = Eigen::VectorXd::Zero(2 * n);
      imp.node_blocks     = {{0, &I}};
      imp.apply_impulse(c, rr);
      const double lhs = u.dot(rr);
      const double rhs = vel.velocity[0].dot(imp.velocity[0]) + vel.node_velocity.dot(imp.node_velocity);
      EXPECT_NEAR(lhs, rhs, 1e-12 * (std::abs(lhs) + 1));
      // And the own Delassus block is H^T G H with G = I.
      const Eigen::Matrix2d W = imp.delassus_block(c);
      for (int k = 0; k < 2; ++k)
        {
          BodyState e = imp;
          e.velocity[0].setZero();
          e.node_velocity.setZero();
          e.apply_impulse(c, Eigen::Vector2d::Unit(k));
          const Eigen::Vector2d column = e.local_velocity(c);
          EXPECT_NEAR(column.x(), W(0, k), 1e-12);
          EXPECT_NEAR(column.y(), W(1, k), 1e-12);
        }
    }
}

TEST(HalfDiscs, ImpactOnALumpedChainConservesMomentum)
{
  // A grain moving up at 2 m/s hits a chain of free point masses (frictionless IQS):
  // total momentum is conserved and the contact's normal velocity ends at zero.
  const double   r = 0.5e-6, mnode = 2e-9;
  LumpedChain    chain(8, L, y_face, mnode);
  ParticleSystem s;
  s.period = L;
  const unsigned g = s.add_disc({3.5 * l, y_face - 0.5 * l - r - 1e-9}, r, rho);
  s.bodies[g].velocity = {0.3, 2.0};
  SolverParameters prm;
  prm.method         = SolverParameters::Method::nlgs;
  prm.tolerance      = 1e-10;
  prm.check_interval = 1;
  MoreauJean mj(0.5, ContactLaw{}, prm, 5e-8);
  mj.attach(chain, l, {0, -1}, L);
  const Vec2 p0 = s.bodies[g].mass * s.bodies[g].velocity + chain.momentum();
  const auto rep = mj.step(s, 1e-9);
  ASSERT_EQ(rep.n_boundary_contacts, 1u);
  ASSERT_EQ(rep.n_active, 1u);
  const Vec2 p1 = s.bodies[g].mass * s.bodies[g].velocity + chain.momentum();
  EXPECT_NEAR(p1.x(), p0.x(), 1e-12 * p0.norm());
  EXPECT_NEAR(p1.y(), p0.y(), 1e-12 * p0.norm());
  const Contact &c = mj.contacts()[0];
  const Vec2 v_point = c.node_map[0] * chain.v[c.node[0]] + c.node_map[1] * chain.v[c.node[1]];
  EXPECT_NEAR(c.normal.dot(s.bodies[g].velocity - v_point) + c.shift, 0.0, 1e-9); // closed at the end
  EXPECT_GT(chain.momentum().y(), 0.0); // pushed up
}

TEST(HalfDiscs, EnergyBalanceWithABoundaryBodyClosesEveryStep)
{
  // Grains squeezed between a sliding rigid wall and a loaded chain of point masses:
  // KE + E_chain changes by h (P_external + P_contacts) every step, to round-off.
  ParticleSystem s;
  s.period = L;
  std::vector<Vec2>   c;
  std::vector<double> rad;
  for (int i = 0; i < 8; ++i)
    {
      c.push_back({(i + 0.5) * l, 0});
      rad.push_back(0.5e-6);
    }
  const unsigned lower = s.add_clump(c, rad, rho);
  for (auto &d : s.bodies[lower].drive)
    d = Drive::velocity;
  s.bodies[lower].velocity = {1.0, 0};
  for (int i = 0; i < 24; ++i)
    s.add_disc({(i % 8 + 0.5 + 0.3 * (i / 8 % 2)) * l, (1.05 + 1.05 * (i / 8)) * l}, 0.5e-6, rho);
  LumpedChain chain(8, L, 4.0 * l, 2e-8, {0, -100.0});
  SolverParameters prm;
  prm.method         = SolverParameters::Method::nlgs;
  prm.tolerance = 1e-9;
  prm.check_interval = 1;
  MoreauJean mj(0.5, ContactLaw{}, prm, 5e-8);
  mj.attach(chain, l, {0, -1}, L);
  double   e0 = s.kinetic_energy() + chain.energy();
  unsigned touched = 0;
  for (int i = 0; i < 300; ++i)
    {
      const auto   rep = mj.step(s, 1e-9);
      const double e1  = rep.kinetic_energy + rep.boundary_energy;
      const double rhs = 1e-9 * (rep.power_external + rep.power_contacts - rep.boundary_dissipation);
      // Round-off: a few ulps of the total (the sliding wall's 2.4e-8 J/m).
      EXPECT_NEAR(e1 - e0, rhs, 1e-9 * (std::abs(e1 - e0) + std::abs(rhs)) + 1e-14 * e1) << "step " << i;
      e0 = e1;
      touched += rep.n_boundary_contacts > 0;
    }
  EXPECT_GT(touched, 100u);
}

namespace
{
  /// Grains in three rows between a lower chain (half-discs facing up, loaded up) and an
  /// upper chain (facing down, loaded down), both free point masses: two first bodies
  /// attached to one MoreauJean, squeezing the layer from both sides.
  struct TwoBodies
  {
    ParticleSystem s;
    LumpedChain    lower{8, L, 0.0, 2e-8, {0, 100.0}}, upper{8, L, 4.2 * l, 2e-8, {0, -100.0}};
    MoreauJean     mj;

    explicit TwoBodies(const SolverParameters &prm)
      : mj(0.5, ContactLaw{}, prm, 5e-8)
    {
      s.period = L;
      for (int i = 0; i < 24; ++i)
        s.add_disc({(i % 8 + 0.5 + 0.3 * (i / 8 % 2)) * l, (1.05 + 1.05 * (i / 8)) * l}, 0.5e-6, rho);
      s.bodies[3].velocity = {0.5, -0.2}; // something to dissipate besides the squeeze
      mj.attach(lower, l, {0, 1}, L);
      mj.attach(upper, l, {0, -1}, L);
    }
    Vec2 grain_momentum() const
    {
      Vec2 p = Vec2::Zero();
      for (const auto &b : s.bodies)
        p += b.mass * b.velocity;
      return p;
    }
  };
} // namespace

TEST(HalfDiscs, TwoBodiesSqueezingGrainsEachTakeTheirOwnContactsImpulses)
{
  // Each chain's momentum changes over a step by its load's impulse minus the impulses of
  // the contacts on its own half-discs (the nodes' shares -J_A^T f, -J_B^T f sum to -f):
  // the engine routes every half-disc contact to its own body. The loads cancel, so the
  // total momentum is conserved; KE + both chains' energies change by h (P_ext + P_c).
  SolverParameters prm;
  prm.method         = SolverParameters::Method::nlgs;
  prm.tolerance      = 1e-10;
  prm.check_interval = 1;
  TwoBodies  t(prm);
  const double h = 1e-9;
  ASSERT_EQ(t.mj.n_boundary_bodies(), 2u);
  const Vec2 p0 = t.grain_momentum() + t.lower.momentum() + t.upper.momentum();
  double     e0 = t.s.kinetic_energy() + t.lower.energy() + t.upper.energy();
  unsigned   both = 0;
  for (int i = 0; i < 300; ++i)
    {
      const Vec2 lower0 = t.lower.momentum(), upper0 = t.upper.momentum();
      const auto rep    = t.mj.step(t.s, h);
      Vec2       on[2]  = {Vec2::Zero(), Vec2::Zero()};
      unsigned   count[2] = {0, 0};
      for (const Contact &c : t.mj.contacts())
        if (c.on_boundary())
          {
            ASSERT_LT(c.boundary_body, 2u);
            on[c.boundary_body] += c.r.x() * c.normal + c.r.y() * Vec2(-c.normal.y(), c.normal.x());
            ++count[c.boundary_body];
            // The first body's half-discs are numbered first: 8 per chain.
            EXPECT_EQ(c.half_disc / 8, int(c.boundary_body));
            EXPECT_EQ(c.node[0] / 8, c.boundary_body);
          }
      EXPECT_EQ(count[0] + count[1], rep.n_boundary_contacts);
      both += count[0] > 0 && count[1] > 0 && on[0].norm() > 0 && on[1].norm() > 0;
      const double scale = h * 8 * 100.0 + on[0].norm() + on[1].norm();
      const Vec2   d_lower = t.lower.momentum() - lower0 - (h * 8 * t.lower.load - on[0]);
      const Vec2   d_upper = t.upper.momentum() - upper0 - (h * 8 * t.upper.load - on[1]);
      EXPECT_LT(d_lower.norm(), 1e-9 * scale) << "step " << i;
      EXPECT_LT(d_upper.norm(), 1e-9 * scale) << "step " << i;
      const Vec2 p1 = t.grain_momentum() + t.lower.momentum() + t.upper.momentum();
      EXPECT_LT((p1 - p0).norm(), 1e-9 * (t.lower.momentum().norm() + t.grain_momentum().norm() + scale))
        << "step " << i;
      const double e1  = rep.kinetic_energy + rep.boundary_energy;
      const double rhs = h * (rep.power_external + rep.power_contacts - rep.boundary_dissipation);
      // Round-off: the 24 grains' and 16 nodes' energies summed (up to 4e-14 of the total).
      EXPECT_NEAR(e1 - e0, rhs, 1e-9 * (std::abs(e1 - e0) + std::abs(rhs)) + 2e-13 * e1) << "step " << i;
      e0 = e1;
    }
  EXPECT_GT(both, 150u); // the layer is squeezed by both bodies for most of the steps
  EXPECT_LT(t.lower.x[0].y() + 0.5 * l, t.upper.x[0].y() - 0.5 * l); // and holds them apart
}

TEST(HalfDiscs, TheAssembledOperatorCouplesHalfDiscsOnlyThroughTheirOwnBody)
{
  // The global methods' sparse Delassus operator (dem/linalg/delassus.h) with two bodies'
  // half-disc contacts: every column equals the local velocities that a unit impulse on
  // that contact gives through BodyState (the sweeps' route: each body's own compliance
  // block), and two half-discs of different bodies that share no grain are not coupled.
  SolverParameters prm;
  prm.method    = SolverParameters::Method::nlgs;
  prm.tolerance = 1e-8;
  TwoBodies t(prm);
  for (int i = 0; i < 40; ++i)
    t.mj.step(t.s, 1e-9);
  const std::vector<Contact> &contacts = t.mj.contacts();
  BodyState                   state    = BodyState::of(t.s);
  state.node_velocity                  = Eigen::VectorXd::Zero(2 * 16);
  state.node_blocks                    = {{0, &t.lower.G}, {8, &t.upper.G}};
  const Eigen::MatrixXd W = Eigen::MatrixXd(assemble_delassus(contacts, state, DelassusPart::full));
  const std::size_t     n = contacts.size();
  ASSERT_EQ(W.rows(), Eigen::Index(2 * n));
  unsigned int on[2] = {0, 0}, uncoupled_pairs = 0;
  for (std::size_t j = 0; j < n; ++j)
    {
      if (contacts[j].on_boundary())
        ++on[contacts[j].boundary_body];
      for (int k = 0; k < 2; ++k)
        {
          BodyState response = state;
          for (auto &v : response.velocity)
            v.setZero();
          response.apply_impulse(contacts[j], Eigen::Vector2d::Unit(k));
          for (std::size_t i = 0; i < n; ++i)
            {
              const Eigen::Vector2d u = response.local_velocity(contacts[i]);
              EXPECT_NEAR(W(2 * i, 2 * j + k), u.x(), 1e-9 * W.cwiseAbs().maxCoeff()) << i << " " << j;
              EXPECT_NEAR(W(2 * i + 1, 2 * j + k), u.y(), 1e-9 * W.cwiseAbs().maxCoeff()) << i << " " << j;
            }
        }
      for (std::size_t i = 0; i < n; ++i)
        if (contacts[i].on_boundary() && contacts[j].on_boundary() &&
            contacts[i].boundary_body != contacts[j].boundary_body && contacts[i].body[1] != contacts[j].body[1])
          {
            EXPECT_EQ((W.block<2, 2>(2 * i, 2 * j).norm()), 0.0);
            ++uncoupled_pairs;
          }
    }
  EXPECT_GE(on[0], 4u);
  EXPECT_GE(on[1], 4u);
  EXPECT_GT(uncoupled_pairs, 0u);
  // Its columns assembled on two threads: the same matrix, bit for bit.
  EXPECT_TRUE((Eigen::MatrixXd(assemble_delassus(contacts, state, DelassusPart::full, nullptr, 2)).array() ==
               W.array()).all());
}
