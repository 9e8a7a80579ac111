// The particle first bodies (sph, mlp; coupling/particle_first_body.h) with their chain
// treated implicitly: the compliance they give the solver (its limits and how well it
// predicts the body's real response), and a column of grains resting on a fixed rigid
// wall under top pressure, at a contact step four times the chain's own wave crossing:
// the body must settle at its elastic thickness and stay there, and the energy of grains
// and body must follow the work of the load, the contacts and the damping step by step.
#include "coupling/particle_first_body.h"
#include "dem/engine/moreau_jean.h"

#include <Eigen/Eigenvalues>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>

using namespace tribo;
using dem::Vec2;

namespace
{
  constexpr double s = 1e-6, L = 8 * s, rho = 7800, P = 1e8, E = 1e11, nu = 0.25;
  const double     y_grain = 0.5 * std::sqrt(3.0) * s;

  /// The body of the column below: 8 particles across, 10 s thick, chain at @p bottom.
  coupling::FirstBodyParameters column_body(const std::string &model, double h, double bottom)
  {
    coupling::FirstBodyParameters p;
    p.model = model;
    p.length = L;
    p.thickness = 10 * s;
    p.bottom = bottom;
    p.youngs_modulus = E;
    p.poisson_ratio = nu;
    p.density = rho;
    p.resolution = s;
    p.time_step = h;
    p.pressure = P;
    p.pressure_ramp_time = 2e-8;
    p.compaction_damping = 1;
    coupling::check_first_body(p);
    return p;
  }

  /// h for the chain's c_p h / s = @p courant.
  double step_for(double courant)
  {
    coupling::FirstBodyParameters p = column_body("mlp", 1, 0);
    return courant * s / coupling::p_wave_speed(p);
  }

  /// What a run of the column measured.
  struct ColumnRun
  {
    double top_speed = 0;  ///< mean sinking speed of the loaded top over the last third, m/s
    double worst_balance = 0; ///< worst per-step energy residual / mean |work| of a step
    double window_balance = 0; ///< summed residual over the run / summed |work|
    double wall_force = 0; ///< mean vertical force on the wall over the last third / (P L)
    /// Energy the body's sub-cycles lost over the run (the residual) / what the contacts dissipated.
    double integrator_loss = 0;
    double body_kinetic = 0; ///< the body's mean kinetic energy over the last third, J/m
  };

  /// 8 wall discs (radius s/2) at x = i s, y = 0, one grain in each pocket, and the
  /// body's chain (spacing s, 8 particles, bottom row at y_grain + s) just touching the
  /// grains from above. Step @p h, load ramped over 20 ns, compaction damping (zeta = 1)
  /// until 0.3 us, then @p steps steps in all; from 0.3 us the wall moves along x at
  /// @p wall_speed (m/s), dragging the grains in its pockets under the frictionless chain.
  /// NLGS to @p tolerance, checked every sweep.
  ColumnRun run_column(const std::string &model, double h, unsigned int steps, double wall_speed = 0,
                       double tolerance = 1e-8)
  {
    dem::ParticleSystem sys;
    sys.period = L;
    std::vector<Vec2>   c;
    std::vector<double> r;
    for (int i = 0; i < 8; ++i)
      {
        c.push_back({i * s, 0});
        r.push_back(0.5 * s);
      }
    const unsigned int wall = sys.add_clump(c, r, rho);
    for (auto &d : sys.bodies[wall].drive)
      d = dem::Drive::velocity;
    for (int i = 0; i < 8; ++i)
      sys.add_disc({(i + 0.5) * s, y_grain}, 0.5 * s, rho);

    auto body = coupling::make_deformable_body(column_body(model, h, y_grain + s));

    dem::SolverParameters nlgs;
    nlgs.method    = dem::SolverParameters::Method::nlgs;
    nlgs.tolerance = tolerance;
    nlgs.check_interval = 1;
    dem::MoreauJean mj(0.5, dem::ContactLaw{}, nlgs, 0.05 * s);
    mj.attach(*body, s, {0, -1}, L);

    ColumnRun out;
    const unsigned int damped = static_cast<unsigned int>(3e-7 / h), window = steps - steps / 3;
    double e0 = sys.kinetic_energy() + body->energy();
    double residual = 0, work = 0, top = 0, wall_force = 0, contact_work = 0;
    std::vector<double> step_residual, step_work;
    for (unsigned int i = 0; i < steps; ++i)
      {
        if (i == damped)
          {
            body->start_shearing();
            sys.bodies[wall].velocity = {wall_speed, 0};
          }
        const auto   rep = mj.step(sys, h);
        const double e1  = rep.kinetic_energy + rep.boundary_energy;
        const double rhs = h * (rep.power_external + rep.power_contacts - rep.boundary_dissipation);
        if (i > damped)
          {
            step_residual.push_back(std::abs(e1 - e0 - rhs));
            step_work.push_back(h * (std::abs(rep.power_external) + std::abs(rep.power_contacts) +
                                     std::abs(rep.boundary_dissipation)));
            residual += e1 - e0 - rhs;
            contact_work += h * rep.power_contacts;
            work += step_work.back();
          }
        e0 = e1;
        if (i >= window)
          {
            top += body->external_power() / (P * L);
            out.body_kinetic += body->kinetic_energy() / (steps - window);
            wall_force += -mj.contact_force()[wall].y() / (P * L);
          }
      }
    double mean_work = 0, worst = 0;
    for (double w : step_work)
      mean_work += w / step_work.size();
    for (double r : step_residual)
      worst = std::max(worst, r / mean_work);
    out.top_speed = top / (steps - window);
    out.wall_force = wall_force / (steps - window);
    out.worst_balance = worst;
    out.window_balance = residual / work;
    out.integrator_loss = -residual / -contact_work;
    std::printf("%s, c_p h / s = %.3g, wall at %g m/s: top sinks at %.3g m/s, wall force %.4f P L, energy residual "
                "%.3g of the summed work (worst step %.3g of the mean), %.3g of the contacts' dissipation, body "
                "kinetic energy %.3g J/m\n",
                model.c_str(), h / step_for(1), wall_speed, out.top_speed, out.wall_force, out.window_balance,
                out.worst_balance, out.integrator_loss, out.body_kinetic);
    return out;
  }

  /// The wall carries P L, the top does not sink, the books close per step within 10 % of
  /// a step's mean work and over the run within 1e-3 of the summed work, of which the
  /// body's sub-cycles lose less than 1 % of what the contacts dissipate.
  void expect_column_holds(const ColumnRun &run)
  {
    EXPECT_NEAR(run.wall_force, 1.0, 0.02);
    EXPECT_LT(std::abs(run.top_speed), 0.05) << "the block keeps thinning (m/s)";
    EXPECT_LT(run.worst_balance, 0.1);
    EXPECT_LT(std::abs(run.window_balance), 1e-3);
    EXPECT_LT(std::abs(run.integrator_loss), 0.01);
  }

  /// What the compliance of a body at rest, its top just loaded by P, is at c_p h / s = courant.
  struct Compliance
  {
    double lumped_min = 0, lumped_max = 0; ///< G_kk m over the chain
    double eigen_min = 0;                  ///< smallest eigenvalue of G / largest
    double asymmetry = 0;                  ///< ||D - D^T|| / ||D|| before symmetrising
    double miss = 0;                       ///< the real response against G's prediction
  };

  /// The column's body at rest, its top just loaded by P (no ramp, no damping), for steps @p h.
  std::unique_ptr<coupling::DeformableBody> body_at_rest(const std::string &model, double h)
  {
    auto p = column_body(model, h, 0);
    p.pressure_ramp_time = 0;
    p.compaction_damping = 0;
    return coupling::make_deformable_body(p);
  }

  /// A grain pushing chain particle 3 up and sideways with P s h, its neighbour less.
  std::vector<Vec2> two_grain_impulses(unsigned int nodes, double h)
  {
    std::vector<Vec2> R(nodes, Vec2::Zero());
    R[3] = Vec2(0.3, 1) * P * s * h;
    R[4] = Vec2(-0.1, 0.5) * P * s * h;
    return R;
  }

  Compliance compliance_of(const std::string &model, double courant)
  {
    const double h    = step_for(courant);
    auto         body = body_at_rest(model, h);
    auto &particles = dynamic_cast<coupling::ParticleFirstBody &>(*body);
    body->predict(h);
    const Eigen::MatrixXd G = body->compliance();
    // Lumped mass of a chain particle: rho s^2 (sph, square lattice), rho s^2 sqrt(3) / 2 (mlp).
    const double m = rho * s * s * (model == "mlp" ? 0.5 * std::sqrt(3.0) : 1.0);
    Compliance   out;
    out.lumped_min = (G.diagonal() * m).minCoeff();
    out.lumped_max = (G.diagonal() * m).maxCoeff();
    const Eigen::VectorXd lambda = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(G).eigenvalues();
    out.eigen_min = lambda.minCoeff() / lambda.maxCoeff();
    out.asymmetry = particles.compliance_asymmetry();
    body->finalize(two_grain_impulses(body->n_nodes(), h));
    out.miss = particles.linearisation_error();
    std::printf("%s at c_p h / s = %g: G_kk m in [%.4f, %.4f], eigenvalues down to %.3g of the largest, "
                "asymmetry %.3g, linearisation miss %.3g\n",
                model.c_str(), courant, out.lumped_min, out.lumped_max, out.eigen_min, out.asymmetry, out.miss);
    return out;
  }

  /// Short steps: the lumped mass (the body cannot respond within the step). Long steps:
  /// the compliance falls (the neighbours carry the impulse within the step), stays
  /// positive semi-definite, and predicts the real nonlinear body's chain to
  /// @p long_miss, its finite-difference D symmetric to @p long_asymmetry.
  void expect_compliance_limits(const std::string &model, double long_asymmetry, double long_miss)
  {
    const Compliance short_step = compliance_of(model, 0.02);
    EXPECT_GT(short_step.lumped_min, 0.99);
    EXPECT_LT(short_step.lumped_max, 1.0 + 1e-6);
    const Compliance long_step = compliance_of(model, 4);
    EXPECT_LT(long_step.lumped_max, 0.5);
    EXPECT_GT(long_step.eigen_min, -1e-12);
    EXPECT_LT(short_step.asymmetry, 1e-6);
    EXPECT_LT(short_step.miss, 1e-6);
    EXPECT_LT(long_step.asymmetry, long_asymmetry);
    EXPECT_LT(long_step.miss, long_miss);
  }

  /// The linearisation miss of each of @p steps steps of a body at rest, its top just
  /// loaded by P, at c_p h / s = 4, under the same impulses every step (those of
  /// compliance_of()); the compliance is built once and then only secant-updated.
  std::vector<double> misses_under_a_repeated_load(const std::string &model, unsigned int steps)
  {
    const double h    = step_for(4);
    auto         body = body_at_rest(model, h);
    auto &particles = dynamic_cast<coupling::ParticleFirstBody &>(*body);
    const std::vector<Vec2> R = two_grain_impulses(body->n_nodes(), h);
    std::vector<double> misses;
    for (unsigned int k = 0; k < steps; ++k)
      {
        body->predict(h);
        const Eigen::VectorXd lambda =
          Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(body->compliance()).eigenvalues();
        EXPECT_GT(lambda.minCoeff(), -1e-12 * lambda.maxCoeff()) << "step " << k;
        EXPECT_LT((body->compliance() - body->compliance().transpose()).norm(), 1e-12 * body->compliance().norm());
        body->finalize(R);
        misses.push_back(particles.linearisation_error());
      }
    EXPECT_EQ(particles.compliance_builds(), 1u);
    std::printf("%s under a repeated load: misses", model.c_str());
    for (const double m : misses)
      std::printf(" %.3g", m);
    std::printf("\n");
    return misses;
  }
  /// A particle body's trial advances on a strip of its bottom rows (ParticleBodyParameters::
  /// prediction_depth) against the whole body's: a body 40 s thick at c_p h / s = 4, its top
  /// loaded by P at t = 0 without damping; the compliance at rest, then the free chain
  /// velocities each step while the load's wave crosses the body, reflects at the chain and
  /// rings; from step 20 on both take the same impulses on the chain (P s h per particle, up
  /// and along x, varying along the chain), so that the real advances after trials on the
  /// strip, which leave the engine at S_0 instead of restoring it, are compared too.
  /// Returns the largest differences relative to the whole body's largest |G|, |free
  /// velocity| and chain displacement over the run.
  struct StripMiss
  {
    double compliance, free_velocity, trajectory;
  };
  StripMiss strip_against_whole_body(const std::string &model, double depth)
  {
    const double h = step_for(4);
    auto         prm = column_body(model, h, 0);
    prm.thickness = 40 * s;
    prm.pressure_ramp_time = 0;
    prm.compaction_damping = 0;
    auto whole = coupling::make_deformable_body(prm);
    prm.particle.prediction_depth = depth;
    auto strip = coupling::make_deformable_body(prm);
    const unsigned int n = whole->n_nodes();
    double g_miss = 0, v_run = 0, dv_run = 0, d_run = 0, dd_run = 0;
    std::vector<dem::Vec2> start(n), impulses(n);
    for (unsigned int i = 0; i < n; ++i)
      {
        start[i]    = whole->node_position(i);
        impulses[i] = P * s * h * dem::Vec2(0.5 * std::sin(2 * M_PI * i / n), 1.0);
      }
    for (unsigned int k = 0; k < 40; ++k)
      {
        whole->predict(h);
        strip->predict(h);
        if (k == 0)
          g_miss = (strip->compliance() - whole->compliance()).cwiseAbs().maxCoeff() /
                   whole->compliance().cwiseAbs().maxCoeff();
        double v_max = 0, dv = 0;
        for (unsigned int i = 0; i < n; ++i)
          {
            v_max = std::max(v_max, whole->node_free_velocity(i).norm());
            dv    = std::max(dv, (strip->node_free_velocity(i) - whole->node_free_velocity(i)).norm());
          }
        v_run  = std::max(v_run, v_max);
        dv_run = std::max(dv_run, dv);
        const std::vector<dem::Vec2> loads = k >= 20 ? impulses : std::vector<dem::Vec2>{};
        whole->finalize(loads);
        strip->finalize(loads);
        for (unsigned int i = 0; i < n; ++i) // the end positions (the next step's start)
          {
            d_run  = std::max(d_run, (whole->node_position(i) - start[i]).norm());
            dd_run = std::max(dd_run, (strip->node_position(i) - whole->node_position(i)).norm());
          }
      }
    const StripMiss miss{g_miss, dv_run / v_run, dd_run / d_run};
    std::printf("%s trials on a strip %g wave reaches deep: compliance off by %.3g, free chain velocities by "
                "%.3g, real chain trajectory under impulses by %.3g\n",
                model.c_str(), depth, miss.compliance, miss.free_velocity, miss.trajectory);
    return miss;
  }

  /// A strip three wave reaches deep predicts as the whole body within @p compliance_tolerance
  /// and @p velocity_tolerance (strip_against_whole_body()); one half a reach deep is felt
  /// by the held rows within the step (free velocities off by more than 1e-2), so the
  /// comparison does see a strip that is too thin. Under the same impulses the real chain
  /// trajectories agree to 1e-12 of the chain's displacement (measured: the same bits).
  void expect_strip_predicts_as_the_whole_body(const std::string &model, double compliance_tolerance,
                                               double velocity_tolerance)
  {
    const StripMiss deep = strip_against_whole_body(model, 3);
    EXPECT_LT(deep.compliance, compliance_tolerance);
    EXPECT_LT(deep.free_velocity, velocity_tolerance);
    EXPECT_LT(deep.trajectory, 1e-12);
    EXPECT_GT(strip_against_whole_body(model, 0.5).free_velocity, 0.01);
  }
} // namespace

#ifdef TRIBO_TEST_SPH
TEST(ParticleCoupling, SphComplianceFromLumpedMassToTheBodysResponse)
{
  // The Monaghan viscosity acts on approaching pairs only, so the response of a body at
  // rest depends on the impulse's direction: measured asymmetry 0.23 and miss 0.068
  // (0.023 and 0.0098 with the viscosity off), docs/first_bodies.md.
  expect_compliance_limits("sph", 0.3, 0.1);
}

TEST(ParticleCoupling, SphSecantUpdatesLearnTheResponseToARepeatedLoad)
{
  const std::vector<double> misses = misses_under_a_repeated_load("sph", 12);
  // A fresh build misses by 0.068 (SphComplianceFromLumpedMassToTheBodysResponse); the
  // body's state then changes under the load (0.28 at the second step) and the secant
  // updates learn it: measured 0.0082 and 0.011 at the last two steps.
  EXPECT_GT(misses.front(), 0.03);
  EXPECT_LT(std::max(misses.end()[-1], misses.end()[-2]), 0.3 * misses.front());
}

TEST(ParticleCoupling, SphTrialAdvancesOnAStripGiveTheWholeBodysPrediction)
{
  // As mlp's (the strip takes its own adaptive steps). Measured: the compliance off by
  // 2.2e-15 and the free chain velocities by 3.6e-7 at three wave reaches (before the
  // impulses from step 20 were added: 4.9e-7; 1.8e-9 and 9.4e-5 at two, 2.3e-4 and 6.4e-3
  // at one, 2.4e-2 and 4.0e-2 at half a reach); the real trajectories the same bits.
  expect_strip_predicts_as_the_whole_body("sph", 1e-6, 1e-5);
}

TEST(ParticleCoupling, SphBodyOnGrainsKeepsItsThicknessAtFourWaveCrossingsPerStep)
{
  // 1.5 us at c_p h / s = 4. With the explicit chain (kicked once per contact step, until
  // 2026-11-25) this needed c_p h / s <= 1, and at 0.29 the sub-cycles lost 7 % of what the
  // contacts dissipate.
  expect_column_holds(run_column("sph", step_for(4), 1500));
}
#endif

#ifdef TRIBO_TEST_MLP
TEST(ParticleCoupling, MlpComplianceFromLumpedMassToTheBodysResponse)
{
  // Conservative: D is symmetric but for the Morse bonds' nonlinearity over the probe
  // P s h (measured 0.0037; 5e-6 with a probe of 1e-5 s), which also sets the miss
  // (measured 0.0015; 0.0048 with the small probe).
  expect_compliance_limits("mlp", 0.01, 0.01);
}

TEST(ParticleCoupling, MlpSecantUpdatesLearnTheResponseToARepeatedLoad)
{
  // The Morse bonds' response is nearly linear (a fresh build misses by 0.0015): the updates
  // must not spoil it (measured at most 0.0058).
  const std::vector<double> misses = misses_under_a_repeated_load("mlp", 12);
  EXPECT_LT(*std::max_element(misses.begin(), misses.end()), 0.01);
}

TEST(ParticleCoupling, MlpTrialAdvancesOnAStripGiveTheWholeBodysPrediction)
{
  // Three wave reaches (15 of the body's 46 rows): measured 0 and 1.6e-13 (before the
  // impulses from step 20 were added: 1.9e-13; at two reaches 0 and 4.6e-9, at one 1.1e-8
  // and 1.8e-3, at half a reach 7.9e-4 and 5.5e-2); the real trajectories the same bits.
  expect_strip_predicts_as_the_whole_body("mlp", 1e-6, 1e-6);
}

TEST(ParticleCoupling, MlpBodyOnGrainsKeepsItsThicknessAtFourWaveCrossingsPerStep)
{
  // As sph; the explicit chain's sub-cycles lost 6 % of the contacts' dissipation at 0.29.
  expect_column_holds(run_column("mlp", step_for(4), 1500));
}

TEST(ParticleCoupling, MlpBodyOverShearedGrainsAtEightWaveCrossingsIsAsQuietAsAtTwo)
{
  // The wall drags its grains at 5 m/s under the chain from 0.3 us. The body's kinetic
  // energy over the last third must not depend on the step (measured 2026-11-26 with NLGS
  // to 1e-8: 4.4e-6 J/m at c_p h / s = 1, 4.0e-6 at 2, 5.5e-6 at 8; to 1e-5, as here:
  // 3.7e-6 at 2, 5.5e-6 at 8). The chain kinematics that took the particles' real start
  // velocities as v_b (until 2026-11-26) fed their vibration back into the grains with
  // gain one at theta = 1/2: 5.9e-5 J/m at 2, 3.1e-4 at 8 (docs/first_bodies.md,
  // "Kinematics"). NLGS to 1e-5: with the grains sliding under the chain, 1e-8 costs a
  // minute.
  const ColumnRun reference = run_column("mlp", step_for(2), 6000, 5.0, 1e-5);
  const ColumnRun long_step = run_column("mlp", step_for(8), 1500, 5.0, 1e-5);
  EXPECT_LT(long_step.body_kinetic, 2 * reference.body_kinetic);
  EXPECT_GT(long_step.body_kinetic, 0.5 * reference.body_kinetic);
  expect_column_holds(long_step);
}
#endif
