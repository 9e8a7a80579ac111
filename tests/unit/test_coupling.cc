// The deal.II first body coupled to discs through half-disc elements
// (coupling/elastic_boundary.h): a column of grains between a fixed rigid wall and
// an elastic block under top pressure.
#include "coupling/elastic_boundary.h"
#include "dem/moreau_jean.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace tribo;
using dem::Vec2;

namespace
{
  constexpr double l = 1e-6, L = 8 * l, rho = 7800, P = 1e8;
  const double     y_grain = 0.5 * std::sqrt(3.0) * l;

  /// A fixed wall of 8 discs (radius l/2) at x = i l, y = 0, one grain in each pocket
  /// (x = (i + 1/2) l, y = (sqrt 3 / 2) l), and the elastic block's bottom at
  /// y = (sqrt 3 / 2 + 1) l, where its half-discs (diameter l, centred at (k + 1/2) l)
  /// just touch the grains from straight above.
  struct Column
  {
    dem::ParticleSystem s;
    unsigned int        wall = 0;
    fem::ElasticBodyParameters prm;

    Column()
    {
      s.period = L;
      std::vector<Vec2>   c;
      std::vector<double> r;
      for (int i = 0; i < 8; ++i)
        {
          c.push_back({i * l, 0});
          r.push_back(0.5 * l);
        }
      wall = s.add_clump(c, r, rho);
      for (auto &d : s.bodies[wall].drive)
        d = dem::Drive::velocity;
      for (int i = 0; i < 8; ++i)
        s.add_disc({(i + 0.5) * l, y_grain}, 0.5 * l, rho);
      prm.length = L;
      prm.thickness = 8 * l;
      prm.bottom = y_grain + l;
      prm.cells_x = 8;
      prm.cells_y = 8;
      prm.top_pressure = P;
      prm.pressure_ramp_time = 2e-8;
      prm.time_step = 1e-9;
    }
  };
} // namespace

TEST(Coupling, ElasticBlockOnGrainsCarriesThePressureAndBalancesEnergy)
{
  Column col;
  col.prm.rayleigh_mass = 2e8; // 1/s: settles within about 1e-8 s
  fem::ElasticBody       body(col.prm);
  coupling::ElasticBoundary boundary(body);
  dem::NlgsParameters    nlgs;
  nlgs.tolerance = 1e-8;
  nlgs.check_interval = 1;
  dem::MoreauJean mj(0.5, dem::ContactLaw{}, nlgs, 0.05 * l);
  mj.attach(boundary, l, {0, -1}, L);
  const double h = 1e-9;
  double e0 = col.s.kinetic_energy() + boundary.energy();
  double total = std::abs(e0);
  for (int i = 0; i < 300; ++i)
    {
      const auto   rep = mj.step(col.s, h);
      const double e1  = rep.kinetic_energy + rep.boundary_energy;
      const double rhs = h * (rep.power_external + rep.power_contacts - rep.boundary_dissipation);
      total = std::max(total, std::abs(e1));
      EXPECT_NEAR(e1 - e0, rhs, 1e-9 * (std::abs(e1 - e0) + std::abs(rhs)) + 1e-12 * total)
        << "step " << i;
      e0 = e1;
      EXPECT_EQ(rep.n_boundary_contacts, 8u) << "step " << i;
    }
  // Settled: the wall carries P L through the grains, each column an eighth.
  const double Fy = mj.contact_force()[col.wall].y();
  EXPECT_NEAR(-Fy, P * L, 1e-3 * P * L);
  for (unsigned int g = 1; g <= 8; ++g)
    EXPECT_NEAR(col.s.bodies[g].velocity.norm(), 0.0, 1e-6);
  // Its mid-height strain is the confined plane-strain one, eps_yy = -P/(lambda + 2 mu)
  // (within 5 %: the bottom is loaded at 8 points, not uniformly).
  const Eigen::Matrix2d eps = body.strain_at({0.5 * L, col.prm.bottom + 0.5 * col.prm.thickness});
  EXPECT_NEAR(eps(1, 1), -P / (body.lame_lambda() + 2 * body.shear_modulus()), 0.05 * P / (body.lame_lambda() + 2 * body.shear_modulus()));
}

TEST(Coupling, StiffBlockMovesLikeARigidBody)
{
  // E -> 1e6 x: the bottom nodes' compliance tends to the rigid translation 1/M
  // (M the block's mass) in y for every pair of nodes.
  Column col;
  col.prm.youngs_modulus = 100e9 * 1e6;
  fem::ElasticBody body(col.prm);
  body.set_time_step(1e-9);
  const Eigen::MatrixXd &G = body.boundary_compliance();
  const double M = rho * col.prm.thickness * L;
  for (unsigned int i = 0; i < 8; ++i)
    for (unsigned int j = 0; j < 8; ++j)
      EXPECT_NEAR(G(2 * i + 1, 2 * j + 1), 1 / M, 0.02 / M) << i << " " << j;
}
