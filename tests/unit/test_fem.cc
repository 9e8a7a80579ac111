// The deal.II elastic body (fem/elastic_body.h) against closed forms and against an
// independent dense Q1 model assembled here by hand.
#include "core/errors.h"
#include "fem/elastic_body.h"

#include <Eigen/Dense>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>

using tribo::fem::ElasticBody;
using tribo::fem::ElasticBodyParameters;

namespace
{
  /// A small steel-like body (E = 100 GPa, nu = 0.33, rho = 7800) of 1 um cells.
  ElasticBodyParameters small_body(unsigned int nx, unsigned int ny)
  {
    ElasticBodyParameters p;
    p.cells_x   = nx;
    p.cells_y   = ny;
    p.length    = nx * 1e-6;
    p.thickness = ny * 1e-6;
    p.bottom    = 2e-6;
    p.time_step = 1e-10; // c h / dx ~ 0.44
    return p;
  }

  /// Dense Mt^-1 = (M + theta h C + theta^2 h^2 K)^-1 of a periodic Q1 plane-strain
  /// mesh of nx x ny rectangles, built without deal.II: closed-form bilinear shape
  /// functions, 2 x 2 Gauss points, nodes numbered j nx + (i mod nx) (the period is in
  /// the numbering), dof 2 node + component. With the top held in x, those dofs are
  /// removed and their rows and columns of the inverse are zero.
  Eigen::MatrixXd dense_inverse_iteration_matrix(const ElasticBodyParameters &p)
  {
    const unsigned int nx = p.cells_x, ny = p.cells_y, n_nodes = nx * (ny + 1), n = 2 * n_nodes;
    const double dx = p.length / nx, dy = p.thickness / ny;
    const double E = p.youngs_modulus, nu = p.poisson_ratio;
    const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
    Eigen::Matrix3d D;
    D << lambda + 2 * mu, lambda, 0, lambda, lambda + 2 * mu, 0, 0, 0, mu;

    const double xi_k[4] = {-1, 1, 1, -1}, eta_k[4] = {-1, -1, 1, 1};
    Eigen::Matrix<double, 8, 8> Me = Eigen::Matrix<double, 8, 8>::Zero(), Ke = Me;
    const double g = 1 / std::sqrt(3.0), detJ = dx * dy / 4;
    for (double xi : {-g, g})
      for (double eta : {-g, g})
        {
          Eigen::Matrix<double, 2, 8> N = Eigen::Matrix<double, 2, 8>::Zero();
          Eigen::Matrix<double, 3, 8> B = Eigen::Matrix<double, 3, 8>::Zero();
          for (int k = 0; k < 4; ++k)
            {
              const double Nk = 0.25 * (1 + xi * xi_k[k]) * (1 + eta * eta_k[k]);
              const double Nx = 0.25 * xi_k[k] * (1 + eta * eta_k[k]) * 2 / dx;
              const double Ny = 0.25 * eta_k[k] * (1 + xi * xi_k[k]) * 2 / dy;
              N(0, 2 * k) = N(1, 2 * k + 1) = Nk;
              B(0, 2 * k)                   = Nx;
              B(1, 2 * k + 1)               = Ny;
              B(2, 2 * k)                   = Ny; // engineering shear strain
              B(2, 2 * k + 1)               = Nx;
            }
          Me += p.density * N.transpose() * N * detJ;
          Ke += B.transpose() * D * B * detJ;
        }

    Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n, n), K = M;
    for (unsigned int j = 0; j < ny; ++j)
      for (unsigned int i = 0; i < nx; ++i)
        {
          const unsigned int node[4] = {j * nx + i, j * nx + (i + 1) % nx, (j + 1) * nx + (i + 1) % nx,
                                        (j + 1) * nx + i};
          for (int a = 0; a < 8; ++a)
            for (int b = 0; b < 8; ++b)
              {
                const unsigned int A = 2 * node[a / 2] + a % 2, B = 2 * node[b / 2] + b % 2;
                M(A, B) += Me(a, b);
                K(A, B) += Ke(a, b);
              }
        }
    const double h = p.time_step, th = p.theta;
    const Eigen::MatrixXd Mt = M + th * h * (p.rayleigh_mass * M + p.rayleigh_stiffness * K) + th * th * h * h * K;

    std::vector<int> free;
    for (unsigned int d = 0; d < n; ++d)
      if (!(p.top_fixed_in_x && d / 2 >= ny * nx && d % 2 == 0))
        free.push_back(d);
    Eigen::MatrixXd Mf(free.size(), free.size());
    for (std::size_t a = 0; a < free.size(); ++a)
      for (std::size_t b = 0; b < free.size(); ++b)
        Mf(a, b) = Mt(free[a], free[b]);
    const Eigen::MatrixXd inv_f = Mf.inverse();
    Eigen::MatrixXd inv = Eigen::MatrixXd::Zero(n, n);
    for (std::size_t a = 0; a < free.size(); ++a)
      for (std::size_t b = 0; b < free.size(); ++b)
        inv(free[a], free[b]) = inv_f(a, b);
    return inv;
  }

  double relative_difference(const Eigen::MatrixXd &a, const Eigen::MatrixXd &b)
  {
    return (a - b).cwiseAbs().maxCoeff() / b.cwiseAbs().maxCoeff();
  }

  std::vector<Eigen::Vector2d> random_impulses(unsigned int n, double scale, std::mt19937 &rng)
  {
    std::uniform_real_distribution<double> U(-1, 1);
    std::vector<Eigen::Vector2d>           R(n);
    for (auto &r : R)
      r = scale * Eigen::Vector2d(U(rng), U(rng));
    return R;
  }

  Eigen::VectorXd stack(const std::vector<Eigen::Vector2d> &x)
  {
    Eigen::VectorXd s(2 * x.size());
    for (std::size_t i = 0; i < x.size(); ++i)
      s.segment<2>(2 * i) = x[i];
    return s;
  }

  Eigen::VectorXd bottom_free_velocities(const ElasticBody &b)
  {
    std::vector<Eigen::Vector2d> v(b.n_boundary_nodes());
    for (unsigned int i = 0; i < v.size(); ++i)
      v[i] = b.boundary_free_velocity(i);
    return stack(v);
  }

  Eigen::VectorXd bottom_velocities(const ElasticBody &b)
  {
    std::vector<Eigen::Vector2d> v(b.n_boundary_nodes());
    for (unsigned int i = 0; i < v.size(); ++i)
      v[i] = b.boundary_velocity(i);
    return stack(v);
  }

  /// A few steps under a ramped pressure with random impulses: a state with u, v != 0.
  void shake(ElasticBody &b, unsigned int steps, std::mt19937 &rng)
  {
    for (unsigned int s = 0; s < steps; ++s)
      {
        b.predict();
        b.finalize(random_impulses(b.n_boundary_nodes(), 1e-8, rng));
      }
  }
} // namespace

// 1. The condensed compliance is the bottom block of a dense Mt^-1 (independent Q1
// model), for both solvers, with damping and theta != 1/2, top held in x or not.
TEST(Fem, ComplianceEqualsDenseInverseBlock)
{
  for (const bool top_fixed : {true, false})
    for (const std::string solver : {"cholmod", "umfpack"})
      {
        auto p               = small_body(4, 3);
        p.theta              = 0.6;
        p.rayleigh_mass      = 1e7;
        p.rayleigh_stiffness = 1e-11;
        p.top_fixed_in_x     = top_fixed;
        p.solver             = solver;
        const ElasticBody body(p);
        ASSERT_EQ(body.n_boundary_nodes(), 4u);
        for (unsigned int i = 0; i < 4; ++i)
          EXPECT_NEAR(body.boundary_position(i).x(), i * 1e-6, 1e-18);

        const Eigen::MatrixXd inv = dense_inverse_iteration_matrix(p);
        const Eigen::MatrixXd G   = body.boundary_compliance();
        // Bottom node i is node i of the dense model: dofs 2i, 2i + 1.
        EXPECT_LT(relative_difference(G, inv.topLeftCorner(8, 8)), 1e-10) << solver << " top fixed " << top_fixed;
        EXPECT_LT(relative_difference(G, G.transpose()), 1e-12);
      }
}

TEST(Fem, FinalizeChangesBottomVelocitiesByComplianceTimesImpulses)
{
  for (const std::string solver : {"cholmod", "umfpack"})
    {
      auto p         = small_body(6, 4);
      p.top_pressure = 1e8;
      p.solver       = solver;
      p.pressure_ramp_time = 5e-10;
      ElasticBody  body(p);
      std::mt19937 rng(7);
      shake(body, 5, rng);
      body.predict();
      const Eigen::VectorXd v_free = bottom_free_velocities(body);
      const auto            R      = random_impulses(body.n_boundary_nodes(), 1e-8, rng);
      body.finalize(R);
      const Eigen::VectorXd dv       = bottom_velocities(body) - v_free;
      const Eigen::VectorXd expected = body.boundary_compliance() * stack(R);
      EXPECT_LT((dv - expected).cwiseAbs().maxCoeff(), 1e-10 * expected.cwiseAbs().maxCoeff()) << solver;
      EXPECT_GT(expected.norm(), 0);
    }
}

// 2. Static pressure on a periodic body on a roller bottom: the laterally confined
// strain eps_yy = -P / (lambda + 2 mu), eps_xx = eps_xy = 0, uniform.
TEST(Fem, StaticPressureGivesConfinedUniaxialStrain)
{
  for (const unsigned int degree : {1u, 2u})
    for (const bool top_fixed : {false, true})
      {
        auto p           = small_body(5, 4);
        p.degree         = degree;
        p.top_pressure   = 1e8;
        p.top_fixed_in_x = top_fixed;
        ElasticBody body(p);
        body.static_solve();
        const double eps = -p.top_pressure / (body.lame_lambda() + 2 * body.shear_modulus());
        for (const double fx : {0.13, 0.5, 0.91})
          for (const double fy : {0.07, 0.5, 0.88})
            {
              const Eigen::Vector2d x(fx * p.length, p.bottom + fy * p.thickness);
              const Eigen::Matrix2d e = body.strain_at(x);
              EXPECT_NEAR(e(1, 1) / eps, 1, 1e-8) << "degree " << degree << " top fixed " << top_fixed;
              EXPECT_LT(std::abs(e(0, 0)) + std::abs(e(0, 1)), 1e-8 * std::abs(eps));
              EXPECT_NEAR(body.displacement_at(x).y() / (eps * fy * p.thickness), 1, 1e-8);
            }
        EXPECT_EQ(body.mean_bottom_displacement_y(), 0);
        EXPECT_NEAR(body.elastic_energy() / (0.5 * p.top_pressure * -eps * p.length * p.thickness), 1, 1e-8);
      }
}

// 3. A step pressure on the top of a tall periodic column (bottom free) launches a
// P-wave at c = sqrt((lambda + 2 mu) / rho); the free bottom starts to move when it
// arrives, at H / c, with the velocity 2 P / (rho c) (reflection at a free end).
TEST(Fem, StepPressureLaunchesPWaveAtTheDilatationalSpeed)
{
  auto p         = small_body(2, 400);
  p.top_pressure = 1e8;
  ElasticBody  body(p);
  const double c = std::sqrt((body.lame_lambda() + 2 * body.shear_modulus()) / p.density);
  const double T = p.thickness / c, v_end = -2 * p.top_pressure / (p.density * c);
  body.set_time_step(0.25 * 1e-6 / c);

  const auto mean_bottom_vy = [&] {
    double s = 0;
    for (unsigned int i = 0; i < body.n_boundary_nodes(); ++i)
      s += body.boundary_velocity(i).y();
    return s / body.n_boundary_nodes();
  };
  double arrival = -1, v_before = 0;
  while (body.time() < 1.3 * T)
    {
      v_before = mean_bottom_vy();
      body.predict();
      body.finalize({});
      const double v_now = mean_bottom_vy();
      if (arrival < 0 && v_now < 0.5 * v_end) // half of the plateau: the front's middle
        arrival = body.time() - body.time_step() * (v_now - 0.5 * v_end) / (v_now - v_before);
    }
  ASSERT_GT(arrival, 0) << "the front never reached the bottom";
  EXPECT_NEAR(arrival / T, 1, 0.03);
  EXPECT_NEAR(body.mean_bottom_displacement_y() / (v_end * (body.time() - T)), 1, 0.05);
}

// 4. theta = 1/2 without damping conserves E_kin + E_el - W_load (and - W_contact) to
// round-off; with damping the loss is exactly the damping dissipation.
TEST(Fem, EnergyIsConservedWithoutDampingAndDissipatedByIt)
{
  struct Case
  {
    double a, b;
    bool   impulses;
  };
  for (const Case c : {Case{0, 0, false}, Case{0, 0, true}, Case{2e8, 0, false}, Case{0, 2e-11, true}})
    {
      auto p               = small_body(6, 4);
      p.top_pressure       = 1e8;
      p.pressure_ramp_time = 20e-10;
      p.rayleigh_mass      = c.a;
      p.rayleigh_stiffness = c.b;
      ElasticBody  body(p);
      std::mt19937 rng(3);
      double       scale = 0;
      for (int s = 0; s < 200; ++s)
        {
          body.predict();
          body.finalize(c.impulses ? random_impulses(body.n_boundary_nodes(), 1e-8, rng) : std::vector<Eigen::Vector2d>{});
          scale = std::max({scale, std::abs(body.load_work()), std::abs(body.contact_work()),
                            body.kinetic_energy() + body.elastic_energy()});
        }
      const double E = body.kinetic_energy() + body.elastic_energy();
      const double balance = E - body.load_work() - body.contact_work() + body.damping_dissipation();
      EXPECT_LT(std::abs(balance), 1e-9 * scale) << "a " << c.a << " b " << c.b << " impulses " << c.impulses;
      if (c.a > 0 || c.b > 0)
        {
          EXPECT_GT(body.damping_dissipation(), 1e-3 * scale);
          EXPECT_LT(E - body.load_work() - body.contact_work(), -1e-3 * scale);
        }
      else
        EXPECT_EQ(body.damping_dissipation(), 0);
    }
}

// 5. CHOLMOD and UMFPACK give the same free velocity.
TEST(Fem, CholmodAndUmfpackAgree)
{
  auto p               = small_body(8, 6);
  p.top_pressure       = 1e8;
  p.pressure_ramp_time = 5e-10;
  p.rayleigh_mass      = 1e7;
  p.solver             = "cholmod";
  ElasticBody a(p);
  p.solver = "umfpack";
  ElasticBody  b(p);
  std::mt19937 rng_a(11), rng_b(11);
  shake(a, 10, rng_a);
  shake(b, 10, rng_b);
  a.predict();
  b.predict();
  const Eigen::VectorXd va = bottom_free_velocities(a), vb = bottom_free_velocities(b);
  EXPECT_GT(va.norm(), 0);
  EXPECT_LT((va - vb).norm(), 1e-12 * va.norm());
  const Eigen::Vector2d x(0.37 * p.length, p.bottom + 0.61 * p.thickness);
  EXPECT_LT((a.velocity_at(x) - b.velocity_at(x)).norm(), 1e-12 * a.velocity_at(x).norm());
}

// Degree 2: the vertex nodes are the contact nodes; G is symmetric positive definite
// and is what finalize applies.
TEST(Fem, QuadraticElementsUseVertexNodesForContact)
{
  auto p   = small_body(5, 3);
  p.degree = 2;
  ElasticBody body(p);
  ASSERT_EQ(body.n_boundary_nodes(), 5u);
  const Eigen::MatrixXd &G = body.boundary_compliance();
  EXPECT_LT(relative_difference(G, G.transpose()), 1e-12);
  EXPECT_EQ(Eigen::LLT<Eigen::MatrixXd>(0.5 * (G + G.transpose())).info(), Eigen::Success);
  std::mt19937 rng(5);
  body.predict();
  const Eigen::VectorXd v_free = bottom_free_velocities(body);
  const auto            R      = random_impulses(5, 1e-8, rng);
  body.finalize(R);
  const Eigen::VectorXd expected = G * stack(R);
  EXPECT_LT((bottom_velocities(body) - v_free - expected).cwiseAbs().maxCoeff(), 1e-10 * expected.cwiseAbs().maxCoeff());
}

// set_time_step refactorises: the compliance is that of a body built with the new h.
TEST(Fem, SetTimeStepRefactorises)
{
  auto        p = small_body(4, 3);
  ElasticBody body(p);
  const Eigen::MatrixXd G0 = body.boundary_compliance();
  body.set_time_step(3e-10);
  p.time_step = 3e-10;
  const ElasticBody fresh(p);
  EXPECT_GT(relative_difference(G0, fresh.boundary_compliance()), 1e-3);
  EXPECT_LT(relative_difference(body.boundary_compliance(), fresh.boundary_compliance()), 1e-12);
  EXPECT_LT(relative_difference(body.boundary_compliance(), dense_inverse_iteration_matrix(p).topLeftCorner(8, 8)), 1e-10);
}

TEST(Fem, SetDampingRefactorises)
{
  auto        p = small_body(4, 3);
  ElasticBody body(p);
  const Eigen::MatrixXd G0 = body.boundary_compliance();
  body.set_damping(3e8, 2e-9);
  p.rayleigh_mass      = 3e8;
  p.rayleigh_stiffness = 2e-9;
  const ElasticBody fresh(p);
  EXPECT_GT(relative_difference(G0, fresh.boundary_compliance()), 1e-3);
  EXPECT_LT(relative_difference(body.boundary_compliance(), fresh.boundary_compliance()), 1e-12);
  EXPECT_THROW(body.set_damping(-1, 0), tribo::InputError);
}

TEST(Fem, WritesVtuWithStressFields)
{
  auto p         = small_body(4, 3);
  p.top_pressure = 1e8;
  ElasticBody body(p);
  body.static_solve();
  const std::string name = testing::TempDir() + "fem_test.vtu";
  body.write_vtu(name);
  std::ifstream     file(name);
  std::stringstream text;
  text << file.rdbuf();
  for (const char *field : {"displacement", "velocity", "sigma_xx", "sigma_yy", "sigma_xy", "sigma_zz", "von_mises"})
    EXPECT_NE(text.str().find(field), std::string::npos) << field;
  std::remove(name.c_str());
}

TEST(Fem, RejectsBadParameters)
{
  auto p = small_body(2, 2);
  p.solver = "mumps";
  EXPECT_ANY_THROW(ElasticBody{p});
  p        = small_body(2, 2);
  p.theta  = 0.4;
  EXPECT_ANY_THROW(ElasticBody{p});
  ElasticBody body(small_body(2, 2));
  EXPECT_ANY_THROW(body.finalize({})); // no predict()
}
