// The Craig-Bampton reduced deal.II body (ElasticBodyParameters::reduced) against the
// full model: exact in the static limit, its first fixed-interface mode at the closed
// form, its dynamics converging with the number of modes, its energy conserved.
#include "fem/elastic_body.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

using tribo::fem::ElasticBody;
using tribo::fem::ElasticBodyParameters;

namespace
{
  /// A steel-like body (E = 100 GPa, nu = 0.33, rho = 7800) of nx x ny cells of 1 um.
  ElasticBodyParameters body(unsigned int nx, unsigned int ny, double h, int modes)
  {
    ElasticBodyParameters p;
    p.cells_x   = nx;
    p.cells_y   = ny;
    p.length    = nx * 1e-6;
    p.thickness = ny * 1e-6;
    p.time_step = h;
    p.reduced   = modes >= 0;
    p.modes     = std::max(modes, 0);
    return p;
  }

  double relative_difference(const Eigen::MatrixXd &a, const Eigen::MatrixXd &b)
  {
    return (a - b).norm() / b.norm();
  }
} // namespace

// Guyan condensation plus the load mode hold every static state. The compliance of
// the step, B (M + theta^2 h^2 K)^-1 B^T, tends to the full model's as h grows: its
// error falls as 1 / h^2 (the modes left out only matter through M). And the static
// solution under the top pressure is the full one.
TEST(FemReduced, StaticLimitIsExact)
{
  for (const int modes : {0, 5})
    {
      double error[2];
      for (const unsigned int i : {0u, 1u})
        {
          const double      h = i == 0 ? 1e-7 : 1e-6; // s; omega_1 = 1.8e9 rad/s
          const ElasticBody full(body(8, 6, h, -1)), reduced(body(8, 6, h, modes));
          EXPECT_EQ(reduced.n_model_dofs(), 2 * 8 + modes + 1);
          error[i] = relative_difference(reduced.boundary_compliance(), full.boundary_compliance());
        }
      EXPECT_GT(error[0] / error[1], 80) << modes << " modes"; // 100 for 1 / h^2
      EXPECT_LT(error[1], 1e-6) << modes << " modes";
    }
  auto p         = body(8, 6, 1e-10, 3);
  p.top_pressure = 1e8;
  ElasticBody reduced(p);
  p.reduced = false;
  ElasticBody full_static(p);
  reduced.static_solve();
  full_static.static_solve();
  for (unsigned int i = 0; i < 8; ++i)
    EXPECT_NEAR(reduced.boundary_displacement(i).y(), full_static.boundary_displacement(i).y(),
                1e-9 * std::abs(full_static.boundary_displacement(i).y()));
  const Eigen::Vector2d mid(4e-6, 3e-6);
  EXPECT_NEAR(reduced.displacement_at(mid).y(), full_static.displacement_at(mid).y(),
              1e-9 * std::abs(full_static.displacement_at(mid).y()));
  EXPECT_NEAR(reduced.elastic_energy(), full_static.elastic_energy(), 1e-9 * full_static.elastic_energy());
}

// With the bottom held, the top held in x and free in y, the lowest mode of the layer
// is its quarter-wave thickness mode: omega_1 = pi c_p / (2 H), c_p the plane-strain
// P-wave speed (below pi c_s / H, the first shear mode, for nu = 0.33).
TEST(FemReduced, FirstModeIsTheQuarterWaveThicknessMode)
{
  const auto        p = body(4, 40, 1e-10, 4);
  const ElasticBody reduced(p);
  const double      nu = p.poisson_ratio, E = p.youngs_modulus;
  const double      c_p = std::sqrt(E * (1 - nu) / ((1 + nu) * (1 - 2 * nu) * p.density));
  const double      omega_1 = M_PI * c_p / (2 * p.thickness);
  ASSERT_EQ(reduced.mode_frequencies().size(), 4u);
  EXPECT_NEAR(reduced.mode_frequencies()[0] / omega_1, 1.0, 0.01);
  for (unsigned int i = 1; i < 4; ++i)
    EXPECT_GE(reduced.mode_frequencies()[i], reduced.mode_frequencies()[i - 1]);
}

// At the contact step the compliance is a dynamic quantity: more modes bring it
// closer to the full model's (54 interior unknowns here).
TEST(FemReduced, DynamicComplianceConvergesWithTheModes)
{
  const double      h = 2e-9;
  const ElasticBody full(body(6, 5, h, -1));
  double            previous = 1e300;
  for (const int modes : {0, 4, 16, 30})
    {
      const ElasticBody reduced(body(6, 5, h, modes));
      const double      error = relative_difference(reduced.boundary_compliance(), full.boundary_compliance());
      std::printf("%2d modes: compliance error %.3e\n", modes, error);
      EXPECT_LT(error, previous) << modes << " modes";
      previous = error;
    }
}

// The reduced theta scheme at theta = 1/2 without damping conserves energy: kinetic
// plus elastic energy changes by the work of the load and of the impulses.
TEST(FemReduced, EnergyBalanceCloses)
{
  auto p               = body(8, 6, 2e-10, 6);
  p.top_pressure       = 1e8;
  p.pressure_ramp_time = 5e-9;
  ElasticBody     b(p);
  std::mt19937    rng(3);
  std::normal_distribution<double> g(0, 1e-7);
  for (unsigned int s = 0; s < 200; ++s)
    {
      b.predict();
      std::vector<Eigen::Vector2d> R(b.n_boundary_nodes());
      for (auto &r : R)
        r = Eigen::Vector2d(g(rng), g(rng));
      b.finalize(R);
    }
  const double energy = b.kinetic_energy() + b.elastic_energy();
  EXPECT_GT(energy, 0);
  EXPECT_NEAR(energy, b.load_work() + b.contact_work(), 1e-9 * (std::abs(b.load_work()) + std::abs(b.contact_work())));
}
