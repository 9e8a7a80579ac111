// The deal.II first body coupled to discs through half-disc elements
// (coupling/elastic_boundary.h): a column of grains between a fixed rigid wall and
// an elastic block under top pressure.
#include "coupling/elastic_boundary.h"
#include "coupling/first_body.h"
#include "coupling/first_body_models.h"
#include "core/errors.h"
#include "dem/engine/moreau_jean.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>

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
  dem::SolverParameters    nlgs;
  nlgs.method    = dem::SolverParameters::Method::nlgs;
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

namespace
{
  /// Per step: the wall's reaction (x, y), the grains' kinetic energy and the block's energy.
  using BlockHistory = std::vector<std::array<double, 4>>;

  /// @p steps steps of the column on the elastic block under @p law, solved by @p prm, the
  /// wall under the grains sliding at 1 m/s; the steps' reports into @p reports.
  BlockHistory elastic_block_history(const dem::SolverParameters &prm, const dem::ContactLaw &law, int steps,
                                     std::vector<dem::StepReport> &reports)
  {
    Column col;
    col.prm.rayleigh_mass            = 2e8;
    col.s.bodies[col.wall].velocity = {1.0, 0.0}; // the wall slides: the grains move
    fem::ElasticBody          body(col.prm);
    coupling::ElasticBoundary boundary(body);
    dem::MoreauJean           mj(0.5, law, prm, 0.05 * l);
    mj.attach(boundary, l, {0, -1}, L);
    BlockHistory history;
    for (int i = 0; i < steps; ++i)
      {
        reports.push_back(mj.step(col.s, 1e-9));
        history.push_back({{mj.contact_force()[col.wall].x(), mj.contact_force()[col.wall].y(),
                            reports.back().kinetic_energy, reports.back().boundary_energy}});
      }
    return history;
  }

  /// NLGS converged to 1e-12 (checked every sweep): the reference of the comparisons.
  dem::SolverParameters converged_nlgs()
  {
    dem::SolverParameters nlgs;
    nlgs.method         = dem::SolverParameters::Method::nlgs;
    nlgs.tolerance      = 1e-12;
    nlgs.check_interval = 1;
    nlgs.max_iterations = 100000;
    return nlgs;
  }

  /// The largest absolute value of each quantity of @p history over its steps.
  std::array<double, 4> largest_values(const BlockHistory &history)
  {
    std::array<double, 4> largest{};
    for (const auto &row : history)
      for (int k = 0; k < 4; ++k)
        largest[k] = std::max(largest[k], std::abs(row[k]));
    return largest;
  }
} // namespace

TEST(Coupling, GlobalContactSolversMatchConvergedNlgsAgainstTheElasticBlock)
{
  // The half-disc contacts couple through the block's condensed compliance (dense
  // blocks of the sparse Delassus operator): the active set, MPRGP, APGD, APGS and the
  // interior-point method, asked for a law residual of 1e-11, give NLGS's history (converged to 1e-12) while the wall under the
  // grains slides at 1 m/s and the block takes its load: the wall's reaction, the grains'
  // kinetic energy and the block's energy at every step.
  auto run = [](const dem::SolverParameters &prm, std::vector<dem::StepReport> &reports) {
    return elastic_block_history(prm, dem::ContactLaw{}, 60, reports);
  };
  const dem::SolverParameters  nlgs = converged_nlgs();
  std::vector<dem::StepReport> ignored;
  const BlockHistory           reference = run(nlgs, ignored);
  const std::array<double, 4>  scale     = largest_values(reference);
  ASSERT_GT(scale[1], 0.5 * P * L);
  ASSERT_GT(scale[2], 0.0);
  for (const auto method : {dem::SolverParameters::Method::active_set, dem::SolverParameters::Method::mprgp,
                            dem::SolverParameters::Method::interior_point, dem::SolverParameters::Method::apgd,
                            dem::SolverParameters::Method::apgs})
    {
      dem::SolverParameters prm = nlgs;
      prm.method                = method;
      prm.residual_target       = 1e-11;
      std::vector<dem::StepReport> reports;
      const BlockHistory           history = run(prm, reports);
      const std::string            name    = dem::method_name(method);
      for (std::size_t i = 0; i < history.size(); ++i)
        for (int k = 1; k < 4; ++k) // without friction the wall's x reaction is round-off
          EXPECT_NEAR(history[i][k], reference[i][k], 1e-6 * scale[k])
            << name << ", step " << i << ", quantity " << k;
      for (const auto &r : reports)
        {
          EXPECT_EQ(r.n_boundary_contacts, 8u) << name;
          EXPECT_FALSE(r.solver.fell_back) << name;
          // The active set's and the interior-point method's round-off floors.
          EXPECT_LT(r.solver.law_residual, method == dem::SolverParameters::Method::interior_point ? 1e-7 : 1e-8)
            << name;
        }
    }
}

TEST(Coupling, FrictionalApgsMatchesConvergedNlgsAgainstTheElasticBlock)
{
  // Coulomb friction mu = 0.3 on the half-discs of the elastic block and at the sliding wall
  // under the grains: APGS (friction in its sweeps) to a law residual of 1e-9 gives the
  // history of NLGS converged to 1e-12 over 20 steps within 1e-3 of each quantity's largest
  // value (the wall's reaction x and y, the grains' kinetic energy, the block's energy), with
  // the law, friction term included, below 2e-9 at every step (a step or two stop at the
  // sweeps' floor, just above 1e-9, and say so). The trajectory is sensitive: over 60 steps
  // the largest difference of the reactions (of about 245 N/m) is 20, 0.97, 0.07 and 0.005
  // N/m at targets of 1e-6, 1e-8, 1e-9 and 1e-10, the same solution approached.
  auto run = [](const dem::SolverParameters &prm, std::vector<dem::StepReport> &reports) {
    dem::ContactLaw law;
    law.friction = 0.3;
    return elastic_block_history(prm, law, 20, reports);
  };
  const dem::SolverParameters  nlgs = converged_nlgs();
  std::vector<dem::StepReport> ignored;
  const BlockHistory           reference = run(nlgs, ignored);
  const std::array<double, 4>  scale     = largest_values(reference);
  ASSERT_GT(scale[0], 0.05 * P * L); // the friction at the sliding wall acts
  dem::SolverParameters prm = nlgs;
  prm.method                = dem::SolverParameters::Method::apgs;
  prm.residual_target       = 1e-9;
  std::vector<dem::StepReport> reports;
  const BlockHistory           history = run(prm, reports);
  for (std::size_t i = 0; i < history.size(); ++i)
    for (int k = 0; k < 4; ++k)
      EXPECT_NEAR(history[i][k], reference[i][k], 1e-3 * scale[k]) << "step " << i << ", quantity " << k;
  for (const auto &r : reports)
    {
      EXPECT_EQ(r.n_boundary_contacts, 8u);
      EXPECT_LT(r.solver.law_residual, 2e-9);
    }
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

namespace
{
  /// The deal.II body's bottom face translated along x by @p shift (m) after the
  /// half-discs were placed: the imposed displacement of a face sheared by tau H / G,
  /// without waiting for a soft body to deform that far.
  class ShiftedBoundary : public coupling::ElasticBoundary
  {
  public:
    using coupling::ElasticBoundary::ElasticBoundary;
    Vec2 node_position(unsigned int i) const override
    {
      return coupling::ElasticBoundary::node_position(i) + Vec2(shift, 0);
    }
    double shift = 0;
  };

  constexpr unsigned int wide = 16; ///< cells along the period of the shifted-face tests

  /// Pairs (grain, half-disc) of @p s's free discs with a gap at most @p distance to the
  /// half-discs of diameter l centred at @p centres (a flat face: the round sides face -y).
  std::vector<std::pair<unsigned int, int>> geometric_contacts(const dem::ParticleSystem &s,
                                                               const std::vector<Vec2> &centres,
                                                               double distance, double *deepest = nullptr)
  {
    std::vector<std::pair<unsigned int, int>> pairs;
    for (unsigned int d = 0; d < s.discs.size(); ++d)
      {
        if (!s.bodies[s.discs[d].body].is_free())
          continue;
        for (unsigned int k = 0; k < centres.size(); ++k)
          {
            Vec2 b = s.disc_centre(d) - centres[k];
            b.x() -= s.period * std::round(b.x() / s.period);
            if (b.y() >= 0)
              continue; // behind the flat side
            const double gap = b.norm() - s.discs[d].radius - 0.5 * l;
            if (deepest)
              *deepest = std::min(*deepest, gap);
            if (gap <= distance)
              pairs.emplace_back(d, int(k));
          }
      }
    std::sort(pairs.begin(), pairs.end());
    return pairs;
  }
} // namespace

TEST(Coupling, HalfDiscsOfAShiftedFaceAreAllDetected)
{
  // Grains scattered under the face of a deal.II body shifted by 1, 3 and 6 spacings (and
  // half spacings more): detection finds exactly the pairs a brute-force search finds.
  fem::ElasticBodyParameters prm;
  prm.length    = wide * l;
  prm.thickness = 4 * l;
  prm.bottom    = 5 * l;
  prm.cells_x   = wide;
  prm.cells_y   = 4;
  fem::ElasticBody body(prm);
  ShiftedBoundary  boundary(body);
  dem::HalfDiscs   hd(boundary, l, {0, -1}, prm.length);
  std::mt19937                           gen(7);
  std::uniform_real_distribution<double> U(0, 1);
  for (const double spacings : {1.0, 3.0, 6.0, 1.5, 3.5, 6.5, 3.3})
    {
      boundary.shift = spacings * l;
      std::vector<Vec2> nodes;
      for (unsigned int i = 0; i < boundary.n_nodes(); ++i)
        nodes.push_back(boundary.node_position(i));
      dem::ParticleSystem s;
      s.period = prm.length;
      std::vector<Vec2> centres;
      for (int g = 0; g < 300; ++g)
        {
          const Vec2 x(prm.length * U(gen), prm.bottom - 1.2 * l * U(gen) - 0.1 * l);
          s.add_disc(x, (0.4 + 0.2 * U(gen)) * l, rho);
          centres.push_back(s.wrap(x));
        }
      std::vector<double> angles(s.bodies.size(), 0.0);
      const double        distance = 0.05 * l;
      std::vector<std::pair<unsigned int, int>> found;
      for (const auto &c : hd.detect(s, centres, angles, nodes, distance))
        found.emplace_back(c.disc[1], c.half_disc);
      std::sort(found.begin(), found.end());
      const auto expected = geometric_contacts(s, hd.centres(nodes), distance);
      EXPECT_GT(expected.size(), 100u);
      EXPECT_EQ(found, expected) << "face shifted by " << spacings << " spacings";
    }
}

TEST(Coupling, GrainsSlidingUnderAShiftedFaceAreNeverLost)
{
  // A column of grains in the pockets of a sliding rigid wall, under a deal.II block
  // pressed at P whose face is shifted by 1, 3 and 6 spacings: over 400 steps of sliding
  // at 2 m/s (0.8 spacing), every grain-half-disc pair closer than half the detection
  // distance at the end of a step was a contact of that step, no grain overlaps a
  // half-disc by more than 5 % of its radius, none gets behind the face, and the
  // wall carries P L.
  for (const double spacings : {1.0, 3.0, 6.0})
    {
      dem::ParticleSystem s;
      s.period = wide * l;
      std::vector<Vec2>   c;
      std::vector<double> r;
      for (unsigned int i = 0; i < wide; ++i)
        {
          c.push_back({i * l, 0});
          r.push_back(0.5 * l);
        }
      const unsigned int wall = s.add_clump(c, r, rho);
      for (auto &d : s.bodies[wall].drive)
        d = dem::Drive::velocity;
      for (unsigned int i = 0; i < wide; ++i)
        s.add_disc({(i + 0.5) * l, y_grain}, 0.5 * l, rho);
      fem::ElasticBodyParameters prm;
      prm.length             = wide * l;
      prm.thickness          = 8 * l;
      prm.bottom             = y_grain + l;
      prm.cells_x            = wide;
      prm.cells_y            = 8;
      prm.top_pressure       = P;
      prm.pressure_ramp_time = 2e-8;
      prm.time_step          = 1e-9;
      prm.rayleigh_mass      = 2e8;
      fem::ElasticBody    body(prm);
      ShiftedBoundary     boundary(body);
      dem::SolverParameters nlgs;
      nlgs.method         = dem::SolverParameters::Method::nlgs;
      nlgs.tolerance      = 1e-6;
      nlgs.check_interval = 1;
      const double    distance = 0.05 * l;
      dem::MoreauJean mj(0.5, dem::ContactLaw{}, nlgs, distance);
      mj.attach(boundary, l, {0, -1}, prm.length);
      dem::HalfDiscs hd(boundary, l, {0, -1}, prm.length);
      boundary.shift = spacings * l;
      double wall_force = 0;
      for (int step = 0; step < 400; ++step)
        {
          if (step == 100)
            s.bodies[wall].velocity.x() = 2.0;
          mj.step(s, 1e-9);
          std::vector<std::pair<unsigned int, int>> detected;
          for (const auto &ct : mj.contacts())
            if (ct.on_boundary())
              detected.emplace_back(ct.disc[1], ct.half_disc);
          std::sort(detected.begin(), detected.end());
          std::vector<Vec2> nodes;
          for (unsigned int i = 0; i < boundary.n_nodes(); ++i)
            nodes.push_back(boundary.node_position(i));
          const auto centres = hd.centres(nodes);
          double     deepest = 0;
          for (const auto &p : geometric_contacts(s, centres, 0.5 * distance, &deepest))
            ASSERT_TRUE(std::binary_search(detected.begin(), detected.end(), p))
              << "grain " << p.first << " against half-disc " << p.second << " not detected at step "
              << step << ", face shifted by " << spacings << " spacings";
          ASSERT_GT(deepest, -0.05 * 0.5 * l) << "step " << step << ", shift " << spacings;
          double face_y = 0;
          for (const Vec2 &x : centres)
            face_y += x.y() / centres.size();
          for (unsigned int g = 1; g <= wide; ++g)
            ASSERT_LT(s.bodies[g].position.y(), face_y) << "grain " << g << " behind the face, step " << step;
          if (step >= 300)
            wall_force += -mj.contact_force()[wall].y() / 100;
        }
      EXPECT_NEAR(wall_force, P * prm.length, 0.05 * P * prm.length) << "shift " << spacings;
    }
}

TEST(Coupling, TheModelTableSaysWhichModelIsAWallOfDiscsAndWhatMayChangeOnResume)
{
  // The scene and the study ask the table, not the model's name.
  EXPECT_TRUE(tribo::coupling::is_wall_of_discs("rigid"));
  for (const char *model : {"fem", "reduced", "sph", "mlp"})
    EXPECT_FALSE(tribo::coupling::is_wall_of_discs(model)) << model;
  try
    {
      tribo::coupling::is_wall_of_discs("wood");
      FAIL() << "an unknown model was accepted";
    }
  catch (const tribo::InputError &e)
    {
      EXPECT_STREQ(e.what(), "unknown upper body model 'wood': expected rigid, fem, reduced, sph or mlp");
    }
  EXPECT_EQ(tribo::coupling::entries_that_may_change_on_resume(),
            std::vector<std::string>{"Upper body prediction depth"});
}

TEST(Coupling, EveryModelIsPlacedThroughTheOneInterface)
{
  // The scene asks the table for its upper body and gives both kinds the same place: the
  // wall of discs takes the clump the scene adds, the deformable body puts its half-discs'
  // bottom on the surface.
  coupling::FirstBodyParameters p;
  p.length = L;
  p.thickness = 1.5e-4;
  p.density = rho;
  p.youngs_modulus = 1e11;
  p.poisson_ratio = 0.3;
  p.resolution = l;
  p.time_step = 1e-9;
  p.pressure = P;
  p.rigid.compaction_speed_limit = 0.5;
  dem::ParticleSystem s;
  s.period = L;
  int walls_added = 0;
  const auto add_wall = [&]() {
    ++walls_added;
    return std::make_pair(s.add_clump({{0.25 * L, 3 * l}, {0.75 * L, 3 * l}}, {0.5 * l, 0.3 * l}, rho), 0.8 * l);
  };
  coupling::check_first_body(p);
  const auto wall = coupling::make_first_body(p, {s, 2 * l, add_wall});
  ASSERT_EQ(walls_added, 1);
  const unsigned int clump = wall->system_body();
  ASSERT_LT(clump, s.bodies.size());
  EXPECT_DOUBLE_EQ(s.bodies[clump].mass, rho * 1.5e-4 * L); // the first body's, not the discs'
  EXPECT_DOUBLE_EQ(wall->y_to_surface(), 0.4 * l);
  EXPECT_DOUBLE_EQ(wall->half_disc_diameter(), 0);
  s.bodies[clump].velocity = {0, -3};
  wall->before_step(s, 2.5, false);
  EXPECT_DOUBLE_EQ(s.bodies[clump].load[1], -2.5);
  EXPECT_DOUBLE_EQ(s.bodies[clump].velocity.y(), -0.5); // capped while compacting
  s.bodies[clump].velocity = {0, -3};
  wall->before_step(s, 2.5, true);
  EXPECT_DOUBLE_EQ(s.bodies[clump].velocity.y(), -3); // free once sliding
  EXPECT_FALSE(wall->in_energy_balance());

  p.model = "fem";
  p.thickness = 8 * l;
  coupling::check_first_body(p);
  const auto body = coupling::make_first_body(p, {s, 2 * l, add_wall});
  EXPECT_EQ(walls_added, 1);
  EXPECT_EQ(body->system_body(), coupling::FirstBody::no_system_body);
  EXPECT_DOUBLE_EQ(body->half_disc_diameter(), l); // one per cell edge
  const auto state = body->state(s, {});
  EXPECT_NEAR(state.surface, 2 * l, 1e-12 * l);
  EXPECT_NEAR(state.y, 2.5 * l, 1e-12 * l);
  EXPECT_TRUE(body->in_energy_balance());

  p.fem.modes = 5000;
  p.model = "reduced";
  EXPECT_THROW(coupling::check_first_body(p), InputError);
}
