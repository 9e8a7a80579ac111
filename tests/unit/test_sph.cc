/// @file Unit tests of the solid-SPH module against closed forms.

#include "core/errors.h"
#include "sph/boundary_force.h"
#include "sph/eos.h"
#include "sph/kernel.h"
#include "sph/lattice.h"
#include "sph/particles.h"
#include "sph/solver.h"

#include "tests/unit/sph_test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>

using namespace tribo::sph;
using tribo::RunError;
using tribo::sph::testing::vec;

namespace
{
  /// Particles at least @p margin inside the bounding box of @p s.
  template <int dim>
  std::vector<unsigned int> interior(const ParticleState<dim> &s, double margin)
  {
    Tensor<1, dim> lo = s.x[0], hi = s.x[0];
    for (const auto &p : s.x)
      for (unsigned int d = 0; d < dim; ++d)
        {
          lo[d] = std::min(lo[d], p[d]);
          hi[d] = std::max(hi[d], p[d]);
        }
    std::vector<unsigned int> out;
    for (unsigned int i = 0; i < s.size(); ++i)
      {
        bool in = true;
        for (unsigned int d = 0; d < dim; ++d)
          in = in && s.x[i][d] > lo[d] + margin && s.x[i][d] < hi[d] - margin;
        if (in)
          out.push_back(i);
      }
    return out;
  }
} // namespace

// ---------------------------------------------------------------- kernel

TEST(SphKernel, NormalisationIntegratesToOne2D)
{
  const double h = 0.7, dx = h / 100;
  double       sum = 0;
  for (double x = -2 * h + dx / 2; x < 2 * h; x += dx)
    for (double y = -2 * h + dx / 2; y < 2 * h; y += dx)
      sum += CubicSplineKernel<2>::value(std::hypot(x, y), h) * dx * dx;
  EXPECT_NEAR(sum, 1.0, 1e-3);
  EXPECT_NEAR(CubicSplineKernel<2>::normalisation(h), 10 / (7 * M_PI * h * h), 1e-15);
}

TEST(SphKernel, NormalisationIntegratesToOne3D)
{
  const double h = 1.3, dx = h / 30;
  double       sum = 0;
  for (double x = -2 * h + dx / 2; x < 2 * h; x += dx)
    for (double y = -2 * h + dx / 2; y < 2 * h; y += dx)
      for (double z = -2 * h + dx / 2; z < 2 * h; z += dx)
        sum += CubicSplineKernel<3>::value(std::sqrt(x * x + y * y + z * z), h) * dx * dx * dx;
  EXPECT_NEAR(sum, 1.0, 1e-3);
}

TEST(SphKernel, GradientIsMinusDerivativeAlongSeparationAndSupportIs2h)
{
  const double h = 0.5;
  for (double q : {0.3, 0.9, 1.0, 1.5, 1.99})
    {
      const Tensor<1, 3> r  = (q * h / std::sqrt(14.0)) * vec<3>(1, -2, 3);
      const Tensor<1, 3> g  = CubicSplineKernel<3>::gradient(r, h);
      const double       d  = 1e-6 * h;
      const double       fd = (CubicSplineKernel<3>::value(q * h + d, h) -
                         CubicSplineKernel<3>::value(q * h - d, h)) / (2 * d);
      // grad_i W = (dW/dr) r/|r| with dW/dr < 0: g points along -r.
      EXPECT_LT(CubicSplineKernel<3>::derivative(q * h, h), 0);
      EXPECT_NEAR((g - (fd / r.norm()) * r).norm() / std::abs(fd), 0, 1e-6);
      EXPECT_NEAR(g * r / (g.norm() * r.norm()), -1, 1e-12);
    }
  EXPECT_EQ(CubicSplineKernel<2>::value(2 * h, h), 0);
  EXPECT_EQ(CubicSplineKernel<2>::value(2.3 * h, h), 0);
  EXPECT_EQ(CubicSplineKernel<3>::gradient(vec<3>(2.0001 * h, 0, 0), h).norm(), 0);
  EXPECT_NEAR(CubicSplineKernel<3>::value(1.999999 * h, h), 0, 1e-15);
}

TEST(SphKernel, PlaneGradientFromSquaredDistanceAndInverseLengthIsTheDerivative)
{
  // The force loop's form, gradient(r, r^2, 1/h), in the plane, on both sides of q = 1.
  const double h = 0.7;
  for (double q : {0.2, 0.8, 0.999, 1.0, 1.3, 1.9})
    {
      const Tensor<1, 2> r  = (q * h / std::sqrt(5.0)) * vec<2>(2, -1);
      const Tensor<1, 2> g  = CubicSplineKernel<2>::gradient(r, r.norm_square(), 1 / h);
      const double       d  = 1e-6 * h;
      const double       fd = (CubicSplineKernel<2>::value(q * h + d, h) -
                         CubicSplineKernel<2>::value(q * h - d, h)) / (2 * d);
      EXPECT_NEAR((g - (fd / r.norm()) * r).norm() / std::abs(fd), 0, 1e-6) << "q = " << q;
      EXPECT_NEAR((g - CubicSplineKernel<2>::gradient(r, h)).norm() / g.norm(), 0, 1e-15);
    }
  EXPECT_EQ(CubicSplineKernel<2>::gradient(vec<2>(0, 2 * h), 4 * h * h, 1 / h).norm(), 0);
  EXPECT_EQ(CubicSplineKernel<2>::gradient(vec<2>(0, 0), 0, 1 / h).norm(), 0);
}

// ---------------------------------------------------------------- EOS

TEST(SphEos, TillotsonReferenceStateAndTables)
{
  for (const Material &m : {Material::granite(), Material::basalt()})
    {
      const auto &t  = m.tillotson;
      const auto  ps = m.evaluate(t.rho0, 0);
      EXPECT_EQ(ps.pressure, 0) << m.name;
      EXPECT_NEAR(ps.sound_speed, std::sqrt(t.A / t.rho0), 1e-9 * ps.sound_speed) << m.name;
      // Small compression: P ~ A mu (bulk modulus A).
      EXPECT_NEAR(m.evaluate(t.rho0 * 1.001, 0).pressure, t.A * 1e-3 + t.B * 1e-6, 1e-6 * t.A);
    }
  const auto g = TillotsonParameters::granite();
  EXPECT_EQ(g.rho0, 2680);
  EXPECT_EQ(g.A, 18e9);
  EXPECT_EQ(g.B, 18e9);
  EXPECT_EQ(g.b, 1.3);
  EXPECT_EQ(g.E0, 16e6);
  EXPECT_EQ(g.E_iv, 3.5e6);
  EXPECT_EQ(g.E_cv, 18e6);
  const auto b = TillotsonParameters::basalt();
  EXPECT_EQ(b.rho0, 2700);
  EXPECT_EQ(b.A, 26.7e9);
  EXPECT_EQ(b.b, 1.5);
  EXPECT_EQ(b.E0, 487e6);
  EXPECT_EQ(b.E_iv, 4.72e6);
  EXPECT_EQ(b.E_cv, 18.2e6);
  // Granite shear modulus keeps K = A and the published Poisson ratio 0.271.
  const Material gr = Material::granite();
  const double   nu = (3 * gr.bulk_modulus - 2 * gr.shear_modulus) /
                    (2 * (3 * gr.bulk_modulus + gr.shear_modulus));
  EXPECT_NEAR(nu, (3 * 50.0 - 2 * 27.0) / (2 * (3 * 50.0 + 27.0)), 1e-12);
  EXPECT_NEAR(Material::basalt().shear_modulus, 22.7e9, 1);
}

TEST(SphEos, TillotsonContinuousAcrossEivAndEcv)
{
  for (const auto &t : {TillotsonParameters::granite(), TillotsonParameters::basalt()})
    {
      Tillotson    eos(t);
      const double rho = 0.95 * t.rho0; // expanded, above the cut-off
      for (double E : {t.E_iv, t.E_cv})
        {
          const double d  = 1e-6 * E;
          const double lo = eos.evaluate(rho, E - d).pressure;
          const double hi = eos.evaluate(rho, E + d).pressure;
          // The jump is of the order of the slope times 2d, not of P itself.
          EXPECT_LT(std::abs(hi - lo), 1e-4 * std::max(std::abs(lo), 1e6)) << E;
        }
      // Continuity across rho0 for a cold and a warm state.
      for (double e : {0.0, 0.5 * t.E_iv, 0.5 * (t.E_iv + t.E_cv)})
        {
          const double lo = eos.evaluate(t.rho0 * (1 - 1e-9), e).pressure;
          const double hi = eos.evaluate(t.rho0 * (1 + 1e-9), e).pressure;
          EXPECT_LT(std::abs(hi - lo), 1e-4 * std::max(std::abs(lo), 1e6)) << e;
        }
    }
}

TEST(SphEos, TillotsonSoundSpeedMatchesFiniteDifferences)
{
  Tillotson eos(TillotsonParameters::granite());
  const double rho0 = 2680;
  for (auto [eta, e] : {std::pair{1.2, 1e6}, {1.05, 5e6}, {0.95, 2e6}, {0.95, 10e6}, {0.95, 25e6}})
    {
      const double rho = eta * rho0;
      double       P, Pr, Pe, P1, P2, dummy1, dummy2;
      eos.pressure_and_derivatives(rho, e, P, Pr, Pe);
      const double dr = 1e-6 * rho, de = 1e-6 * e;
      eos.pressure_and_derivatives(rho + dr, e, P1, dummy1, dummy2);
      eos.pressure_and_derivatives(rho - dr, e, P2, dummy1, dummy2);
      EXPECT_NEAR(Pr, (P1 - P2) / (2 * dr), 1e-5 * std::abs(Pr)) << eta << " " << e;
      eos.pressure_and_derivatives(rho, e + de, P1, dummy1, dummy2);
      eos.pressure_and_derivatives(rho, e - de, P2, dummy1, dummy2);
      EXPECT_NEAR(Pe, (P1 - P2) / (2 * de), 1e-5 * std::abs(Pe) + 1e-9) << eta << " " << e;
    }
  // Expansion cut-off: no tension below 0.9 rho0 for cold material.
  EXPECT_EQ(eos.evaluate(0.85 * rho0, 0).pressure, 0);
  EXPECT_LT(eos.evaluate(0.95 * rho0, 0).pressure, 0);
  // Linear EOS.
  const Material lin = Material::linear(1000, 2e9, 1e9);
  EXPECT_NEAR(lin.evaluate(1010, 0).pressure, 2e7, 1e-3);
  EXPECT_NEAR(lin.longitudinal_speed(), std::sqrt((2e9 + 4e9 / 3) / 1000), 1e-9);
}

// ---------------------------------------------------------------- boundary forces

TEST(SphBoundaryForce, ContinuityConditionsOfThePaper)
{
  const double h = 1e-3;
  const auto   f1 = BoundaryForce::spring(1e6, h);
  EXPECT_NEAR(f1.value(0.5 * h), 1e6 * 0.5 * h, 1e-9);
  EXPECT_EQ(f1.value(h), 0);
  EXPECT_EQ(f1.value(1.1 * h), 0);

  const auto f2 = BoundaryForce::monaghan(1e5, 4, h);
  const double l = f2.junction(), d = 1e-9 * h;
  EXPECT_NEAR(l, 4 * h / 6, 1e-15);
  EXPECT_NEAR(f2.value(l - d), f2.value(l + d), 1e-5 * f2.value(l));
  const double s_lo = (f2.value(l - d) - f2.value(l - 3 * d)) / (2 * d);
  const double s_hi = (f2.value(l + 3 * d) - f2.value(l + d)) / (2 * d);
  EXPECT_NEAR(s_lo, s_hi, 1e-4 * std::abs(s_lo));
  EXPECT_NEAR(f2.value(h), 0, 1e-12);

  for (auto [m, n] : {std::pair{8.0, 4.0}, {12.0, 6.0}})
    {
      const double eps = BoundaryForce::lennard_jones_epsilon(3000, h, m, n);
      const auto   f3  = BoundaryForce::lennard_jones(eps, m, n, h, 1.5 * h);
      const double rc  = f3.junction();
      EXPECT_NEAR(rc, h * std::pow(m / n, 1 / (m - n)), 1e-15);
      EXPECT_NEAR(f3.value(h), 0, 1e-9 * eps);
      EXPECT_NEAR(f3.value(1.5 * h - 1e-12 * h), 0, 1e-6 * eps);
      EXPECT_LT(f3.value(rc), 0); // attractive minimum
      EXPECT_NEAR(f3.value(rc - d), f3.value(rc + d), 1e-6 * eps);
      const double a_lo = (f3.value(rc - d) - f3.value(rc - 3 * d)) / (2 * d);
      const double a_hi = (f3.value(rc + 3 * d) - f3.value(rc + d)) / (2 * d);
      EXPECT_NEAR(a_lo, 0, 1e-4 * eps / h);
      EXPECT_NEAR(a_hi, 0, 1e-4 * eps / h);
    }
}

// ---------------------------------------------------------------- neighbours, lattice

TEST(SphNeighbours, CellListMatchesBruteForceWithPeriodicX)
{
  std::mt19937_64                        rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  const double                           L = 1.0, cut = 0.11;
  std::vector<Tensor<1, 3>>              x(800);
  for (auto &p : x)
    p = vec<3>(L * u(rng), 0.5 * u(rng), 0.3 * u(rng));
  for (double period : {0.0, L})
    {
      NeighbourSearch<3> ns(period);
      ns.build(x, cut);
      std::set<std::pair<unsigned, unsigned>> found, expect;
      for (unsigned int i = 0; i < x.size(); ++i)
        for (unsigned int q = ns.start[i]; q < ns.start[i + 1]; ++q)
          found.insert({i, ns.list[q]});
      for (unsigned int i = 0; i < x.size(); ++i)
        for (unsigned int j = 0; j < x.size(); ++j)
          if (i != j && ns.separation(x[i], x[j]).norm() < cut)
            expect.insert({i, j});
      EXPECT_EQ(found, expect) << period;
      EXPECT_EQ(found.size(), ns.list.size());
      EXPECT_GT(found.size(), 1000u);
    }
}

TEST(SphLattice, SpacingVolumeAndSurfaceModifiers)
{
  const double a = 1e-3;
  for (LatticeType type : {LatticeType::cubic, LatticeType::hexagonal})
    {
      const auto box = vec<3>(12 * a, 10 * a, 8 * a);
      auto       pts = lattice_points<3>(type, vec<3>(0, 0, 0), box, a);
      double     dmin = 1;
      for (unsigned int i = 0; i < pts.size(); ++i)
        for (unsigned int j = i + 1; j < pts.size(); ++j)
          dmin = std::min(dmin, (pts[i] - pts[j]).norm());
      EXPECT_NEAR(dmin, a, 1e-12);
      // Mass consistency: n V_particle ~ box volume (within a boundary layer).
      EXPECT_NEAR(pts.size() * volume_per_particle<3>(type, a) / (12 * 10 * 8 * a * a * a), 1, 0.12);
    }
  auto pts = lattice_points<2>(LatticeType::hexagonal, vec<2>(0, 0), vec<2>(40 * a, 10 * a), a);
  const unsigned int n_top = surface_layer(pts, 0.1 * a).size();
  EXPECT_EQ(n_top, 40u);
  auto holes = pts;
  random_holes(holes, 0.25, 7, 0.1 * a);
  EXPECT_EQ(pts.size() - holes.size(), 10u);
  auto rough = pts;
  random_heights(rough, 0.5 * a, 7, 0.1 * a);
  double top = surface_layer(pts, 0.1 * a).size() ? pts[surface_layer(pts, 0.1 * a)[0]][1] : 0;
  for (unsigned int i : surface_layer(pts, 0.1 * a))
    EXPECT_LE(std::abs(rough[i][1] - top), 0.25 * a + 1e-15);
  auto stepped = pts;
  add_step(stepped, 20 * a, a, 0.1 * a);
  EXPECT_EQ(stepped.size() - pts.size(), 20u);
  auto fractal = pts;
  fractal_heights(fractal, 1.5, 0.2 * a, vec<2>(40 * a, 10 * a), 20, 11, 0.1 * a);
  double sq = 0;
  for (unsigned int i : surface_layer(pts, 0.1 * a))
    sq += std::pow(fractal[i][1] - top, 2);
  EXPECT_NEAR(std::sqrt(sq / n_top), 0.2 * a, 1e-9 * a);
  auto tilted = pts;
  tilt(tilted, vec<2>(0, 0), 0.3);
  EXPECT_NEAR(tilted[5].norm(), pts[5].norm(), 1e-15);
  EXPECT_NEAR(std::atan2(tilted[5][1], tilted[5][0]) - std::atan2(pts[5][1], pts[5][0]), 0.3, 1e-12);
  // A twist about the vertical axis (3D, plane x-y) keeps the heights: a flat face stays flat.
  std::vector<Tensor<1, 3>> column = {vec<3>(2 * a, 0, 5 * a), vec<3>(3 * a, a, 5 * a)};
  tilt(column, vec<3>(a, 0, 0), M_PI / 2, 1);
  EXPECT_NEAR(column[0][0], a, 1e-15);
  EXPECT_NEAR(column[0][1], a, 1e-15);
  EXPECT_NEAR(column[1][0], 0, 1e-15);
  EXPECT_NEAR(column[1][1], 2 * a, 1e-15);
  EXPECT_EQ(column[0][2], 5 * a);
  EXPECT_EQ(column[1][2], 5 * a);
}

// ---------------------------------------------------------------- SPH interpolation

TEST(SphInterpolation, LinearFieldReproducedInTheInterior)
{
  const double a = 1e-3;
  {
    ParticleState<2> s;
    const auto pts = lattice_points<2>(LatticeType::hexagonal, vec<2>(0, 0), vec<2>(20 * a, 20 * a), a);
    add_particles(s, pts, 2700, volume_per_particle<2>(LatticeType::hexagonal, a), 1.2 * a, 0, 0);
    NeighbourSearch<2> ns;
    ns.build(s.x, 2.4 * a);
    std::vector<double> f(s.size());
    for (unsigned int i = 0; i < s.size(); ++i)
      f[i] = 3 + 2 * s.x[i][0] / a - s.x[i][1] / a;
    const auto fi = interpolate(s, ns, f);
    double     err = 0;
    for (unsigned int i : interior(s, 2.5 * a))
      err = std::max(err, std::abs(fi[i] - f[i]));
    EXPECT_LT(err, 5e-3 * 40); // relative to the field's range over the block (~40)
    std::printf("2D hexagonal: max interpolation error %.3g (field range 40)\n", err);
  }
  {
    ParticleState<3> s;
    const auto pts = lattice_points<3>(LatticeType::cubic, vec<3>(0, 0, 0), vec<3>(10 * a, 10 * a, 10 * a), a);
    add_particles(s, pts, 2700, a * a * a, 1.2 * a, 0, 0);
    NeighbourSearch<3> ns;
    ns.build(s.x, 2.4 * a);
    std::vector<double> f(s.size());
    for (unsigned int i = 0; i < s.size(); ++i)
      f[i] = 1 + s.x[i][0] / a + 2 * s.x[i][1] / a - s.x[i][2] / a;
    const auto fi = interpolate(s, ns, f);
    double     err = 0;
    for (unsigned int i : interior(s, 2.5 * a))
      err = std::max(err, std::abs(fi[i] - f[i]));
    EXPECT_LT(err, 5e-3 * 40);
    std::printf("3D cubic: max interpolation error %.3g (field range 40)\n", err);
  }
}
