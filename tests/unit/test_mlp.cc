// Unit tests of the movable lattice particles module against closed forms.
#include "core/errors.h"
#include "mlp/analysis.h"
#include "mlp/interaction.h"
#include "mlp/langevin.h"
#include "mlp/linear_theory.h"
#include "mlp/neighbour_list.h"
#include "mlp/particles.h"
#include "mlp/random.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

using namespace tribo;
using namespace tribo::mlp;

namespace
{
  constexpr double c0   = 1e-6; // lattice spacing r0, m
  constexpr double kc   = 1e9;  // U''(r0), N/m^2
  constexpr double rho0 = 7800; // kg/m^3
  const double     mass = rho0 * area_per_particle(LatticeType::hexagonal, c0); // kg/m

  InteractionParameters parameters(double f0, unsigned int n = 6,
                                   ReturnForceForm form = ReturnForceForm::paper)
  {
    InteractionParameters p;
    p.r0        = c0;
    p.stiffness = kc;
    p.f0        = f0;
    p.n         = n;
    p.form      = form;
    return p;
  }

  /// A periodic nx x ny hexagonal patch and its box.
  void periodic_patch(Particles &particles, Box &box, unsigned int nx, unsigned int ny)
  {
    add_lattice_patch(particles, LatticeType::hexagonal, Vec2(0.25 * c0, 0.25 * c0), nx, ny, c0,
                      mass);
    box = periodic_box(LatticeType::hexagonal, nx, ny, c0, true);
  }

  /// Virial stress of the patch after the homogeneous deformation x -> (I + G) x
  /// (G upper triangular: G_yx = 0), box deformed alike.
  Eigen::Matrix2d stress_under(const InteractionParameters &p, const Eigen::Matrix2d &G)
  {
    Particles particles;
    Box       box;
    periodic_patch(particles, box, 12, 12);
    const double ly = box.ly;
    for (Vec2 &x : particles.position)
      x += G * x;
    box.lx *= 1 + G(0, 0);
    box.ly   = ly * (1 + G(1, 1));
    box.tilt = G(0, 1) * ly;
    ForceField field(p);
    return field.virial_stress(particles, box, box.lx * box.ly);
  }

  /// d sigma / d G along the direction @p G (central difference), Pa.
  Eigen::Matrix2d stiffness_along(const InteractionParameters &p, const Eigen::Matrix2d &G)
  {
    const double eps = 1e-6;
    return (stress_under(p, eps * G) - stress_under(p, -eps * G)) / (2 * eps);
  }

  struct MeasuredModuli
  {
    double c11, c12, mu_pure, simple_xy, simple_yx, youngs, poisson;
  };

  MeasuredModuli measure_moduli(const InteractionParameters &p)
  {
    MeasuredModuli        m;
    Eigen::Matrix2d       G;
    G << 1, 0, 0, 0;
    const Eigen::Matrix2d u = stiffness_along(p, G);
    m.c11 = u(0, 0);
    m.c12 = u(1, 1);
    G << 1, 0, 0, -1;
    const Eigen::Matrix2d s = stiffness_along(p, G);
    m.mu_pure = (s(0, 0) - s(1, 1)) / 4;
    G << 0, 1, 0, 0;
    const Eigen::Matrix2d t = stiffness_along(p, G);
    m.simple_xy = t(0, 1);
    m.simple_yx = t(1, 0);
    m.youngs    = (m.c11 * m.c11 - m.c12 * m.c12) / m.c11;
    m.poisson   = m.c12 / m.c11;
    return m;
  }
} // namespace

// ---------------------------------------------------------------- return forces

TEST(MlpReturnForce, VanishesOnAxesAndTurnsBondsBack)
{
  for (unsigned int n : {6u, 4u})
    for (ReturnForceForm form : {ReturnForceForm::paper, ReturnForceForm::potential})
      {
        const double      f0 = 50;
        const Interaction model(parameters(f0, n, form));
        const double      axis = 2 * M_PI / n;
        for (unsigned int k = 0; k < n; ++k)
          {
            const double phi_k = k * axis;
            const Vec2   on_axis = c0 * Vec2(std::cos(phi_k), std::sin(phi_k));
            EXPECT_LT(model.return_force(on_axis).norm(), 1e-12 * f0) << "n " << n << " k " << k;
            // Half-way between axes: an unstable zero.
            const double phi_h = phi_k + 0.5 * axis;
            EXPECT_LT(model.return_force(c0 * Vec2(std::cos(phi_h), std::sin(phi_h))).norm(),
                      1e-12 * f0);
            for (double frac : {-0.4, -0.1, 0.1, 0.25, 0.4})
              {
                const double delta = frac * axis; // |delta| < half a sector
                const double phi   = phi_k + delta;
                const Vec2   d     = c0 * Vec2(std::cos(phi), std::sin(phi));
                const Vec2   e_phi(-std::sin(phi), std::cos(phi));
                const Vec2   F = model.return_force(d);
                // Eq. (18): F = f0 sin(n phi) e_phi on the particle i (d = x_j - x_i).
                EXPECT_NEAR(F.dot(e_phi), f0 * std::sin(n * phi), 1e-12 * f0);
                EXPECT_NEAR(F.x(), -f0 * std::sin(phi) * std::sin(n * phi), 1e-12 * f0);
                EXPECT_NEAR(F.y(), f0 * std::cos(phi) * std::sin(n * phi), 1e-12 * f0);
                // Moving i along F turns the bond back towards the axis phi_k.
                const Vec2   d_new   = d - 1e-3 * c0 * F / F.norm();
                const double phi_new = std::atan2(d_new.y(), d_new.x());
                double       back    = std::remainder(phi_new - phi_k, 2 * M_PI);
                EXPECT_LT(std::abs(back), std::abs(delta)) << "n " << n << " frac " << frac;
                // Equal and opposite on j.
                const Vec2 Fj = model.return_force(-d);
                EXPECT_EQ(Fj.x(), -F.x());
                EXPECT_EQ(Fj.y(), -F.y());
              }
          }
      }
}

TEST(MlpReturnForce, PotentialFormIsMinusGradientOfV)
{
  // F_i = +dV/dd for V(d) = (f0 r0/n)(1 - cos n phi) S(r) + U(r).
  const Interaction model(parameters(80, 6, ReturnForceForm::potential));
  for (const Vec2 &d : {Vec2(1.05, 0.2), Vec2(-0.7, 0.8), Vec2(1.25, 0.1), Vec2(0.3, -1.22)})
    {
      const Vec2   x = c0 * d;
      const double h = 1e-6 * c0;
      const Vec2   grad((model.energy(x + Vec2(h, 0)) - model.energy(x - Vec2(h, 0))) / (2 * h),
                      (model.energy(x + Vec2(0, h)) - model.energy(x - Vec2(0, h))) / (2 * h));
      EXPECT_NEAR((model.force(x) - grad).norm(), 0, 1e-6 * grad.norm() + 1e-9 * kc * c0);
    }
}

TEST(MlpForces, PairForcesSumToZero)
{
  Particles particles;
  add_lattice_patch(particles, LatticeType::hexagonal, Vec2(0, 0), 20, 20, c0, mass);
  RandomSource rng(7);
  for (Vec2 &x : particles.position)
    x += 0.15 * c0 * Vec2(rng.normal(), rng.normal());
  Box box;
  box.periodic_x = true;
  box.lx         = 20 * c0;
  for (ReturnForceForm form : {ReturnForceForm::paper, ReturnForceForm::potential})
    {
      ForceField field(parameters(100, 6, form));
      field.compute(particles, box);
      Vec2   total = Vec2::Zero();
      double scale = 0;
      for (const Vec2 &f : particles.force)
        {
          total += f;
          scale += f.norm();
        }
      EXPECT_GT(scale, 0);
      EXPECT_LT(total.norm(), 1e-13 * scale);
      std::printf("[ MLP      ] total force / sum |F| = %.2e (%s form)\n", total.norm() / scale,
                  form == ReturnForceForm::paper ? "paper" : "potential");
    }
}

TEST(MlpForces, ParallelGatherIsBitwiseDeterministic)
{
  Particles particles;
  add_lattice_patch(particles, LatticeType::hexagonal, Vec2(0, 0), 60, 60, c0, mass);
  RandomSource rng(3);
  for (Vec2 &x : particles.position)
    x += 0.1 * c0 * Vec2(rng.normal(), rng.normal());
  Box        box;
  ForceField serial(parameters(100)), parallel(parameters(100));
  serial.set_parallel(false);
  Particles a = particles, b = particles;
  serial.compute(a, box);
  parallel.compute(b, box);
  for (unsigned int i = 0; i < a.size(); ++i)
    ASSERT_TRUE(a.force[i] == b.force[i]) << "particle " << i;
}

// ---------------------------------------------------------------- neighbour list

TEST(MlpNeighbours, CellListMatchesBruteForceInTiltedPeriodicBox)
{
  Particles particles;
  Box       box;
  box.periodic_x = box.periodic_y = true;
  box.lx                          = 9.3 * c0;
  box.ly                          = 7.1 * c0;
  box.tilt                        = 0.8 * c0;
  add_random_particles(particles, Vec2(0, 0), Vec2(box.lx, box.ly), 60, 0.5 * c0, mass, 11);
  NeighbourList list(1.35 * c0, 0.3 * c0);
  list.build(particles, box);
  std::set<std::pair<unsigned int, unsigned int>> found(list.pairs().begin(), list.pairs().end());
  EXPECT_EQ(found.size(), list.pairs().size()); // no duplicates
  unsigned int expected = 0;
  for (unsigned int i = 0; i < particles.size(); ++i)
    for (unsigned int j = i + 1; j < particles.size(); ++j)
      if (box.minimum_image(particles.position[j] - particles.position[i]).norm() < 1.65 * c0)
        {
          ++expected;
          EXPECT_TRUE(found.count({i, j})) << i << " " << j;
        }
  EXPECT_EQ(expected, list.pairs().size());
  // Small moves keep the list; a move beyond skin/2 rebuilds it.
  particles.position[5].x() += 0.1 * c0;
  EXPECT_FALSE(list.needs_rebuild(particles, box));
  particles.position[5].x() += 0.1 * c0;
  EXPECT_TRUE(list.needs_rebuild(particles, box));
}

// ---------------------------------------------------------------- linear theory

TEST(MlpModuli, HexagonalCentralSpringsGivePoissonOneThird)
{
  const MeasuredModuli      m = measure_moduli(parameters(0));
  const HexagonalElasticity h = hexagonal_elasticity(0, kc, c0, mass);
  std::printf("[ MLP      ] f0 = 0: C11 %.5g C12 %.5g (theory %.5g %.5g) Pa, mu pure %.5g "
              "simple %.5g (theory %.5g), nu %.5f\n",
              m.c11, m.c12, h.lambda + 2 * h.mu, h.lambda, m.mu_pure, m.simple_xy, h.mu,
              m.poisson);
  EXPECT_NEAR(m.poisson, 1.0 / 3.0, 1e-3);
  EXPECT_NEAR(m.c11 / (h.lambda + 2 * h.mu), 1, 1e-3);
  EXPECT_NEAR(m.c12 / h.lambda, 1, 1e-3);
  EXPECT_NEAR(m.mu_pure / h.mu, 1, 1e-3);
  EXPECT_NEAR(m.simple_xy / h.mu, 1, 1e-3);
  EXPECT_NEAR(m.simple_yx / h.mu, 1, 1e-3);
  // Area per particle: mu = sqrt(3)(k1 + k2/4) (area (sqrt(3)/2) c^2), twice the
  // paper's eq. (11) (sqrt(3)/2)(k1 + k2/4), which divides by sqrt(3) c^2.
  const double mu_paper = 0.5 * std::sqrt(3.0) * (0 + 0.25 * kc);
  EXPECT_NEAR(m.mu_pure / mu_paper, 2, 2e-3);
}

TEST(MlpModuli, ReturnForcesMatchLinearTheoryAndSplitPureFromSimpleShear)
{
  for (ReturnForceForm form : {ReturnForceForm::paper, ReturnForceForm::potential})
    {
      const double              kt = 0.5 * kc, f0 = kt * c0 / 6;
      const MeasuredModuli      m  = measure_moduli(parameters(f0, 6, form));
      const Interaction         model(parameters(f0, 6, form));
      const HexagonalElasticity h = hexagonal_elasticity(model.k1(), model.k2(), c0, mass);
      std::printf("[ MLP      ] k_t = k_c/2 (%s): C11 %.5g/%.5g C12 %.5g/%.5g pure shear %.5g/%.5g "
                  "simple shear xy %.5g/%.5g yx %.5g/%.5g Pa (measured/theory); nu %.4f/%.4f; "
                  "Navier mu_N %.5g lambda_N %.5g\n",
                  form == ReturnForceForm::paper ? "paper" : "potential", m.c11,
                  h.lambda + 2 * h.mu, m.c12, h.lambda, m.mu_pure, h.mu, m.simple_xy,
                  h.simple_shear_modulus, m.simple_yx, h.mu - 0.5 * h.rotation_modulus,
                  m.poisson, h.poisson_ratio, h.mu_navier, h.lambda_navier);
      EXPECT_NEAR(m.c11 / (h.lambda + 2 * h.mu), 1, 1e-3);
      EXPECT_NEAR(m.c12 / h.lambda, 1, 1e-3);
      EXPECT_NEAR(m.mu_pure / h.mu, 1, 1e-3);
      EXPECT_NEAR(m.simple_xy / h.simple_shear_modulus, 1, 1e-3);
      EXPECT_NEAR(m.simple_yx / (h.mu - 0.5 * h.rotation_modulus), 1, 1e-3);
      EXPECT_NEAR(m.poisson / h.poisson_ratio, 1, 1e-3);
      EXPECT_NEAR(h.simple_shear_modulus, h.mu_navier, 1e-9 * h.mu);
      // Simple shear is stiffer than pure shear by C/2 = (sqrt(3)/2) k_t.
      EXPECT_GT(m.simple_xy / m.mu_pure, 1.5);
    }
}

TEST(MlpModuli, ParameterMappingRoundTrips)
{
  for (double nu : {1.0 / 3.0, 0.2, 0.0, -0.5})
    {
      const double         E     = 2e9;
      const HexagonalModel model = hexagonal_model_for(E, nu, c0);
      InteractionParameters p    = parameters(model.f0);
      p.stiffness                = model.stiffness;
      const MeasuredModuli m     = measure_moduli(p);
      std::printf("[ MLP      ] target E %.4g Pa nu %.4f -> k_c %.4g Pa f0 %.4g N/m -> measured E "
                  "%.4g nu %.4f\n",
                  E, nu, model.stiffness, model.f0, m.youngs, m.poisson);
      EXPECT_NEAR(m.youngs / E, 1, 5e-3);
      EXPECT_NEAR(m.poisson, nu, 5e-3);
    }
  // Navier target: the bulk-equation moduli of eq. (11) come back.
  const HexagonalModel nav = hexagonal_model_for(2e9, 0.25, c0, MappingTarget::navier);
  const Interaction    model(parameters(nav.f0));
  InteractionParameters p = parameters(nav.f0);
  p.stiffness             = nav.stiffness;
  const Interaction         mn(p);
  const HexagonalElasticity h  = hexagonal_elasticity(mn.k1(), mn.k2(), c0, mass);
  const double              ln = h.lambda_navier, un = h.mu_navier;
  EXPECT_NEAR(4 * un * (ln + un) / (ln + 2 * un) / 2e9, 1, 1e-9);
  EXPECT_NEAR(ln / (ln + 2 * un), 0.25, 1e-9);
  // Out of reach: nu > 1/3.
  EXPECT_THROW(hexagonal_model_for(2e9, 0.4, c0), InputError);
}

TEST(MlpModuli, StableStepFromStiffestBond)
{
  // Hexagonal central springs: omega_max^2 = 6 k/m (M point); square: 4 (k_c + k_t)/m.
  EXPECT_NEAR(max_angular_frequency(LatticeType::hexagonal, kc, 0, mass) /
                std::sqrt(6 * kc / mass), 1, 1e-3);
  EXPECT_NEAR(max_angular_frequency(LatticeType::square, kc, 0.3 * kc, mass) /
                std::sqrt(4 * 1.3 * kc / mass), 1, 1e-3);
}

// ---------------------------------------------------------------- Langevin

TEST(MlpLangevin, StepAboveLimitIsRefusedWithTheNumbers)
{
  Particles particles;
  add_lattice_patch(particles, LatticeType::hexagonal, Vec2(0, 0), 4, 4, c0, mass);
  ForceField         field(parameters(0));
  LangevinParameters lp;
  lp.time_step         = 1e-12;
  LangevinIntegrator ok(field, particles, lp);
  const double       limit = ok.max_time_step();
  EXPECT_NEAR(limit, 0.5 * 2 / std::sqrt(6 * kc / mass), 1e-3 * limit);
  lp.time_step = 1.5 * limit;
  try
    {
      LangevinIntegrator bad(field, particles, lp);
      FAIL() << "no InputError";
    }
  catch (const InputError &e)
    {
      const std::string msg = e.what();
      std::printf("[ MLP      ] %s\n", msg.c_str());
      EXPECT_NE(msg.find("time step " + to_text(1.5 * limit) + " s exceeds the stable limit " +
                         to_text(limit) + " s"),
                std::string::npos);
      EXPECT_NE(msg.find("use a time step of at most " + to_text(limit) + " s"),
                std::string::npos);
    }
  // At the limit the undamped lattice stays bounded.
  lp.time_step = limit;
  Box                box = periodic_box(LatticeType::hexagonal, 4, 4, c0, true);
  LangevinIntegrator at_limit(field, particles, lp);
  RandomSource       rng(5);
  for (Vec2 &v : particles.velocity)
    v = Vec2(rng.normal(), rng.normal());
  const double e0 = particles.kinetic_energy();
  at_limit.run(particles, box, 2000);
  EXPECT_LT(particles.kinetic_energy() + field.potential_energy(particles, box) -
              (-3.0 * particles.size() * field.interaction().potential().depth()),
            2 * e0);
}

TEST(MlpLangevin, NonFiniteStateNamesTheParticle)
{
  Particles particles;
  add_lattice_patch(particles, LatticeType::hexagonal, Vec2(0, 0), 4, 4, c0, mass);
  ForceField         field(parameters(0));
  LangevinParameters lp;
  lp.time_step = 1e-11;
  LangevinIntegrator integrator(field, particles, lp);
  particles.velocity[3].y() = std::nan("");
  try
    {
      integrator.step(particles, Box());
      FAIL() << "no RunError";
    }
  catch (const RunError &e)
    {
      EXPECT_NE(std::string(e.what()).find("particle 3 "), std::string::npos) << e.what();
    }
}

TEST(MlpLangevin, EquipartitionAndVelocityAutocorrelation)
{
  // Free particles (3 r0 apart: no pairs). eta dt/m = 0.05, k_B T = m (1 m/s)^2.
  Particles particles;
  const unsigned int side = 32;
  add_lattice_patch(particles, LatticeType::square, Vec2(0, 0), side, side, 3 * c0, mass);
  const unsigned int n = particles.size();
  ForceField         field(parameters(0));
  LangevinParameters lp;
  lp.time_step      = 2e-10;
  lp.damping        = 0.05 * mass / lp.time_step;
  lp.thermal_energy = mass * 1.0;
  lp.seed           = 42;
  LangevinIntegrator integrator(field, particles, lp);
  const Box          box;
  integrator.run(particles, box, 300); // 15 relaxation times m/eta
  const unsigned int steps = 4000, lag_max = 40;
  std::vector<double> ke_sum(n, 0.0);              // per particle: sum m v_x^2/2
  std::vector<Vec2>   ring(n * (lag_max + 1));     // v history
  double              acf[3] = {0, 0, 0}, acf0 = 0;
  const unsigned int  lags[3] = {10, 20, 40};
  unsigned long long  acf_count = 0;
  for (unsigned int s = 0; s < steps; ++s)
    {
      integrator.step(particles, box);
      for (unsigned int i = 0; i < n; ++i)
        {
          const Vec2 &v = particles.velocity[i];
          ke_sum[i] += 0.5 * mass * v.x() * v.x();
          ring[(s % (lag_max + 1)) * n + i] = v;
          if (s >= lag_max)
            {
              acf0 += v.squaredNorm();
              for (unsigned int l = 0; l < 3; ++l)
                acf[l] += v.dot(ring[((s - lags[l]) % (lag_max + 1)) * n + i]);
            }
        }
      if (s >= lag_max)
        ++acf_count;
    }
  // Particles are independent: the error bar is the spread of per-particle
  // time averages over sqrt(n).
  double mean = 0, var = 0;
  for (double k : ke_sum)
    mean += k / steps / n;
  for (double k : ke_sum)
    var += (k / steps - mean) * (k / steps - mean) / (n - 1);
  const double se = std::sqrt(var / n), target = 0.5 * lp.thermal_energy;
  std::printf("[ MLP      ] <m v_x^2/2> / (k_B T/2) = %.4f +- %.4f (1 s.e.)\n", mean / target,
              se / target);
  EXPECT_LT(std::abs(mean - target), 4 * se);
  EXPECT_LT(std::abs(mean / target - 1), 0.02);
  for (unsigned int l = 0; l < 3; ++l)
    {
      const double measured = acf[l] / acf0;
      const double expected = std::exp(-lp.damping * lags[l] * lp.time_step / mass);
      std::printf("[ MLP      ] VACF(t = %.2f m/eta) = %.4f, exp(-eta t/m) = %.4f\n",
                  lags[l] * 0.05, measured, expected);
      EXPECT_NEAR(measured, expected, 0.01);
    }
}

// ---------------------------------------------------------------- waves

namespace
{
  /// Angular frequency of the mode u_@p comp = A sin(k x) of a lattice: the
  /// zero crossings of its projection over about two periods. @p lateral adds
  /// u_y = -nu (y - y_c) A k cos(k x) (the Poisson contraction of a strip).
  double mode_frequency(Particles &particles, const Box &box, const InteractionParameters &p,
                        unsigned int comp, double lateral_nu, double omega_guess)
  {
    const double                    k = 2 * M_PI / box.lx, A = 1e-4 * c0;
    const std::vector<Vec2>         x0 = particles.position;
    double                          yc = 0;
    for (const Vec2 &x : x0)
      yc += x.y() / x0.size();
    for (unsigned int i = 0; i < particles.size(); ++i)
      {
        particles.position[i][comp] += A * std::sin(k * x0[i].x());
        if (lateral_nu != 0)
          particles.position[i].y() -=
            lateral_nu * (x0[i].y() - yc) * A * k * std::cos(k * x0[i].x());
      }
    ForceField         field(p);
    LangevinParameters lp;
    lp.time_step = 0.25 * 2 / max_angular_frequency(LatticeType::hexagonal, p.stiffness,
                                                    field.interaction().transverse_stiffness(),
                                                    mass);
    LangevinIntegrator integrator(field, particles, lp);
    const unsigned int steps = static_cast<unsigned int>(2.3 * 2 * M_PI / omega_guess /
                                                         lp.time_step);
    std::vector<double> crossings;
    double              previous = 0;
    for (unsigned int s = 0; s <= steps; ++s)
      {
        double a = 0;
        for (unsigned int i = 0; i < particles.size(); ++i)
          a += box.minimum_image(particles.position[i] - x0[i])[comp] * std::sin(k * x0[i].x());
        if (s > 0 && (a > 0) != (previous > 0))
          crossings.push_back(integrator.time() - lp.time_step * a / (a - previous));
        previous = a;
        integrator.step(particles, box);
      }
    EXPECT_GE(crossings.size(), 3u);
    return M_PI * (crossings.size() - 1) / (crossings.back() - crossings.front());
  }
} // namespace

TEST(MlpWaves, LongitudinalAndTransverseSpeedsInPeriodicLattice)
{
  const double kt = 0.5 * kc;
  for (double f0 : {0.0, kt * c0 / 6})
    {
      const InteractionParameters p = parameters(f0);
      const Interaction           model(p);
      const HexagonalElasticity   h = hexagonal_elasticity(model.k1(), model.k2(), c0, mass);
      for (unsigned int comp : {0u, 1u})
        {
          Particles particles;
          Box       box;
          add_lattice_patch(particles, LatticeType::hexagonal, Vec2(0.25 * c0, 0.25 * c0), 48, 6,
                            c0, mass);
          box               = periodic_box(LatticeType::hexagonal, 48, 6, c0, true);
          const double k    = 2 * M_PI / box.lx;
          const double c_th = comp == 0 ? h.longitudinal_speed : h.transverse_speed;
          const double c_me = mode_frequency(particles, box, p, comp, 0, c_th * k) / k;
          std::printf("[ MLP      ] f0 = %.3g N/m %s wave: %.2f m/s, theory %.2f m/s "
                      "(sqrt(mu_pure/rho) = %.2f)\n",
                      f0, comp == 0 ? "longitudinal" : "transverse", c_me, c_th,
                      std::sqrt(h.mu / h.density));
          EXPECT_NEAR(c_me / c_th, 1, 0.01);
        }
    }
}

TEST(MlpWaves, StripWaveFollowsPureStrainYoungsModulus)
{
  // Free top and bottom: uniaxial stress, c = sqrt(E/rho) with the pure-strain E
  // (the Navier constants of eq. (11) would give a 10 % lower speed here).
  const double                kt = 0.5 * kc;
  const InteractionParameters p  = parameters(kt * c0 / 6);
  const Interaction           model(p);
  const HexagonalElasticity   h = hexagonal_elasticity(model.k1(), model.k2(), c0, mass);
  Particles                   particles;
  // 16 rows: the free edges soften the strip by O(1/rows) (6 rows: -1.9 %).
  add_lattice_patch(particles, LatticeType::hexagonal, Vec2(0.25 * c0, 0.25 * c0), 64, 16, c0,
                    mass);
  const Box    box = periodic_box(LatticeType::hexagonal, 64, 16, c0, false);
  const double k   = 2 * M_PI / box.lx;
  const double c_s = std::sqrt(h.youngs_modulus / h.density);
  const double ln = h.lambda_navier, un = h.mu_navier;
  const double c_n = std::sqrt(4 * un * (ln + un) / (ln + 2 * un) / h.density);
  const double c_me = mode_frequency(particles, box, p, 0, h.poisson_ratio, c_s * k) / k;
  std::printf("[ MLP      ] strip wave %.2f m/s, sqrt(E/rho) %.2f m/s (Navier E: %.2f m/s)\n",
              c_me, c_s, c_n);
  EXPECT_NEAR(c_me / c_s, 1, 0.02);
}

// ---------------------------------------------------------------- analysis

TEST(MlpAnalysis, StructureFactorShowsLatticeSymmetry)
{
  Particles hex, square;
  add_lattice_patch(hex, LatticeType::hexagonal, Vec2(0, 0), 12, 12, c0, mass);
  add_lattice_patch(square, LatticeType::square, Vec2(0, 0), 12, 12, c0, mass);
  const double b_hex = 4 * M_PI / (std::sqrt(3.0) * c0), b_sq = 2 * M_PI / c0;
  // 3 x 3 grid: node (1, 2) is (0, q_max), node (2, 1) is (q_max, 0).
  const Grid2D sh = structure_factor(hex, b_hex, 3), ss = structure_factor(square, b_sq, 3);
  EXPECT_NEAR(sh(1, 1) / hex.size(), 1, 1e-12);           // S(0) = N
  EXPECT_NEAR(sh(1, 2) / hex.size(), 1, 1e-9);            // Bragg peak at 90 degrees
  EXPECT_LT(sh(2, 1) / hex.size(), 0.05);                 // no peak at 0 degrees
  EXPECT_NEAR(ss(2, 1) / square.size(), 1, 1e-9);         // square: peaks on the axes
  EXPECT_NEAR(ss(1, 2) / square.size(), 1, 1e-9);
  EXPECT_NEAR(ss(2, 2) / square.size(), 1, 1e-9);         // and (b, b)
  // Real-space correlation: six nearest neighbours per particle in the bulk.
  Box          box  = periodic_box(LatticeType::hexagonal, 12, 12, c0, true);
  Particles    phex;
  add_lattice_patch(phex, LatticeType::hexagonal, Vec2(0.25 * c0, 0.25 * c0), 12, 12, c0, mass);
  const Grid2D g = pair_correlation(phex, box, 1.2 * c0, 24);
  double       count = 0;
  for (double v : g.values)
    count += v * g.dx * g.dy;
  EXPECT_NEAR(count, 6, 1e-9);
}

TEST(MlpAnalysis, GaussianDensityAndWidth)
{
  Particles particles;
  add_lattice_patch(particles, LatticeType::hexagonal, Vec2(0, 0), 6, 5, c0, mass);
  const double lambda = 0.2 * c0 * c0;
  const Grid2D g = gaussian_density(particles, Vec2(-4 * c0, -4 * c0), Vec2(10 * c0, 8 * c0), 281,
                                    241, lambda);
  double integral = 0;
  for (double v : g.values)
    integral += v * g.dx * g.dy;
  EXPECT_NEAR(integral / (particles.size() * M_PI * lambda), 1, 1e-6);
  const double h0 = extent(particles, 1);
  EXPECT_NEAR(h0, 4 * 0.5 * std::sqrt(3.0) * c0, 1e-15);
  for (Vec2 &x : particles.position)
    x.y() *= 0.9;
  EXPECT_NEAR(normalised_width(particles, h0), 0.9, 1e-12);
}
