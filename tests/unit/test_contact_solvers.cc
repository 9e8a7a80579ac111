// The sparse Delassus operator, the law residual and the active-set method against
// the dense operator, closed forms and NLGS converged to 1e-12.
#include "dem/solvers/apgs.h"
#include "dem/linalg/bisected_cholesky.h"
#include "dem/linalg/delassus.h"
#include "dem/solvers/frictionless_problem.h"
#include "dem/laws/law_residual.h"
#include "dem/engine/moreau_jean.h"

#include <Eigen/Dense>

#include <gtest/gtest.h>

#include <algorithm>

#include <cmath>
#include <map>
#include <numeric>

using namespace tribo::dem;

namespace
{
  const double rho = 7800, radius = 0.5e-6, h = 1e-9;

  /// A hyperstatic packing: three hexagonal rows of @p columns discs (six neighbours each)
  /// in a periodic cell @p columns diameters wide, on a fixed wall clump, under a wall
  /// clump free in y and pushed down by @p load (N/m), the lower wall sliding at @p slide
  /// m/s.
  ParticleSystem hexagonal_stack(double load, double slide, int columns = 4)
  {
    ParticleSystem s;
    const double   d = 2 * radius, row = d * std::sqrt(3.0) / 2;
    s.period         = columns * d;
    std::vector<Vec2>   wall;
    std::vector<double> radii(columns, radius);
    for (int i = 0; i < columns; ++i)
      wall.push_back({(i + 0.5) * d, 0});
    const unsigned lower = s.add_clump(wall, radii, rho);
    for (auto &k : s.bodies[lower].drive)
      k = Drive::velocity;
    s.bodies[lower].velocity = {slide, 0};
    for (int j = 1; j <= 3; ++j)
      for (int i = 0; i < columns; ++i)
        s.add_disc({(i + (j % 2 ? 1.0 : 0.5)) * d, j * row}, radius, rho);
    for (auto &p : wall)
      p = {p.x(), 4 * row}; // row 4 sits like row 0
    const unsigned upper   = s.add_clump(wall, radii, rho);
    s.bodies[upper].drive  = {{Drive::velocity, Drive::force, Drive::velocity}};
    s.bodies[upper].load[1] = -load;
    return s;
  }

  SolverParameters nlgs_converged()
  {
    SolverParameters p;
    p.method         = SolverParameters::Method::nlgs;
    p.tolerance      = 1e-12;
    p.check_interval = 1;
    p.max_iterations = 200000;
    return p;
  }

  SolverParameters active_set()
  {
    SolverParameters p;
    p.method          = SolverParameters::Method::active_set;
    p.residual_target = 1e-11;
    return p;
  }

  /// The global methods, each to a law residual of 1e-11 (MPRGP, APGD: up to 1e5 products; the
  /// interior-point method stops at its round-off floor, reported not converged).
  std::vector<SolverParameters> global_methods()
  {
    SolverParameters mprgp;
    mprgp.method          = SolverParameters::Method::mprgp;
    mprgp.residual_target = 1e-11;
    mprgp.max_iterations  = 100000;
    SolverParameters interior_point;
    interior_point.method          = SolverParameters::Method::interior_point;
    interior_point.residual_target = 1e-11;
    SolverParameters apgd = mprgp;
    apgd.method           = SolverParameters::Method::apgd;
    SolverParameters apgs = mprgp;
    apgs.method           = SolverParameters::Method::apgs;
    return {active_set(), mprgp, interior_point, apgd, apgs};
  }

  /// The law residual @p prm's method reaches when asked for 1e-11: the interior-point
  /// method's round-off floor is higher (its matrix's condition grows like 1 / mu).
  double reached(const SolverParameters &prm)
  {
    return prm.method == SolverParameters::Method::interior_point ? 1e-7 : 1e-9;
  }

  /// Velocities (v_x, v_y, spin) of every body after @p steps steps with @p prm.
  Eigen::VectorXd velocities_after(ParticleSystem s, const ContactLaw &law,
                                   const SolverParameters &prm, int steps,
                                   std::vector<SolveReport> *reports = nullptr)
  {
    MoreauJean mj(0.5, law, prm, 0.1 * radius);
    for (int i = 0; i < steps; ++i)
      {
        const auto rep = mj.step(s, h);
        if (reports)
          reports->push_back(rep.solver);
      }
    Eigen::VectorXd v(3 * s.bodies.size());
    for (std::size_t b = 0; b < s.bodies.size(); ++b)
      v.segment<3>(3 * b) << s.bodies[b].velocity, s.bodies[b].spin;
    return v;
  }
  /// Every global method gives the velocities of NLGS converged to 1e-12 after @p steps
  /// steps of @p s, converged (the interior point: to its round-off floor), no fallback.
  void expect_global_methods_match_converged_nlgs(const ParticleSystem &s, const ContactLaw &law,
                                                  int steps)
  {
    const Eigen::VectorXd v_nlgs = velocities_after(s, law, nlgs_converged(), steps);
    for (const SolverParameters &prm : global_methods())
      {
        std::vector<SolveReport> reports;
        const Eigen::VectorXd    v = velocities_after(s, law, prm, steps, &reports);
        EXPECT_LT((v - v_nlgs).norm(), 1e-6 * v_nlgs.norm()) << method_name(prm.method);
        for (const auto &r : reports)
          {
            if (prm.method != SolverParameters::Method::interior_point)
              {
                EXPECT_TRUE(r.converged) << method_name(prm.method);
              }
            EXPECT_FALSE(r.fell_back);
            EXPECT_LT(r.law_residual, reached(prm)) << method_name(prm.method);
          }
      }
  }
} // namespace

TEST(ContactSolvers, SparseDelassusEqualsTheDenseOperator)
{
  // W_ij from the exchange of impulses through the bodies (BodyState, tested against
  // the dense H^T M^-1 H in test_delassus.cc), column by column.
  ParticleSystem s = hexagonal_stack(100, 1);
  MoreauJean     mj(0.5, ContactLaw{}, SolverParameters{}, 0.1 * radius);
  mj.step(s, h);
  const std::vector<Contact> &contacts = mj.contacts();
  ASSERT_GE(contacts.size(), 30u);
  const BodyState                   state = BodyState::of(s);
  const Eigen::SparseMatrix<double> W     = assemble_delassus(contacts, state, DelassusPart::full);
  const Eigen::SparseMatrix<double> Wn    = assemble_delassus(contacts, state, DelassusPart::normal);
  Eigen::MatrixXd                   exchanged(2 * contacts.size(), 2 * contacts.size());
  for (std::size_t j = 0; j < contacts.size(); ++j)
    for (int a = 0; a < 2; ++a)
      {
        BodyState       st = state;
        Eigen::Vector2d r  = Eigen::Vector2d::Zero();
        r[a]               = 1e-9;
        st.apply_impulse(contacts[j], r);
        for (std::size_t i = 0; i < contacts.size(); ++i)
          exchanged.block<2, 1>(2 * i, 2 * j + a) =
            (st.local_velocity(contacts[i]) - state.local_velocity(contacts[i])) / 1e-9;
      }
  const Eigen::MatrixXd dense = Eigen::MatrixXd(W);
  EXPECT_LT((dense - exchanged).norm(), 1e-9 * exchanged.norm());
  // Assembled on two threads: the same entries, bit for bit.
  for (const DelassusPart part : {DelassusPart::full, DelassusPart::normal})
    {
      const Eigen::SparseMatrix<double> one = assemble_delassus(contacts, state, part, nullptr, 1),
                                        two = assemble_delassus(contacts, state, part, nullptr, 2);
      ASSERT_EQ(one.nonZeros(), two.nonZeros());
      EXPECT_TRUE(std::equal(one.valuePtr(), one.valuePtr() + one.nonZeros(), two.valuePtr()));
      EXPECT_TRUE(std::equal(one.innerIndexPtr(), one.innerIndexPtr() + one.nonZeros(), two.innerIndexPtr()));
      EXPECT_TRUE(std::equal(one.outerIndexPtr(), one.outerIndexPtr() + one.cols() + 1, two.outerIndexPtr()));
    }
  EXPECT_LT((dense - dense.transpose()).norm(), 1e-12 * dense.norm());
  for (std::size_t i = 0; i < contacts.size(); ++i)
    {
      EXPECT_NEAR(Wn.coeff(i, i), dense(2 * i, 2 * i), 1e-12 * dense(2 * i, 2 * i));
      EXPECT_LT((dense.block<2, 2>(2 * i, 2 * i) - state.delassus_block(contacts[i])).norm(),
                1e-12 * dense(2 * i, 2 * i));
    }
}

TEST(ContactSolvers, WallsAsLowRankColumnsAddUpToTheOperator)
{
  // W = W_sparse + U U^T whichever bodies are kept out (contact limit 0: every body that
  // is not imposed; 6: the walls of this 36-column stack, whose discs have six contacts), both parts; the free wall
  // contributes one column (its y dof), the discs three each.
  ParticleSystem s = hexagonal_stack(100, 1, 36);
  MoreauJean     mj(0.5, ContactLaw{}, SolverParameters{}, 0.1 * radius);
  mj.step(s, h);
  const std::vector<Contact> &contacts = mj.contacts();
  const BodyState             state    = BodyState::of(s);
  for (const DelassusPart part : {DelassusPart::full, DelassusPart::normal})
    {
      const Eigen::MatrixXd W = Eigen::MatrixXd(assemble_delassus(contacts, state, part));
      for (const unsigned int limit : {0u, 6u})
        {
          LowRankBodies   low_rank;
          low_rank.contact_limit = limit;
          const Eigen::MatrixXd sparse = Eigen::MatrixXd(assemble_delassus(contacts, state, part, &low_rank));
          EXPECT_LT((sparse + low_rank.U * low_rank.U.transpose() - W).norm(), 1e-12 * W.norm());
          EXPECT_EQ(low_rank.U.cols(), limit == 0 ? 1 + 3 * 108 : 1);
        }
    }
}

TEST(ContactSolvers, GlobalMethodsWithTheWallAsLowRankMatchConvergedNlgs)
{
  // 36 columns: the upper wall carries more than 64 contacts, so the interior-point
  // method solves through Sherman-Morrison-Woodbury and MPRGP multiplies by
  // A_sparse + U U^T (dem/linalg/delassus.h).
  const ParticleSystem s = hexagonal_stack(3600, 2, 36);
  {
    ParticleSystem probe = s;
    MoreauJean     mj(0.5, ContactLaw{}, SolverParameters{}, 0.1 * radius);
    mj.step(probe, h);
    unsigned int on_upper = 0;
    for (const Contact &c : mj.contacts())
      on_upper += c.body[0] == 109 || c.body[1] == 109;
    ASSERT_GT(on_upper, 64u);
  }
  SolverParameters ipm;
  ipm.method          = SolverParameters::Method::interior_point;
  ipm.residual_target = 1e-11;
  SolverParameters mprgp;
  mprgp.method          = SolverParameters::Method::mprgp;
  mprgp.residual_target = 1e-11;
  mprgp.max_iterations  = 100000;
  SolverParameters apgd = mprgp;
  apgd.method           = SolverParameters::Method::apgd;
  SolverParameters apgs = mprgp; // its sweeps keep the wall's low-rank part current in place
  apgs.method           = SolverParameters::Method::apgs;
  const Eigen::VectorXd v_nlgs = velocities_after(s, ContactLaw{}, nlgs_converged(), 3);
  for (const SolverParameters &prm : {ipm, mprgp, apgd, apgs})
    {
      std::vector<SolveReport> reports;
      const Eigen::VectorXd    v = velocities_after(s, ContactLaw{}, prm, 3, &reports);
      EXPECT_LT((v - v_nlgs).norm(), 1e-6 * v_nlgs.norm()) << method_name(prm.method);
      for (const auto &r : reports)
        {
          EXPECT_LT(r.law_residual, 1e-7) << method_name(prm.method);
          if (prm.method != SolverParameters::Method::interior_point) // it stops at its floor
            {
              EXPECT_TRUE(r.converged) << method_name(prm.method);
            }
        }
    }
}

namespace
{
  /// The 400-disc stack after 20 steps solved by the active set: its contacts and state.
  struct SolvedStack
  {
    ParticleSystem       s = hexagonal_stack(400, 0);
    const ContactLaw     law;
    std::vector<Contact> contacts;
    BodyState            state;
    SolvedStack()
    {
      MoreauJean mj(0.5, law, active_set(), 0.1 * radius);
      for (int i = 0; i < 20; ++i)
        mj.step(s, h);
      contacts = mj.contacts();
      state    = BodyState::of(s);
    }
  };
} // namespace

TEST(ContactSolvers, LawResidualIsZeroWhenSolvedAndPositiveWhenAContactIsLeftUnsolved)
{
  SolvedStack           stack;
  const ContactLaw     &law      = stack.law;
  std::vector<Contact> &contacts = stack.contacts;
  BodyState            &state    = stack.state;
  const LawResidual     solved   = law_residual(contacts, state, law, 0.5 * h);
  EXPECT_GT(solved.mean_impulse, 0.0);
  EXPECT_LT(solved.relative, 1e-9);
  EXPECT_LT(solved.gap_violation, 1e-9 * radius);
  // Remove the impulse of the most loaded contact from it and from the bodies.
  std::size_t loaded = 0;
  for (std::size_t i = 0; i < contacts.size(); ++i)
    if (contacts[i].r.x() > contacts[loaded].r.x())
      loaded = i;
  const Eigen::Vector2d r = contacts[loaded].r;
  state.apply_impulse(contacts[loaded], -r);
  contacts[loaded].r.setZero();
  const LawResidual unsolved = law_residual(contacts, state, law, 0.5 * h);
  EXPECT_GT(unsolved.relative, 0.1);
  EXPECT_GT(unsolved.gap_violation, 0.0);
}

TEST(ContactSolvers, LawResidualWithNothingLoadedReadsAgainstTheContactsVelocities)
{
  // Every impulse of the solved stack removed: nothing is loaded, and the closing contacts'
  // residual reads against the mean impulse that would stop the contacts' velocities, so it
  // is large; a contact left closing slowly among separating ones is not.
  SolvedStack stack;
  for (Contact &c : stack.contacts)
    {
      stack.state.apply_impulse(c, -c.r);
      c.r.setZero();
    }
  const LawResidual free = law_residual(stack.contacts, stack.state, stack.law, 0.5 * h);
  EXPECT_EQ(free.loaded, 0u);
  EXPECT_GT(free.velocity_scale, 0.0);
  EXPECT_GT(free.relative, 0.1);
  EXPECT_DOUBLE_EQ(free.relative, free.max_phi / free.velocity_scale);
  EXPECT_DOUBLE_EQ(relative_law_residual(1.9e-17, 0, 1e-9), 1.9e-8);
  EXPECT_EQ(relative_law_residual(1e-17, 0, 0), 1.0);
  EXPECT_EQ(relative_law_residual(0, 0, 0), 0.0);
  EXPECT_DOUBLE_EQ(relative_law_residual(1e-3, 2.0, 1e-9), 5e-4); // loaded: the mean impulse
  EXPECT_DOUBLE_EQ(relative_law_residual(1e-15, 1e-16, 1e-9), 10.0); // loaded, however little
  // ... down to 1e-12 of the velocity scale; below, round-off on contacts that carry nothing
  // (2.6e-31 N s/m seen on two ranks): nothing loaded.
  EXPECT_DOUBLE_EQ(relative_law_residual(1e-30, 2e-21, 1e-9), 5e-10);
  EXPECT_DOUBLE_EQ(relative_law_residual(4.7e-35, 2.6e-31, 1e-9), 4.7e-26);
}

TEST(ContactSolvers, ApgsPolishesOneWrongContactWithoutAWholeSweep)
{
  // A converged wide stack (300 columns, about 2700 contacts) with the impulse of its most
  // loaded contact removed: the contacts above the target are that one and its bodies'
  // other contacts, far fewer than ApgsSolver::polish_fraction of all, so the local polish
  // (dem/solvers/apgs.h) restores the solution to the target before any block of
  // ApgsSolver::check_interval sweeps (without it: one check, 10 sweeps, one check at least).
  ParticleSystem   s = hexagonal_stack(30000, 0, 300);
  const ContactLaw law;
  SolverParameters converged;
  converged.method          = SolverParameters::Method::apgs;
  converged.residual_target = 1e-11;
  converged.max_iterations  = 100000;
  MoreauJean mj(0.5, law, converged, 0.1 * radius);
  for (int i = 0; i < 20; ++i)
    mj.step(s, h);
  std::vector<Contact> contacts = mj.contacts();
  BodyState            state    = BodyState::of(s);
  ASSERT_LT(law_residual(contacts, state, law, 0.5 * h).relative, 1e-10);
  // The most loaded contact between two grains (the walls, bodies 0 and the last, touch
  // every contact of their row).
  const unsigned int upper_wall = s.bodies.size() - 1;
  auto between_grains = [&](const Contact &c) {
    return c.body[0] != 0 && c.body[1] != 0 && c.body[0] != upper_wall && c.body[1] != upper_wall;
  };
  std::size_t loaded = contacts.size();
  for (std::size_t i = 0; i < contacts.size(); ++i)
    if (between_grains(contacts[i]) && (loaded == contacts.size() || contacts[i].r.x() > contacts[loaded].r.x()))
      loaded = i;
  ASSERT_LT(loaded, contacts.size());
  const Eigen::Vector2d r = contacts[loaded].r;
  state.apply_impulse(contacts[loaded], -r);
  contacts[loaded].r.setZero();
  ASSERT_GT(law_residual(contacts, state, law, 0.5 * h).relative, 0.1);

  SolverParameters prm;
  prm.method          = SolverParameters::Method::apgs;
  prm.residual_target = 1e-3; // the shipped cases' accuracy (tighter, the local passes converge slowly)
  prm.predictor_sweeps = 0;
  ApgsSolver        apgs(prm);
  const SolveReport report = apgs.solve(contacts, state, law);
  EXPECT_TRUE(report.converged);
  // One pass: the first check (which failed, above). The polishes' own checks recompute
  // the polished neighbourhoods only and are not passes; no sweep was made.
  EXPECT_EQ(report.iterations, 1u);
  // A solution (the stack is hyperstatic: its impulses need not be the removed ones).
  EXPECT_LT(law_residual(contacts, state, law, 0.5 * h).relative, prm.residual_target);
}

TEST(ContactSolvers, GlobalMethodsCarryTheAppliedForceOfADiscOnAWall)
{
  // Closed form: a disc touching a fixed wall under a load F is held by r_n = h F. The
  // wall's other discs lie beyond what the load could carry the disc in a step (h^2 F / m,
  // which contact detection foresees): one contact.
  for (SolverParameters prm : global_methods())
    {
      ParticleSystem s;
      const unsigned wall = s.add_clump({{-3e-6, 0}, {0, 0}, {3e-6, 0}}, {radius, radius, radius}, rho);
      for (auto &k : s.bodies[wall].drive)
        k = Drive::velocity;
      const unsigned disc     = s.add_disc({0, 2 * radius}, radius, rho);
      const double   F        = -120.0;
      s.bodies[disc].drive[1] = Drive::force;
      s.bodies[disc].load[1]  = F;
      prm.predictor_sweeps    = 0; // the method's own iterations alone
      MoreauJean mj(0.5, ContactLaw{}, prm, 1e-8);
      const auto report = mj.step(s, 1e-8);
      const std::string name = method_name(prm.method);
      EXPECT_EQ(report.n_contacts, 1u) << name;
      EXPECT_FALSE(report.solver.fell_back) << name;
      if (prm.method != SolverParameters::Method::interior_point)
        {
          EXPECT_TRUE(report.solver.converged) << name;
        }
      if (prm.method == SolverParameters::Method::mprgp || prm.method == SolverParameters::Method::apgd ||
          prm.method == SolverParameters::Method::apgs)
        {
          EXPECT_GE(report.solver.iterations, 1u);
        }
      else
        {
          EXPECT_GE(report.solver.factorizations, 1u);
        }
      EXPECT_NEAR(mj.contact_force()[disc].y(), -F, 1e-9 * std::abs(F)) << name;
      EXPECT_LT(report.solver.law_residual, 1e-3 * reached(prm)) << name;
    }
}

TEST(ContactSolvers, GlobalMethodsKeepAnOpenContactQuietUntilItCloses)
{
  // A disc 10 nm above a fixed wall (inside the detection distance: a contact that stays
  // open for about 350 steps), pulled down by F: it lands and then rests, held by r_n = h F.
  // The interior-point method once carried the interior impulses of the open contact
  // into its warm start, shrinking its start step after step until the landing blew up.
  for (SolverParameters prm : global_methods())
    {
      prm.residual_target = 1e-3;
      ParticleSystem s;
      const unsigned wall = s.add_clump({{-1e-6, 0}, {0, 0}, {1e-6, 0}}, {radius, radius, radius}, rho);
      for (auto &k : s.bodies[wall].drive)
        k = Drive::velocity;
      const unsigned disc     = s.add_disc({0, 2 * radius + 1e-8}, radius, rho);
      const double   F        = -1e-3; // 350 steps to land
      s.bodies[disc].drive[1] = Drive::force;
      s.bodies[disc].load[1]  = F;
      MoreauJean   mj(0.5, ContactLaw{}, prm, 0.1 * radius);
      const double h = 1e-9;
      double       fastest = 0;
      for (int i = 0; i < 3000; ++i)
        {
          mj.step(s, h);
          fastest = std::max(fastest, s.bodies[disc].velocity.norm());
        }
      const std::string name = method_name(prm.method);
      // Free fall over 10 nm under F / m: v = sqrt(2 a d), about 0.1 m/s.
      const double a = std::abs(F) / s.bodies[disc].mass;
      EXPECT_LT(fastest, 2 * std::sqrt(2 * a * 1e-8)) << name;
      EXPECT_NEAR(mj.contact_force()[disc].y(), -F, 1e-3 * std::abs(F)) << name;
      // IQS freezes the landing's overlap, at most (1 - theta) h v.
      EXPECT_LE(s.bodies[disc].position.y(), 2 * radius) << name;
      EXPECT_GE(s.bodies[disc].position.y(), 2 * radius - 0.5 * h * fastest) << name;
    }
}

TEST(ContactSolvers, GlobalMethodsMatchConvergedNlgsOnAHyperstaticStack)
{
  // Six contacts per disc: the impulses are not unique, the velocities are.
  expect_global_methods_match_converged_nlgs(hexagonal_stack(400, 2), ContactLaw{}, 40);
}

TEST(ContactSolvers, GlobalMethodsMatchConvergedNlgsOnACohesiveCluster)
{
  // Upper wall pulled away: the cohesive bonds hold the grains to both walls.
  ContactLaw law;
  law.cohesion       = 50;
  law.cohesion_range = 0.05 * radius;
  expect_global_methods_match_converged_nlgs(hexagonal_stack(-200, 1), law, 30);
}

TEST(ContactSolvers, GlobalMethodsWithElasMatchConvergedNlgs)
{
  // ELAS shifts every near contact by g / (theta h): on this stack the projected Newton
  // iterations converge only linearly in some steps, which then finish with NLGS (here
  // converged to 1e-12 too): the result must not depend on it, and most steps must not
  // need it.
  ContactLaw law;
  law.type      = ContactLaw::Type::elas;
  law.stiffness = 1e12;
  SolverParameters prm = nlgs_converged();
  prm.method           = SolverParameters::Method::active_set;
  prm.residual_target  = 1e-11;
  std::vector<SolveReport> reports;
  const ParticleSystem     s      = hexagonal_stack(400, 1);
  const Eigen::VectorXd    v_as   = velocities_after(s, law, prm, 30, &reports);
  const Eigen::VectorXd    v_nlgs = velocities_after(s, law, nlgs_converged(), 30);
  EXPECT_LT((v_as - v_nlgs).norm(), 1e-6 * v_nlgs.norm());
  unsigned fallbacks = 0;
  for (const auto &r : reports)
    {
      fallbacks += r.fell_back;
      if (!r.fell_back)
        {
          EXPECT_LT(r.law_residual, 1e-9);
        }
    }
  EXPECT_LE(fallbacks, 10u);
  // MPRGP, the interior-point method, APGD and APGS: the compliance makes A better
  // conditioned; they have no fallback and need none.
  for (const SolverParameters &prm : {global_methods()[1], global_methods()[2], global_methods()[3], global_methods()[4]})
    {
      reports.clear();
      const Eigen::VectorXd v = velocities_after(s, law, prm, 30, &reports);
      EXPECT_LT((v - v_nlgs).norm(), 1e-6 * v_nlgs.norm()) << method_name(prm.method);
      for (const auto &r : reports)
        EXPECT_LT(r.law_residual, reached(prm)) << method_name(prm.method);
    }
}

TEST(ContactSolvers, GlobalMethodsWithoutAFrictionalSolveUseNlgs)
{
  ContactLaw law;
  law.friction = 0.3;
  for (const SolverParameters &prm : global_methods())
    {
      if (solves_friction(prm.method))
        continue;
      std::vector<SolveReport> reports;
      const Eigen::VectorXd v     = velocities_after(hexagonal_stack(400, 2), law, prm, 5, &reports);
      SolverParameters      nlgs  = prm;
      nlgs.method                 = SolverParameters::Method::nlgs;
      const Eigen::VectorXd v_ref = velocities_after(hexagonal_stack(400, 2), law, nlgs, 5);
      EXPECT_EQ(v, v_ref) << method_name(prm.method);
      for (const auto &r : reports)
        {
          EXPECT_EQ(r.factorizations, 0u);
          EXPECT_GT(r.iterations, 0u);
        }
    }
}

namespace
{
  /// APGS to a law residual of 1e-8 (the frictional sweeps' floor is near 1e-9, dem/solvers/apgs.h).
  SolverParameters frictional_apgs()
  {
    SolverParameters apgs;
    apgs.method          = SolverParameters::Method::apgs;
    apgs.residual_target = 1e-8;
    apgs.max_iterations  = 100000;
    return apgs;
  }

  /// Every step of @p reports converged, by the method itself, to a law residual (friction
  /// term included, measured from the bodies' velocities) below twice @p target.
  void expect_law_solved(const std::vector<SolveReport> &reports, double target = 1e-8)
  {
    for (const auto &r : reports)
      {
        EXPECT_TRUE(r.converged) << r.iterations << " sweeps, law residual " << r.law_residual;
        EXPECT_FALSE(r.fell_back);
        EXPECT_EQ(r.factorizations, 0u);
        EXPECT_LT(r.law_residual, 2 * target);
      }
  }
} // namespace

TEST(ContactSolvers, FrictionalMethodsGiveTheClosedFormOfADiscLandingOnASlidingWall)
{
  // A disc (radius R, mass m, I = m R^2 / 2) lands on a wall clump sliding at V. In the
  // contact's frame at the predicted configuration (n from the wall disc to the disc,
  // t = (-n_y, n_x), gap g < 0, the contact point at a = R + g / 2 from the disc's centre)
  // the contact point's relative velocity is u0 = (n, t).(v0 + w0 k x (-a n) - V) and
  // W = diag(1/m, 1/m + a^2 / I). IQS closes the contact (the predicted gap is an overlap:
  // u_n = 0), P_n = -m u_n0; P_t = -u_t0 / W_tt (stick, rolling) if |P_t| <= mu P_n, else
  // -mu P_n sign(u_t0) (slip). Then v = v0 + (P_n n + P_t t) / m, w = w0 - a P_t / I.
  const double mu = 0.4, V = 1.5, vy0 = -2, w0 = 1e5;
  for (const double vx0 : {1.6, 0.2, 3.0, -2.0})
    for (SolverParameters prm : {nlgs_converged(), frictional_apgs()})
      {
        ParticleSystem s;
        const unsigned wall = s.add_clump({{0, 0}, {2 * radius, 0}}, {radius, radius}, rho);
        for (auto &k : s.bodies[wall].drive)
          k = Drive::velocity;
        s.bodies[wall].velocity = {V, 0};
        const unsigned disc     = s.add_disc({0, 2 * radius}, radius, rho);
        s.bodies[disc].velocity = {vx0, vy0};
        s.bodies[disc].spin     = w0;
        ContactLaw law;
        law.friction = mu;
        MoreauJean       mj(0.5, law, prm, 0.1 * radius);
        const StepReport report = mj.step(s, h);

        const double m = M_PI * radius * radius * rho, I = m * radius * radius / 2;
        const Vec2   branch = Vec2(0.5 * h * vx0, 2 * radius + 0.5 * h * vy0) - Vec2(0.5 * h * V, 0);
        const Vec2   n      = branch.normalized();
        const Vec2   t(-n.y(), n.x());
        const double a     = radius + 0.5 * (branch.norm() - 2 * radius);
        const Vec2   v_rel = Vec2(vx0, vy0) - w0 * a * t - Vec2(V, 0);
        const double Pn = -m * n.dot(v_rel), stick = -t.dot(v_rel) / (1 / m + a * a / I);
        const double Pt = std::abs(stick) <= mu * Pn ? stick : (stick > 0 ? mu * Pn : -mu * Pn);
        const Vec2   v  = Vec2(vx0, vy0) + (Pn * n + Pt * t) / m;
        EXPECT_EQ(report.n_active, 1u);
        EXPECT_LT((s.bodies[disc].velocity - v).norm(), 1e-12 * v.norm()) << method_name(prm.method) << " " << vx0;
        EXPECT_NEAR(s.bodies[disc].spin, w0 - a * Pt / I, 1e-12 * w0) << method_name(prm.method) << " " << vx0;
      }
}

TEST(ContactSolvers, FrictionalApgsSolvesTheLawOnAShearedHyperstaticStack)
{
  // The lower wall slides at 2 m/s under a load: contacts stick and slip, the walls (clumps,
  // low-rank columns) couple the normal and tangential rows. With friction the velocities of
  // this packing are not unique (NLGS and APGS, both to 1e-12, end 10-60 % apart after one
  // step: two solutions of one law), so the test is the law itself, measured from the bodies.
  // The sweeps' floor on this thin, fast-sheared stack rises to 1e-8 within 40 steps.
  ContactLaw law;
  law.friction = 0.3;
  std::vector<SolveReport> reports;
  SolverParameters         prm = frictional_apgs();
  prm.residual_target          = 1e-6;
  velocities_after(hexagonal_stack(400, 2), law, prm, 40, &reports);
  expect_law_solved(reports, prm.residual_target);
  EXPECT_GT(reports.back().iterations, 1u);
}

TEST(ContactSolvers, FrictionalApgsSolvesTheLawOnACohesiveCluster)
{
  // Friction on the shifted impulse r_n + gamma h: bonds in tension still carry a tangential
  // impulse. Not unique either (NLGS's velocities differ by more than their norm).
  ContactLaw law;
  law.friction       = 0.3;
  law.cohesion       = 50;
  law.cohesion_range = 0.05 * radius;
  std::vector<SolveReport> reports;
  velocities_after(hexagonal_stack(-200, 1), law, frictional_apgs(), 30, &reports);
  expect_law_solved(reports);
}

TEST(ContactSolvers, FrictionalApgsMatchesConvergedNlgsWithElas)
{
  // ELAS's compliance makes the solution unique.
  ContactLaw law;
  law.type      = ContactLaw::Type::elas;
  law.stiffness = 1e9;
  law.friction  = 0.3;
  std::vector<SolveReport> reports;
  const Eigen::VectorXd    v_nlgs = velocities_after(hexagonal_stack(400, 1), law, nlgs_converged(), 30);
  const Eigen::VectorXd    v      = velocities_after(hexagonal_stack(400, 1), law, frictional_apgs(), 30, &reports);
  EXPECT_LT((v - v_nlgs).norm(), 1e-6 * v_nlgs.norm());
  expect_law_solved(reports);
}

TEST(ContactSolvers, FrictionalApgsGivesTheSameBitsOnTwoThreads)
{
  // Without NLGS's predictor sweeps, whose bands change their order with the threads.
  ContactLaw law;
  law.friction = 0.3;
  SolverParameters prm;
  prm.method           = SolverParameters::Method::apgs;
  prm.predictor_sweeps = 0;
  std::vector<SolveReport> one, two;
  const Eigen::VectorXd    v1 = velocities_after(hexagonal_stack(3600, 2, 180), law, prm, 10, &one);
  prm.threads                 = 2;
  const Eigen::VectorXd v2    = velocities_after(hexagonal_stack(3600, 2, 180), law, prm, 10, &two);
  EXPECT_EQ(v1, v2);
}

namespace
{
  /// One contact between a fixed body 0 and a disc 1 (mass 2 kg/m, moment 0.5 kg m, arms
  /// @p arm_n and @p arm_t): normal (0, 1), tangent (-1, 0). Its impulse is @p r and the
  /// disc's velocity gives the local velocity @p u; returns the law residual under @p law.
  LawResidual one_contact_residual(const ContactLaw &law, const Eigen::Vector2d &r, const Eigen::Vector2d &u,
                                   double arm_n = 0, double arm_t = 0.5)
  {
    BodyState state;
    state.velocity     = {Eigen::Vector3d::Zero(), Eigen::Vector3d(-u.y(), u.x(), 0)};
    state.inverse_mass = {{{0, 0, 0}}, {{0.5, 0.5, 2}}};
    Contact c;
    c.body[0] = 0;
    c.body[1] = 1;
    c.normal  = Vec2(0, 1);
    c.arm_n[1] = arm_n;
    c.arm_t[1] = arm_t;
    c.W        = state.delassus_block(c);
    c.r        = r;
    return law_residual({c}, state, law, 0);
  }
} // namespace

TEST(ContactSolvers, LawResidualsFrictionTermMatchesClosedForms)
{
  ContactLaw law;
  law.friction = 0.3;
  // W = diag(1/m, 1/m + arm_t^2 / I) = diag(0.5, 1): rho_t = 1 / W_tt = 1 s/m per N s/m.
  // Stick: |r_t| < mu r_n with u = 0 is the law; a slip u_t left in it costs u_t / W_tt.
  EXPECT_EQ(one_contact_residual(law, {1, 0.2}, {0, 0}).max_phi, 0.0);
  EXPECT_NEAR(one_contact_residual(law, {1, 0.2}, {0, 0.05}).max_phi, 0.05, 1e-15);
  // Slip: r_t = -mu r_n sign(u_t) is the law whatever |u_t|.
  EXPECT_EQ(one_contact_residual(law, {1, -0.3}, {0, 0.4}).max_phi, 0.0);
  EXPECT_EQ(one_contact_residual(law, {1, 0.3}, {0, -7.0}).max_phi, 0.0);
  // Sliding against the wrong sign: phi_t = r_t - proj(r_t - u_t / W_tt) = 0.4, then 2 mu r_n.
  EXPECT_NEAR(one_contact_residual(law, {1, 0.3}, {0, 0.4}).max_phi, 0.4, 1e-15);
  EXPECT_NEAR(one_contact_residual(law, {1, 0.3}, {0, 1.0}).max_phi, 0.6, 1e-15);
  // Outside the cone at rest: |r_t| - mu r_n.
  EXPECT_NEAR(one_contact_residual(law, {1, 0.5}, {0, 0}).max_phi, 0.2, 1e-15);
  // Relative to the mean loaded impulse.
  EXPECT_NEAR(one_contact_residual(law, {2, 0.3}, {0, 0.1}).relative, 0.1 / 2, 1e-15);
  // The friction term needs friction: the same slip, frictionless, is only the normal term's.
  EXPECT_EQ(one_contact_residual(ContactLaw{}, {1, 0.2}, {0, 0.05}).max_phi, 0.0);

  // The coupled block (W_nt != 0: an arm along the normal, as on a clump): every solution of
  // the local problem solve_coulomb() returns has a zero residual, in stick and in slip.
  const double arm_n = 0.2, arm_t = 0.5;
  BodyState    probe;
  probe.velocity     = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  probe.inverse_mass = {{{0, 0, 0}}, {{0.5, 0.5, 2}}};
  Contact c;
  c.body[1]                 = 1;
  c.normal                  = Vec2(0, 1);
  c.arm_n[1]                = arm_n;
  c.arm_t[1]                = arm_t;
  const Eigen::Matrix2d W   = probe.delassus_block(c);
  ASSERT_NEAR(W(0, 1), 2 * arm_n * arm_t, 1e-15);
  for (const Eigen::Vector2d &q : {Eigen::Vector2d(-1, 0.01), Eigen::Vector2d(-1, 0.5), Eigen::Vector2d(-1, -2)})
    {
      const Eigen::Vector2d r = law.solve_coulomb(W(0, 0), W(0, 1), W(1, 0), W(1, 1), q.x(), q.y());
      const Eigen::Vector2d u = W * r + q;
      EXPECT_LT(one_contact_residual(law, r, u, arm_n, arm_t).max_phi, 1e-12 * r.norm()) << q.transpose();
      EXPECT_LE(std::abs(r.y()), law.friction * r.x() * (1 + 1e-12));
    }
  // q_t = 0.01: stick (u = 0); q_t = 0.5 and -2: slip opposite to the sliding velocity.
  const Eigen::Vector2d stick = law.solve_coulomb(W(0, 0), W(0, 1), W(1, 0), W(1, 1), -1, 0.01);
  EXPECT_LT((W * stick + Eigen::Vector2d(-1, 0.01)).norm(), 1e-14);
  const Eigen::Vector2d slip = law.solve_coulomb(W(0, 0), W(0, 1), W(1, 0), W(1, 1), -1, 0.5);
  EXPECT_NEAR(slip.y(), -law.friction * slip.x(), 1e-15);
  EXPECT_GT((W * slip + Eigen::Vector2d(-1, 0.5)).y(), 0);
}

TEST(ContactSolvers, InteriorPointReachesATightTargetAtEveryWarmStartedStepOfAHyperstaticStack)
{
  // Each warm-started step ends at the target, whether the iteration gets there or the
  // crossover closes the closed set exactly (dem/solvers/interior_point.cc), and the velocities
  // are converged NLGS's: a crossover that froze a growing component along the redundant
  // directions would break both within a few steps.
  SolverParameters prm;
  prm.method          = SolverParameters::Method::interior_point;
  prm.residual_target = 1e-10;
  std::vector<SolveReport> reports;
  const ParticleSystem     stack  = hexagonal_stack(400, 2);
  const Eigen::VectorXd    v      = velocities_after(stack, ContactLaw{}, prm, 40, &reports);
  const Eigen::VectorXd    v_nlgs = velocities_after(stack, ContactLaw{}, nlgs_converged(), 40);
  EXPECT_LT((v - v_nlgs).norm(), 1e-6 * v_nlgs.norm());
  for (std::size_t step = 1; step < reports.size(); ++step)
    {
      EXPECT_TRUE(reports[step].converged) << "step " << step;
      EXPECT_LT(reports[step].law_residual, 1e-10) << "step " << step;
    }
}

TEST(ContactSolvers, InteriorPointOnTwoThreadsGivesOneThreadsSolution)
{
  // A hexagonal stack 700 discs wide (three rows, about 6300 contacts): with two threads
  // its Newton matrix is factorised in two halves; both reach the target and the steps'
  // velocities are one thread's.
  const ParticleSystem s = hexagonal_stack(70000, 2, 700);
  SolverParameters prm;
  prm.method          = SolverParameters::Method::interior_point;
  prm.residual_target = 1e-8; // the converged target
  std::vector<ParticleSystem> runs(2, s);
  std::vector<SolveReport>    last(2);
  for (const unsigned int threads : {1u, 2u})
    {
      prm.threads = threads;
      MoreauJean mj(0.5, ContactLaw{}, prm, 0.1 * radius);
      for (int step = 0; step < 3; ++step)
        last[threads - 1] = mj.step(runs[threads - 1], h).solver;
      if (threads == 2)
        {
          std::vector<Contact> contacts = mj.contacts();
          ASSERT_GT(contacts.size(), 4000u);
          const BodyState           state = BodyState::of(runs[1]);
          const FrictionlessProblem lcp(contacts, state, true);
          // The grains' edge cut: halves of about as many contacts, sharing no grain (the
          // walls, bodies 0 and the last, couple nothing in A'), a small separator.
          const std::vector<int> part = grain_bisection(contacts, state);
          ASSERT_EQ(part.size(), contacts.size());
          std::vector<int> side_of_body(runs[1].bodies.size(), -1), count(3, 0);
          const unsigned int upper_wall = runs[1].bodies.size() - 1;
          for (std::size_t i = 0; i < contacts.size(); ++i)
            {
              ++count[part[i]];
              if (part[i] == 2)
                continue;
              for (const unsigned int b : contacts[i].body)
                if (b != 0 && b != upper_wall)
                  {
                    EXPECT_NE(side_of_body[b], 1 - part[i]) << "body " << b;
                    side_of_body[b] = part[i];
                  }
            }
          EXPECT_LT(std::abs(count[0] - count[1]), 0.05 * contacts.size());
          EXPECT_LT(count[2], 0.02 * contacts.size());
          EXPECT_TRUE(BisectedCholesky(lcp.scaled().A, part).split());
          // One thread's order: 2100 grains dissected into 8 parts (3 levels of cuts). The
          // contacts inside parts join the grains into at least 8 groups of at most a part's
          // grains (METIS balances to a few per cent), and the cuts are few.
          const std::vector<int> level = grain_dissection(contacts, state);
          ASSERT_EQ(level.size(), contacts.size());
          EXPECT_EQ(*std::max_element(level.begin(), level.end()), 3);
          std::vector<unsigned int> group(runs[1].bodies.size());
          std::iota(group.begin(), group.end(), 0U);
          auto root = [&](unsigned int b) {
            while (group[b] != b)
              b = group[b] = group[group[b]];
            return b;
          };
          std::size_t across = 0;
          for (std::size_t i = 0; i < contacts.size(); ++i)
            {
              const unsigned int a = contacts[i].body[0], b = contacts[i].body[1];
              if (level[i] > 0)
                ++across;
              else if (a != 0 && a != upper_wall && b != 0 && b != upper_wall)
                group[root(a)] = root(b);
            }
          std::map<unsigned int, int> size;
          for (unsigned int b = 1; b < upper_wall; ++b)
            ++size[root(b)];
          int largest = 0;
          for (const auto &[r, count_r] : size)
            largest = std::max(largest, count_r);
          EXPECT_GE(size.size(), 8u);
          EXPECT_LE(largest, 1.1 * (upper_wall - 1) / 8);
          EXPECT_LT(across, 0.05 * contacts.size());
        }
    }
  double difference = 0, scale = 0;
  for (std::size_t b = 0; b < s.bodies.size(); ++b)
    {
      difference = std::max(difference, (runs[0].bodies[b].velocity - runs[1].bodies[b].velocity).norm());
      scale      = std::max(scale, runs[0].bodies[b].velocity.norm());
    }
  EXPECT_LT(difference, 1e-6 * scale);
  for (const SolveReport &r : last)
    {
      EXPECT_TRUE(r.converged);
      EXPECT_LT(r.law_residual, 1e-8);
    }
}

TEST(ContactSolvers, AStepAboveTheGapTargetIsNotConverged)
{
  // A heavy upper wall (10^4 times its mass) lands at 10 m/s on the stack: stopping it takes
  // impulses that inflate the mean loaded impulse, so a law residual of 1e-3 relative to it
  // still lets grains close on each other (the gap violation theta h max(0, -(u_n + b))).
  // Above Solver/Gap target such a step is not converged; the converged solve stays below,
  // and so do APGS, APGD and MPRGP, which solve to the gap target as well.
  auto run = [](SolverParameters prm, std::vector<SolveReport> &reports) {
    ParticleSystem s     = hexagonal_stack(0, 0);
    RigidBody     &upper = s.bodies.back();
    upper.mass *= 1e4;
    upper.velocity = {0, -10};
    prm.gap_target = 1e-3 * radius;
    MoreauJean mj(0.5, ContactLaw{}, prm, 0.1 * radius);
    for (int i = 0; i < 20; ++i)
      reports.push_back(mj.step(s, h).solver);
  };
  // APGS told to stop at a gap tolerance of a whole radius, far above the target.
  SolverParameters apgs;
  apgs.method          = SolverParameters::Method::apgs;
  apgs.residual_target = 1e-3;
  SolverParameters loose_gaps = apgs;
  loose_gaps.gap_tolerance    = radius;
  std::vector<SolveReport> loose;
  run(loose_gaps, loose);
  unsigned int exceeded = 0;
  for (const auto &r : loose)
    {
      EXPECT_LE(r.law_residual, 1.5e-3); // the relative residual is met, ...
      EXPECT_EQ(r.gap_exceeded, r.gap_violation > 1e-3 * radius);
      EXPECT_EQ(r.converged, !r.gap_exceeded); // ... the step is not converged when the gaps are not
      exceeded += r.gap_exceeded ? 1 : 0;
    }
  EXPECT_GT(exceeded, 0u);
  SolverParameters interior_point;
  interior_point.method           = SolverParameters::Method::interior_point;
  interior_point.residual_target  = 1e-8;
  interior_point.predictor_sweeps = 0;
  SolverParameters apgd = apgs, mprgp = apgs;
  apgd.method           = SolverParameters::Method::apgd;
  mprgp.method          = SolverParameters::Method::mprgp;
  for (const SolverParameters &prm : {interior_point, apgs, apgd, mprgp})
    {
      std::vector<SolveReport> solved;
      run(prm, solved);
      for (const auto &r : solved)
        {
          EXPECT_FALSE(r.gap_exceeded) << method_name(prm.method);
          if (prm.method != SolverParameters::Method::interior_point) // it may stop short of 1e-8
            {
              EXPECT_TRUE(r.converged) << method_name(prm.method);
            }
          EXPECT_LT(r.gap_violation, 1e-3 * radius) << method_name(prm.method);
        }
    }
}

TEST(ContactSolvers, AGlobalMethodsStepAboveItsResidualTargetIsNotConverged)
{
  // A global method whose own test says converged (here one that leaves the warm start as
  // it is) while the law residual of its answer is above its residual target: the step is
  // reported not converged, with that residual. The same step solved by APGS is converged.
  class SaysConverged : public ContactSolver
  {
  public:
    using ContactSolver::ContactSolver;
    SolveReport solve(std::vector<Contact> &, BodyState &, const ContactLaw &, double) override
    {
      SolveReport report;
      report.converged = true;
      return report;
    }
    bool        solves_friction() const override { return true; }
    std::string random_state() const override { return ""; }
    void        set_random_state(const std::string &) override {}
  };
  SolverParameters apgs;
  apgs.method          = SolverParameters::Method::apgs;
  apgs.residual_target = 1e-3;
  for (const bool solved : {false, true})
    {
      ParticleSystem s = hexagonal_stack(100, 0);
      MoreauJean     mj(0.5, ContactLaw{}, apgs, 0.1 * radius);
      if (!solved)
        mj.use_solver(std::make_unique<SaysConverged>(apgs));
      const StepReport report = mj.step(s, h);
      ASSERT_GT(report.n_contacts, 10u);
      EXPECT_EQ(report.solver.converged, solved);
      if (solved)
        {
          EXPECT_LE(report.solver.law_residual, 1e-3);
        }
      else
        {
          EXPECT_GT(report.solver.law_residual, 1e-2);
        }
    }
}

TEST(ContactSolvers, ApgsWithAGapToleranceKeepsEveryStepsGapBelowIt)
{
  // The landing of AStepAboveTheGapTargetIsNotConverged, where APGS at a law residual of 1e-3
  // alone leaves steps above a gap violation of 1e-3 r: with Solver/Gap tolerance = 1e-3 r it
  // sweeps on until every contact's gap violation theta h max(0, -(u_n + b)) is below that,
  // so every step converges and the overlaps stop growing through the loose solve.
  ParticleSystem s     = hexagonal_stack(0, 0);
  RigidBody     &upper = s.bodies.back();
  upper.mass *= 1e4;
  upper.velocity = {0, -10};
  SolverParameters apgs;
  apgs.method          = SolverParameters::Method::apgs;
  apgs.residual_target = 1e-3;
  apgs.gap_target      = 1e-3 * radius;
  apgs.gap_tolerance   = 1e-3 * radius;
  MoreauJean mj(0.5, ContactLaw{}, apgs, 0.1 * radius);
  for (int i = 0; i < 20; ++i)
    {
      const SolveReport r = mj.step(s, h).solver;
      EXPECT_TRUE(r.converged) << "step " << i;
      EXPECT_LE(r.gap_violation, 1e-3 * radius * (1 + 1e-6)) << "step " << i;
      EXPECT_LE(r.law_residual, 1e-3) << "step " << i;
    }
}
