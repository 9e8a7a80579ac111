/// @file Unit tests of the solid-SPH dynamics: conservation, wave speed, Jaumann
/// rate, damping, step floor.

#include "core/errors.h"
#include "sph/lattice.h"
#include "sph/solver.h"

#include <deal.II/base/multithread_info.h>

#include "tests/unit/sph_test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

using namespace tribo::sph;
using tribo::RunError;
using tribo::sph::testing::vec;

namespace
{
  /// A block of granite-like linear solid on a lattice of spacing a, h = 1.2 a.
  template <int dim>
  Solver<dim> make_block(const Tensor<1, dim> &size, double a, LatticeType type,
                         const SolverParameters &prm, const Material &mat)
  {
    Solver<dim> s({mat}, prm);
    add_particles(s.state, lattice_points<dim>(type, Tensor<1, dim>(), size, a), mat.rho0,
                  volume_per_particle<dim>(type, a), 1.2 * a, 0, 0);
    return s;
  }

  const Material rock = Material::linear(2700, 26.7e9, 22.7e9);

  /// A 2D granite block of 8 x 4 particles (a = 5e-4 m) at rest whose top two layers (y >
  /// 2a) move along x at @p V, imposed on x only (the other components free), at every
  /// stage or, with @p between_steps, as a reset after each step; advanced by @p integrator.
  Solver<2> pushed_block(double V, bool between_steps, Integrator integrator = Integrator::midpoint)
  {
    const double     a = 5e-4;
    SolverParameters prm;
    prm.integrator = integrator;
    auto s = make_block<2>(vec<2>(8 * a, 4 * a), a, LatticeType::cubic, prm, Material::granite());
    ImposedVelocity<2> push;
    for (unsigned int i = 0; i < s.state.size(); ++i)
      if (s.state.x[i][1] > 2 * a)
        {
          push.particles.push_back(i);
          s.state.v[i][0] = V;
        }
    push.velocity      = vec<2>(V, 0);
    push.components    = 1;
    push.between_steps = between_steps;
    s.imposed.push_back(push);
    return s;
  }
} // namespace

TEST(SphDynamics, MomentumConservedToRoundOffWithRandomVelocities)
{
  SolverParameters prm; // alpha = 1, beta = 0.1: viscosity on
  const double     a = 1e-3;
  auto s = make_block<3>(vec<3>(7 * a, 6 * a, 6 * a), a, LatticeType::hexagonal, prm, Material::granite());
  std::mt19937_64                        rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  double                                 pabs = 0;
  for (unsigned int i = 0; i < s.state.size(); ++i)
    {
      s.state.v[i] = vec<3>(u(rng), u(rng), u(rng));
      pabs += s.state.mass[i] * s.state.v[i].norm();
    }
  const Tensor<1, 3> p0 = s.state.momentum();
  for (unsigned int k = 0; k < 200; ++k)
    s.step();
  const double drift = (s.state.momentum() - p0).norm() / pabs;
  std::printf("momentum drift / sum m|v| = %.3g after 200 steps (%u particles)\n", drift, s.state.size());
  EXPECT_LT(drift, 1e-13);
}

TEST(SphDynamics, EnergyConservedWithoutViscosityForSmallVibration)
{
  // sum m (|v|^2/2 + e) is conserved by the space discretisation; the RK2 error
  // after a fixed time falls as dt^2 (halving the Courant number: / ~4).
  double rel[2];
  for (int run = 0; run < 2; ++run)
    {
      SolverParameters prm;
      prm.alpha   = 0;
      prm.beta    = 0;
      prm.courant = run == 0 ? 0.3 : 0.15;
      const double a = 1e-3, L = 16 * a;
      auto s = make_block<2>(vec<2>(L, L), a, LatticeType::hexagonal, prm, rock);
      const double v0 = 0.1; // m/s: strain ~ v0/c ~ 3e-5
      for (unsigned int i = 0; i < s.state.size(); ++i)
        {
          const double x = s.state.x[i][0] / L - 0.5, y = s.state.x[i][1] / L - 0.5;
          s.state.v[i] = vec<2>(v0 * x, -v0 * y + 0.5 * v0 * std::sin(2 * M_PI * x));
        }
      const double E0 = s.total_energy(), K0 = s.state.kinetic_energy();
      const double t_end = 3 * L / rock.longitudinal_speed(); // ~3 crossings
      const unsigned int n = s.advance_to(t_end);
      rel[run] = std::abs(s.total_energy() - E0) / K0;
      std::printf("energy: C = %.2f, %u steps, |dE|/K0 = %.3g, K(t)/K0 = %.3f\n", prm.courant, n,
                  rel[run], s.state.kinetic_energy() / K0);
      // The energy did move between kinetic and internal (a real vibration).
      EXPECT_LT(s.state.kinetic_energy() / K0, 0.95);
    }
  EXPECT_LT(rel[0], 3e-3);
  EXPECT_LT(rel[1], 1e-3);
  EXPECT_LT(rel[1], rel[0] / 3);
}

TEST(SphDynamics, CompressionPulseTravelsAtLongitudinalSpeed)
{
  // Strip periodic in x (laterally confined: plane wave), a piston at the
  // bottom pushes at v_p from t = 0; the front (v_y = v_p/2) crosses two
  // heights at times t1, t2: speed (y2 - y1)/(t2 - t1) vs c_P = sqrt((K + 4G/3)/rho).
  SolverParameters prm;
  prm.alpha = 0.5;
  prm.beta  = 0;
  const double a = 1e-3, W = 12 * a, H = 160 * a;
  prm.period    = W;
  auto s = make_block<2>(vec<2>(W, H), a, LatticeType::cubic, prm, rock);
  ImposedVelocity<2> piston;
  const double       vp = 0.5;
  piston.velocity       = vec<2>(0, vp);
  for (unsigned int i = 0; i < s.state.size(); ++i)
    if (s.state.x[i][1] < 2.5 * a)
      piston.particles.push_back(i);
  s.imposed.push_back(piston);
  const double cP = rock.longitudinal_speed();
  const double y1 = 40 * a, y2 = 120 * a;
  auto mean_vy = [&](double y) {
    double sum = 0;
    int    n   = 0;
    for (unsigned int i = 0; i < s.state.size(); ++i)
      if (std::abs(s.state.x[i][1] - y) < 0.5 * a)
        {
          sum += s.state.v[i][1];
          ++n;
        }
    return sum / n;
  };
  double t1 = -1, t2 = -1, prev1 = 0, prev2 = 0, tprev = 0;
  while (s.time < 1.4 * y2 / cP && t2 < 0)
    {
      s.step();
      const double v1 = mean_vy(y1), v2 = mean_vy(y2);
      if (t1 < 0 && v1 >= 0.5 * vp)
        t1 = tprev + (s.time - tprev) * (0.5 * vp - prev1) / (v1 - prev1);
      if (t2 < 0 && v2 >= 0.5 * vp)
        t2 = tprev + (s.time - tprev) * (0.5 * vp - prev2) / (v2 - prev2);
      prev1 = v1;
      prev2 = v2;
      tprev = s.time;
    }
  ASSERT_GT(t1, 0);
  ASSERT_GT(t2, 0);
  const double c = (y2 - y1) / (t2 - t1);
  std::printf("pulse speed %.1f m/s, c_P = %.1f m/s (error %.2f %%)\n", c, cP, 100 * (c / cP - 1));
  EXPECT_NEAR(c / cP, 1, 0.03);
  // Stress behind the front: sigma_yy = -rho c_P v_p (compression).
  const Rates<2> &k = s.last_rates();
  double          syy = 0;
  int             n   = 0;
  for (unsigned int i = 0; i < s.state.size(); ++i)
    if (std::abs(s.state.x[i][1] - 0.5 * (y1 + y2) + 40 * a) < 0.5 * a)
      {
        syy += -k.pressure[i] + s.state.S[i][1][1];
        ++n;
      }
  syy /= n;
  std::printf("sigma_yy behind the front %.4g Pa, -rho c_P v_p = %.4g Pa\n", syy, -rock.rho0 * cP * vp);
  EXPECT_NEAR(syy / (-rock.rho0 * cP * vp), 1, 0.05);
}

TEST(SphDynamics, RigidRotationRotatesPrestressWithJaumannRate)
{
  // Velocities imposed as a rigid rotation (w counter-clockwise) on a
  // pre-stressed 2D body: the deviator must turn with the body,
  // S(t) = Q(w t) S0 Q(w t)^T, keeping its invariants. The wrong Jaumann sign
  // would turn it by -w t (error ~ |S0|).
  for (bool corrected : {true, false})
    {
      SolverParameters prm;
      prm.corrected_gradient = corrected;
      const double     a = 1e-3, L = 16 * a, w = 2e4; // rad/s
      auto s = make_block<2>(vec<2>(L, L), a, LatticeType::hexagonal, prm, rock);
      const Tensor<1, 2> c = vec<2>(0.5 * L, 0.5 * L);
      SymmetricTensor<2, 2> S0;
      S0[0][0] = 3e6;
      S0[1][1] = -1e6;
      S0[0][1] = 2e6;
      ImposedVelocity<2> rot;
      rot.field = [&](const Tensor<1, 2> &x, double) { return vec<2>(-w * (x[1] - c[1]), w * (x[0] - c[0])); };
      for (unsigned int i = 0; i < s.state.size(); ++i)
        {
          s.state.S[i] = S0;
          rot.particles.push_back(i);
        }
      s.imposed.push_back(rot);
      std::vector<unsigned int> inner;
      for (unsigned int i = 0; i < s.state.size(); ++i)
        if ((s.state.x[i] - c).norm() < 0.5 * L - 3 * a)
          inner.push_back(i);
      const double theta = M_PI / 4;
      const unsigned int steps = s.advance_to(theta / w);
      Tensor<2, 2> Q;
      Q[0][0] = Q[1][1] = std::cos(theta);
      Q[1][0]           = std::sin(theta);
      Q[0][1]           = -std::sin(theta);
      const Tensor<2, 2> Se = Q * Tensor<2, 2>(S0) * dealii::transpose(Q);
      const Tensor<2, 2> Sw = dealii::transpose(Q) * Tensor<2, 2>(S0) * Q; // wrong sign
      const double       j2_0 = 0.5 * deviator_norm_squared(S0);
      double             err = 0, err_j2 = 0, err_all = 0;
      for (unsigned int i : inner)
        {
          err    = std::max(err, (Tensor<2, 2>(s.state.S[i]) - Se).norm() / Tensor<2, 2>(S0).norm());
          err_j2 = std::max(err_j2, std::abs(s.state.j2(i) / j2_0 - 1));
        }
      for (unsigned int i = 0; i < s.state.size(); ++i)
        err_all = std::max(err_all, (Tensor<2, 2>(s.state.S[i]) - Se).norm() / Tensor<2, 2>(S0).norm());
      std::printf("rotation by 45 deg (%s gradient, %u steps): interior max |S - Q S0 Q^T|/|S0| = %.3g, "
                  "all particles %.3g, max |J2/J2_0 - 1| = %.3g; wrong sign would give %.3g\n",
                  corrected ? "corrected" : "paper's", steps, err, err_all, err_j2,
                  (Se - Sw).norm() / Tensor<2, 2>(S0).norm());
      EXPECT_LT(err, corrected ? 1e-3 : 0.06);
      if (corrected)
        {
          EXPECT_LT(err_all, 1e-3);
        }
      EXPECT_LT(err_j2, 1e-6);
    }
}

TEST(SphDynamics, ExactDampingAtStepFarAboveTwoOverGamma)
{
  // Isolated particles (no neighbours): v_rel(t) = v_rel(0) exp(-gamma t) exactly.
  SolverParameters prm;
  const double     gamma = 1e9, dt = 5e-9; // gamma dt = 5 >> 2
  prm.dt_max             = dt;
  Solver<3>                              s({rock}, prm);
  std::mt19937_64                        rng(9);
  std::uniform_real_distribution<double> u(-1, 1);
  for (unsigned int i = 0; i < 10; ++i)
    s.state.add(vec<3>(0.01 * i, 0, 0), vec<3>(u(rng), u(rng), u(rng)), 1e-6 * (1 + i), 2700, 1e-3, 0, 0);
  s.damping.push_back({0, gamma});
  const Tensor<1, 3>          p0 = s.state.momentum();
  double                      m  = 0;
  for (double mi : s.state.mass)
    m += mi;
  const Tensor<1, 3>          vcm = p0 / m;
  std::vector<Tensor<1, 3>>   rel0;
  for (const auto &v : s.state.v)
    rel0.push_back(v - vcm);
  for (unsigned int k = 0; k < 2; ++k)
    EXPECT_EQ(s.step(), dt);
  const double f = std::exp(-gamma * s.time);
  for (unsigned int i = 0; i < s.state.size(); ++i)
    EXPECT_NEAR((s.state.v[i] - vcm - f * rel0[i]).norm() / (f * rel0[i].norm()), 0, 1e-9);
  EXPECT_NEAR((s.state.momentum() - p0).norm() / p0.norm(), 0, 1e-14);

  // An elastic block at its CFL step (>> 2/gamma) with gamma = 1e9 stays finite,
  // keeps its centre-of-mass velocity and loses its internal motion.
  SolverParameters prm2;
  auto b = make_block<3>(vec<3>(6e-3, 6e-3, 6e-3), 1e-3, LatticeType::cubic, prm2, rock);
  b.damping.push_back({0, gamma});
  for (unsigned int i = 0; i < b.state.size(); ++i)
    b.state.v[i] = vec<3>(1 + u(rng), u(rng), u(rng));
  const Tensor<1, 3> P0 = b.state.momentum();
  double dt_b = 0;
  for (unsigned int k = 0; k < 20; ++k)
    dt_b = b.step();
  EXPECT_GT(dt_b * gamma, 20.0);
  EXPECT_NEAR((b.state.momentum() - P0).norm() / P0.norm(), 0, 1e-12);
  double mb = 0;
  for (double mi : b.state.mass)
    mb += mi;
  const double k_rel = b.state.kinetic_energy() - 0.5 * P0.norm_square() / mb;
  EXPECT_LT(k_rel, 1e-6 * b.state.kinetic_energy());
}

TEST(SphDynamics, StepBelowFloorThrowsNamingTheFloor)
{
  SolverParameters prm;
  prm.dt_min = 1e-6; // CFL step here ~ 4e-8 s
  auto s = make_block<2>(vec<2>(8e-3, 8e-3), 1e-3, LatticeType::cubic, prm, rock);
  try
    {
      s.step();
      FAIL() << "no RunError";
    }
  catch (const RunError &e)
    {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("step floor dt_min = 1e-06 s"), std::string::npos) << msg;
      EXPECT_NE(msg.find("CFL"), std::string::npos) << msg;
      EXPECT_NE(msg.find("particle"), std::string::npos) << msg;
    }
  // Two particles of different bodies thrown at each other against a stiff
  // repulsion: the acceleration limit takes over and hits the floor.
  SolverParameters prm2;
  prm2.boundary = BoundaryForce::monaghan(1e16, 4, 1e-3);
  prm2.dt_min   = 1e-9;
  Solver<2> c({rock}, prm2);
  c.state.add(vec<2>(0, 0), vec<2>(100, 0), 1e-3, 2700, 1e-3, 0, 0);
  c.state.add(vec<2>(5e-4, 0), vec<2>(-100, 0), 1e-3, 2700, 1e-3, 0, 1);
  EXPECT_THROW(
    {
      try
        {
          for (int k = 0; k < 1000; ++k)
            c.step();
        }
      catch (const RunError &e)
        {
          EXPECT_NE(std::string(e.what()).find("acceleration"), std::string::npos) << e.what();
          throw;
        }
    },
    RunError);
  // NaN is reported, never propagated.
  auto n = make_block<2>(vec<2>(8e-3, 8e-3), 1e-3, LatticeType::cubic, SolverParameters(), rock);
  n.state.v[7][0] = std::nan("");
  try
    {
      n.step();
      FAIL() << "no RunError";
    }
  catch (const RunError &e)
    {
      EXPECT_NE(std::string(e.what()).find("NaN"), std::string::npos) << e.what();
    }
}

TEST(SphDynamics, BoundaryForcePressesBlockOnSubstrateWithPressureRamp)
{
  // Block (body 1) on a substrate (body 0) with fixed bottom, pressure P on top
  // ramped with tau, spring law f1, damping of both bodies: at rest the total
  // boundary force on the block balances the applied load, F_y = P W.
  SolverParameters prm;
  const double     a = 1e-3, W = 12 * a, P = 1e7;
  prm.period         = W;
  prm.boundary       = BoundaryForce::spring(26.7e9 * a, a);
  Solver<2> s({rock}, prm);
  const auto vol = volume_per_particle<2>(LatticeType::cubic, a);
  add_particles(s.state, lattice_points<2>(LatticeType::cubic, vec<2>(0, 0), vec<2>(W, 6 * a), a), rock.rho0, vol, 1.2 * a, 0, 0);
  const unsigned int first = add_particles(
    s.state, lattice_points<2>(LatticeType::cubic, vec<2>(0, 6 * a), vec<2>(W, 6 * a), a), rock.rho0, vol, 1.2 * a, 0, 1);
  ImposedVelocity<2> bottom;
  ExternalForce<2>   load;
  for (unsigned int i = 0; i < s.state.size(); ++i)
    {
      if (s.state.x[i][1] < a)
        bottom.particles.push_back(i);
      if (s.state.x[i][1] > 11 * a)
        load.particles.push_back(i);
    }
  load.force = vec<2>(0, -P * W / load.particles.size());
  load.tau   = 1e-5;
  s.imposed.push_back(bottom);
  s.external.push_back(load);
  // Damped relative to rest (the block's rigid bounce on the springs, omega ~ 4e4
  // 1/s, is critically damped), so it settles within the run.
  s.damping.push_back({0, 8e4, false});
  s.damping.push_back({1, 8e4, false});
  s.advance_to(1.5e-4);
  double fy = 0;
  for (unsigned int i = first; i < s.state.size(); ++i)
    fy += s.last_rates().boundary_force[i][1];
  std::printf("boundary force on block %.4g N/m, P W = %.4g N/m, block KE %.3g J/m\n", fy, P * W,
              s.state.kinetic_energy());
  EXPECT_NEAR(fy / (P * W), 1, 0.03);
}

TEST(SphDynamics, ResultsIndependentOfThreadCount)
{
  // Gathered loops: the state after 20 steps is bitwise the same for 1 and 2 threads,
  // with either integrator.
  for (const Integrator integrator : {Integrator::midpoint, Integrator::leapfrog})
  {
  std::vector<Tensor<1, 3>> v_end[2];
  for (unsigned int threads : {1U, 2U})
    {
      dealii::MultithreadInfo::set_thread_limit(threads);
      SolverParameters prm;
      prm.integrator = integrator;
      auto s = make_block<3>(vec<3>(6e-3, 6e-3, 6e-3), 1e-3, LatticeType::cubic, prm, Material::granite());
      std::mt19937_64                        rng(2);
      std::uniform_real_distribution<double> u(-1, 1);
      for (auto &v : s.state.v)
        v = vec<3>(u(rng), u(rng), u(rng));
      s.advance_to(20 * 0.3 * 1.2e-3 / s.materials()[0].longitudinal_speed());
      v_end[threads - 1] = s.state.v;
    }
  dealii::MultithreadInfo::set_thread_limit();
  ASSERT_EQ(v_end[0].size(), v_end[1].size());
  for (unsigned int i = 0; i < v_end[0].size(); ++i)
    EXPECT_EQ((v_end[0][i] - v_end[1][i]).norm(), 0.0) << i;
  }
}

TEST(SphDynamics, ImposedComponentMovesExactlyAndItsImpulseIsTheMomentumGiven)
{
  // A block at rest whose top two layers are pushed along x at V (x imposed, the other
  // components free), no damping: the x momentum the free particles gain is the
  // impulse the constraint reports, and the pushed layers advance by exactly V t; with
  // either integrator.
  for (const Integrator integrator : {Integrator::midpoint, Integrator::leapfrog})
    {
      const double a = 5e-4, V = 0.1;
      auto         s = pushed_block(V, false, integrator);
      const auto   x0 = s.state.x;
      const double t  = 2e-6;
      s.advance_to(t);
      double p_free = 0;
      for (unsigned int i = 0; i < s.state.size(); ++i)
        if (s.state.x[i][1] < 2 * a)
          p_free += s.state.mass[i] * s.state.v[i][0];
      const double impulse = s.imposed[0].impulse[0];
      std::printf("free-layer x momentum %.6e N s/m, constraint impulse %.6e N s/m\n", p_free, impulse);
      // The pushed layers drag the free ones: a momentum of order m V, not round-off.
      EXPECT_GT(p_free, 1e-3 * s.state.mass[0] * V);
      EXPECT_NEAR(impulse, p_free, 1e-9 * std::abs(p_free));
      for (unsigned int i : s.imposed[0].particles)
        EXPECT_NEAR(s.state.x[i][0] - x0[i][0], V * t, 1e-12 * a);
    }
}

TEST(SphDynamics, ImposedBetweenStepsIsAResetWhoseImpulseIsTheMomentumGiven)
{
  // The push of the previous test imposed only after each step (ImposedVelocity::
  // between_steps): within a step the pushed layers are slowed by the free ones, so they
  // advance less than V t, end each step at exactly V, and the resets' impulse is all the
  // x momentum the block has gained.
  const double a = 5e-4, V = 0.1;
  auto         s  = pushed_block(V, true);
  double       p0 = 0;
  for (unsigned int i : s.imposed[0].particles)
    p0 += s.state.mass[i] * V;
  const auto   x0 = s.state.x;
  const double t  = 2e-6;
  s.advance_to(t);
  double p = 0;
  for (unsigned int i = 0; i < s.state.size(); ++i)
    p += s.state.mass[i] * s.state.v[i][0];
  const double impulse = s.imposed[0].impulse[0];
  std::printf("block x momentum gained %.6e N s/m, resets' impulse %.6e N s/m\n", p - p0, impulse);
  EXPECT_GT(impulse, 1e-3 * s.state.mass[0] * V);
  EXPECT_NEAR(impulse, p - p0, 1e-9 * std::abs(p - p0));
  double lag = 0;
  for (unsigned int i : s.imposed[0].particles)
    {
      EXPECT_EQ(s.state.v[i][0], V);
      lag = std::max(lag, V * t - (s.state.x[i][0] - x0[i][0]));
    }
  std::printf("largest lag of a pushed particle behind V t: %.3g a\n", lag / a);
  EXPECT_GT(lag, 1e-6 * a);
}

TEST(SphDynamics, InterfaceViscosityActsAcrossBodiesConservingMomentumAndEnergy)
{
  // Two particles of different bodies approaching head-on within 2 h, a boundary force
  // too short to reach them: without interface viscosity they pass untouched; with it
  // their approach slows, momentum is kept and the kinetic energy lost is the viscous heat.
  const double a = 1e-3;
  for (bool on : {false, true})
    {
      SolverParameters prm;
      prm.boundary            = BoundaryForce::spring(1e9, 1e-6 * a);
      prm.interface_viscosity = on;
      Solver<2> s({rock}, prm);
      const double vol = volume_per_particle<2>(LatticeType::cubic, a);
      add_particles(s.state, {vec<2>(0, 0)}, rock.rho0, vol, 1.2 * a, 0, 0);
      add_particles(s.state, {vec<2>(a, 0)}, rock.rho0, vol, 1.2 * a, 0, 1);
      s.state.v[0] = vec<2>(5, 0);
      s.state.v[1] = vec<2>(-5, 0);
      const double e0 = s.total_energy(), ke0 = s.state.kinetic_energy();
      for (int k = 0; k < 20; ++k)
        s.step();
      const double approach = s.state.v[0][0] - s.state.v[1][0];
      std::printf("interface viscosity %d: approach speed %.6g m/s, KE lost %.4g J/m, viscous heat %.4g J/m\n",
                  on, approach, ke0 - s.state.kinetic_energy(), s.viscous_heat());
      EXPECT_NEAR(s.state.momentum()[0], 0, 1e-12 * s.state.mass[0] * 5);
      if (!on)
        {
          EXPECT_EQ(approach, 10.0);
          EXPECT_EQ(s.viscous_heat(), 0.0);
          continue;
        }
      EXPECT_LT(approach, 9.9);
      // The midpoint scheme pairs work and heat to its truncation error.
      EXPECT_NEAR(s.total_energy(), e0, 0.02 * s.viscous_heat());
      EXPECT_NEAR(ke0 - s.state.kinetic_energy(), s.viscous_heat(), 0.02 * s.viscous_heat());
      EXPECT_GT(s.viscous_heat(), 1e-3 * ke0);
    }
}

TEST(SphDynamics, FixedStepReplacesTheAdaptiveOne)
{
  // SolverParameters::fixed_step: every step takes it, far below or above the CFL step.
  for (double fixed : {1e-9, 3e-7})
    {
      SolverParameters prm;
      prm.fixed_step = fixed;
      auto s = make_block<2>(vec<2>(4e-3, 4e-3), 1e-3, LatticeType::cubic, prm, rock);
      EXPECT_EQ(s.step(), fixed);
      EXPECT_EQ(s.last_limiter(), "fixed");
    }
}

TEST(SphDynamics, LeapfrogKeepsTheVibrationsEnergyWhereTheMidpointRuleBlowsUp)
{
  // The vibrating block of EnergyConservedWithoutViscosityForSmallVibration, no viscosity,
  // over 30 crossings. The leapfrog's energy error is second order (x ~4 for twice the
  // step) and it stays stable to C = 1.5; the midpoint rule, undamped, grows by
  // (omega dt)^4 / 8 per step and blows up at C = 0.6.
  const auto run = [](Integrator integrator, double courant) {
    SolverParameters prm;
    prm.integrator = integrator;
    prm.alpha      = 0;
    prm.beta       = 0;
    prm.courant    = courant;
    const double a = 1e-3, L = 16 * a;
    auto s = make_block<2>(vec<2>(L, L), a, LatticeType::hexagonal, prm, rock);
    const double v0 = 0.1;
    for (unsigned int i = 0; i < s.state.size(); ++i)
      {
        const double x = s.state.x[i][0] / L - 0.5, y = s.state.x[i][1] / L - 0.5;
        s.state.v[i] = vec<2>(v0 * x, -v0 * y + 0.5 * v0 * std::sin(2 * M_PI * x));
      }
    const double E0 = s.total_energy(), K0 = s.state.kinetic_energy();
    try
      {
        const unsigned int n = s.advance_to(30 * L / rock.longitudinal_speed());
        const double rel = std::abs(s.total_energy() - E0) / K0;
        std::printf("%s, C = %.1f: %u steps, |dE| / K0 = %.3g, K / K0 = %.3f\n",
                    integrator == Integrator::leapfrog ? "leapfrog" : "midpoint", courant, n, rel,
                    s.state.kinetic_energy() / K0);
        if (rel < 1) // energy moved into e: a vibration
          {
            EXPECT_LT(s.state.kinetic_energy() / K0, 0.95);
          }
        return rel;
      }
    catch (const RunError &)
      {
        return std::numeric_limits<double>::infinity();
      }
  };
  const double leap_03 = run(Integrator::leapfrog, 0.3), leap_06 = run(Integrator::leapfrog, 0.6);
  EXPECT_LT(leap_03, 2e-3);
  EXPECT_LT(leap_06, 6e-3);
  EXPECT_GT(leap_06, 3 * leap_03);
  EXPECT_LT(run(Integrator::leapfrog, 1.5), 0.05);
  EXPECT_GT(run(Integrator::midpoint, 0.6), 1.0);
}
