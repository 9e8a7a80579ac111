// Moreau-Jean stepping against closed-form mechanics.
#include "core/errors.h"
#include "dem/engine/moreau_jean.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

using namespace tribo::dem;

namespace
{
  const double rho = 7800, r = 0.6e-6;

  /// NLGS at a tight tolerance, checked every sweep.
  SolverParameters tight()
  {
    SolverParameters p;
    p.method         = SolverParameters::Method::nlgs;
    p.tolerance      = 1e-6;
    p.check_interval = 1;
    return p;
  }

  /// Two equal discs approaching head-on at relative speed v from gap g0.
  ParticleSystem pair(double v, double g0)
  {
    ParticleSystem s;
    s.add_disc({0, 0}, r, rho);
    s.add_disc({2 * r + g0, 0}, r, rho);
    s.bodies[0].velocity = {0.5 * v, 0};
    s.bodies[1].velocity = {-0.5 * v, 0};
    return s;
  }

  double m_eff(const ParticleSystem &s) { return 0.5 * s.bodies[0].mass; }
} // namespace

TEST(Dynamics, DiscOnAFixedWallCarriesTheAppliedForceAfterOneStep)
{
  ParticleSystem s;
  const unsigned wall = s.add_clump({{-1e-6, 0}, {0, 0}, {1e-6, 0}}, {0.5e-6, 0.5e-6, 0.5e-6}, rho);
  for (auto &d : s.bodies[wall].drive)
    d = Drive::velocity;
  const unsigned disc = s.add_disc({0, 0.5e-6 + r}, r, rho); // touching, gap 0
  const double   F    = -120.0;                               // N/m, pushing down
  s.bodies[disc].drive[1] = Drive::force;
  s.bodies[disc].load[1]  = F;
  MoreauJean mj(0.5, ContactLaw{}, tight(), 1e-8);
  const auto report = mj.step(s, 1e-8);
  EXPECT_TRUE(report.solver.converged);
  EXPECT_NEAR(mj.contact_force()[disc].y(), -F, 1e-9 * std::abs(F));
  EXPECT_NEAR(mj.contact_force()[wall].y(), F, 1e-9 * std::abs(F));
  // At rest: the free velocity h F/m (~1e2 m/s) is cancelled to round-off.
  EXPECT_NEAR(s.bodies[disc].velocity.norm(), 0.0, 1e-13 * 1e-8 * std::abs(F) / s.bodies[disc].mass);
}

TEST(Dynamics, CheckPassMeasuresTheStateAndAppliesNothing)
{
  // One contact: the first sweep's local solve is exact, so the check pass after it
  // (check interval 1) finds nothing left to change and the solver stops there. A check
  // that measured the sweep's own change instead would see the whole impulse move and
  // need a second sweep. The pass applies nothing: the velocities are the sweep's.
  ParticleSystem s = pair(2.0, 1e-9);
  MoreauJean     mj(0.5, ContactLaw{}, tight(), 1e-8);
  const auto     rep = mj.step(s, 1e-9).solver; // closes the 1e-9 m gap at 2 m/s
  EXPECT_TRUE(rep.converged);
  EXPECT_EQ(rep.iterations, 1u);
  EXPECT_EQ(rep.check_passes, 1u);
  EXPECT_EQ(rep.residual, 0.0);
  ASSERT_EQ(mj.contacts().size(), 1u);
  EXPECT_GT(mj.contacts()[0].r.x(), 0.0);
}

TEST(Dynamics, IqsHeadOnCollisionConservesMomentumAndStopsTheApproach)
{
  ParticleSystem s = pair(2.0, 1e-9);
  s.bodies[1].mass *= 3; // unequal masses
  const Vec2 p0 = s.bodies[0].mass * s.bodies[0].velocity + s.bodies[1].mass * s.bodies[1].velocity;
  MoreauJean mj(0.5, ContactLaw{}, tight(), 1e-8);
  for (int i = 0; i < 20; ++i)
    mj.step(s, 1e-10);
  const Vec2 p1 = s.bodies[0].mass * s.bodies[0].velocity + s.bodies[1].mass * s.bodies[1].velocity;
  EXPECT_LT((p1 - p0).norm(), 1e-14 * p0.norm());
  EXPECT_NEAR(s.bodies[1].velocity.x() - s.bodies[0].velocity.x(), 0.0, 1e-12);
  // The gap closed; the only overlap is the scheme's explicit half step with the
  // velocity before the impact, bounded by (1 - theta) h v.
  const double gap = (s.bodies[1].position - s.bodies[0].position).norm() - 2 * r;
  EXPECT_GE(gap, -(1 - 0.5) * 1e-10 * 2.0 * (1 + 1e-9));
  EXPECT_LT(gap, 1e-15);
}

// Two discs closing at 10 m/s with a detection distance of 1e-9 m and h = 1e-8 s: at the
// first step's predicted configuration their gap g = 3e-8 m is far beyond the distance, but
// less than the implicit half step's theta h v = 5e-8 m. Detected by their motion, IQS
// closes the gap exactly at the end of that step, leaving them approaching at g / (theta h)
// = 6 m/s; the next explicit half step carries them (1 - theta) h 6 m/s = 3e-8 m into each
// other, and IQS keeps that overlap. Found by the distance alone, they would pass into each
// other undetected and the next step would find them h v - g = 7e-8 m deep.
TEST(Dynamics, AFastPairIsDetectedBeforeItCloses)
{
  const double   v = 10, h = 1e-8, g = 3e-8;
  ParticleSystem s = pair(v, g + 0.5 * h * v);
  MoreauJean     mj(0.5, ContactLaw{}, tight(), 1e-9);
  auto           gap = [&] { return (s.bodies[1].position - s.bodies[0].position).norm() - 2 * r; };
  mj.step(s, h);
  ASSERT_EQ(mj.contacts().size(), 1u);
  EXPECT_NEAR(mj.contacts()[0].gap, g, 1e-20);
  EXPECT_GT(mj.contacts()[0].r.x(), 0.0);
  EXPECT_NEAR(gap(), 0.0, 1e-20);
  EXPECT_NEAR(s.bodies[0].velocity.x() - s.bodies[1].velocity.x(), g / (0.5 * h), 1e-9);
  for (int i = 0; i < 3; ++i)
    mj.step(s, h);
  EXPECT_NEAR(gap(), -0.5 * h * g / (0.5 * h), 1e-20);
  EXPECT_NEAR(s.bodies[1].velocity.x() - s.bodies[0].velocity.x(), 0.0, 1e-9);
}

TEST(Dynamics, ElasContactLastsPiSqrtMOverK)
{
  ContactLaw law;
  law.type      = ContactLaw::Type::elas;
  law.stiffness = 1e10;
  ParticleSystem s      = pair(1.0, 1e-10);
  const double   dtstar = std::sqrt(m_eff(s) / law.stiffness);
  const double   h      = dtstar / 2000;
  MoreauJean     mj(0.5, law, tight(), 1e-10);
  unsigned long  steps_in_contact = 0;
  for (int i = 0; i < 20000; ++i)
    {
      const auto rep = mj.step(s, h);
      if (rep.n_active > 0)
        ++steps_in_contact;
    }
  const double duration = steps_in_contact * h;
  EXPECT_NEAR(duration / (M_PI * dtstar), 1.0, 0.01);
  // Rebound: the relative velocity is reversed (elastic), up to the scheme's dissipation.
  const double v_out = s.bodies[1].velocity.x() - s.bodies[0].velocity.x();
  EXPECT_NEAR(v_out, 1.0, 0.01);
}

namespace
{
  /// Start two discs in contact (gap 0), separating at v; true if they escape
  /// the cohesion range within ample time.
  bool separates(ContactLaw::Type type, double v_over_escape)
  {
    ContactLaw law;
    law.type           = type;
    law.stiffness      = 1e10;
    law.cohesion       = 1.0;   // N/m
    law.cohesion_range = 1e-9;  // m
    ParticleSystem s   = pair(-1.0, 0.0);
    const double   v_esc = std::sqrt(2 * law.cohesion * law.cohesion_range / m_eff(s));
    const double   v     = v_over_escape * v_esc;
    s.bodies[0].velocity = {-0.5 * v, 0};
    s.bodies[1].velocity = {0.5 * v, 0};
    const double h  = 1e-3 * law.cohesion_range / v_esc;
    MoreauJean   mj(0.5, law, tight(), 2e-9);
    for (int i = 0; i < 20000; ++i)
      mj.step(s, h);
    const double gap = (s.bodies[1].position - s.bodies[0].position).norm() - 2 * r;
    return gap > law.cohesion_range;
  }
} // namespace

TEST(Dynamics, CohesivePairEscapesOnlyAboveTheEscapeVelocity)
{
  for (const auto type : {ContactLaw::Type::iqs, ContactLaw::Type::elas})
    {
      EXPECT_FALSE(separates(type, 0.95)) << "law " << int(type);
      EXPECT_TRUE(separates(type, 1.05)) << "law " << int(type);
    }
}

namespace
{
  /// 16 discs between a sliding fixed-height wall (1 m/s) and a wall pushed down by 800 N/m.
  ParticleSystem squeezed_layer()
  {
    ParticleSystem s;
    s.period = 8e-6;
    std::vector<Vec2>   c;
    std::vector<double> rad;
    for (int i = 0; i < 8; ++i)
      {
        c.push_back({(i + 0.5) * 1e-6, 0});
        rad.push_back(0.5e-6);
      }
    const unsigned lower = s.add_clump(c, rad, rho);
    for (auto &d : s.bodies[lower].drive)
      d = Drive::velocity;
    s.bodies[lower].velocity = {1.0, 0}; // sliding
    for (int i = 0; i < 16; ++i)
      s.add_disc({(i % 8 + 0.5 + 0.3 * (i / 8)) * 1e-6, (1.05 + 1.1 * (i / 8)) * 1e-6}, 0.5e-6, rho);
    for (auto &p : c)
      p.y() = 3.4e-6;
    const unsigned upper = s.add_clump(c, rad, rho);
    s.bodies[upper].drive = {{Drive::velocity, Drive::force, Drive::velocity}};
    s.bodies[upper].load[1] = -800.0;
    return s;
  }
} // namespace

TEST(Dynamics, KineticEnergyChangeEqualsThePowerOfDriversAndContacts)
{
  // Every step, KE_after - KE_before = h (P_external + P_contacts) (midpoint velocities).
  ParticleSystem s = squeezed_layer();
  MoreauJean mj(0.5, ContactLaw{}, tight(), 5e-8);
  double dissipated = 0;
  for (int i = 0; i < 300; ++i)
    {
      const double ke0 = s.kinetic_energy();
      const auto   rep = mj.step(s, 1e-9);
      const double dke = rep.kinetic_energy - ke0;
      const double rhs = 1e-9 * (rep.power_external + rep.power_contacts);
      EXPECT_NEAR(dke, rhs, 1e-9 * (std::abs(dke) + std::abs(rhs)) + 1e-25) << "step " << i;
      dissipated -= 1e-9 * rep.power_contacts;
    }
  // Frictionless IQS contacts dissipate over the run (a single step may not:
  // with midpoint velocities, a contact whose normal turned can give back a little).
  EXPECT_GT(dissipated, 0.0);
}

TEST(Dynamics, NlgsSolutionSatisfiesSignorini)
{
  // A tight Quad tolerance measures the impulse changes W_aa dr; in a hyperstatic
  // packing the impulses need not converge where the velocities have (a loop of
  // contacts through the imposed-velocity wall), so a few steps may reach the sweep
  // cap. The velocities must satisfy Signorini either way.
  ParticleSystem s = squeezed_layer();
  SolverParameters prm = tight();
  prm.max_iterations = 20000;
  MoreauJean     mj(0.5, ContactLaw{}, prm, 5e-8);
  const double   h = 1e-9;
  unsigned capped = 0;
  for (int i = 0; i < 200; ++i)
    {
      const auto rep = mj.step(s, h).solver;
      capped += rep.converged ? 0 : 1;
      EXPECT_LT(rep.residual, 1e-5) << "step " << i;
    }
  EXPECT_LT(capped, 20u);
  // Recompute every contact's final local velocity from the bodies: with r_n > 0
  // the end-of-step gap is closed (u_n = -shift), with r_n = 0 it stays open.
  const BodyState state = BodyState::of(s);
  // The tolerance is relative to W r, about 33 m/s here (r = 1e-7 N s/m on a 6e-9 kg/m
  // disc): 1e-6 of it is 3.3e-5 m/s. The Quad norm is a mean square over the contacts,
  // so the loaded contacts' mean square violation is held to 3 times that and the worst
  // one to 30 times.
  unsigned loaded = 0;
  double   sum_square = 0, worst = 0;
  for (const auto &c : mj.contacts())
    {
      const double un = state.local_velocity(c).x();
      EXPECT_GE(c.r.x(), 0.0);
      EXPECT_GE(un + c.shift, -1e-3);
      if (c.r.x() > 0)
        {
          ++loaded;
          sum_square += (un + c.shift) * (un + c.shift);
          worst = std::max(worst, std::abs(un + c.shift));
        }
    }
  EXPECT_LT(std::sqrt(sum_square / loaded), 1e-4);
  EXPECT_LT(worst, 1e-3);
  EXPECT_GT(loaded, 10u);
}

namespace
{
  /// The RunError message of one step, or "" if the step is taken.
  std::string step_error(MoreauJean &mj, ParticleSystem &s, double h)
  {
    try
      {
        mj.step(s, h);
      }
    catch (const tribo::RunError &e)
      {
        return e.what();
      }
    return "";
  }

  /// Two discs of radius r, the second at @p distance along x moving at @p vx.
  ParticleSystem pair_at(double distance, double vx)
  {
    ParticleSystem s;
    s.add_disc({0, 0}, r, rho);
    s.add_disc({distance, 0}, r, rho);
    s.bodies[1].velocity = {vx, 0};
    return s;
  }
} // namespace

TEST(Dynamics, AnOverlapDeeperThanTheSmallestRadiusStopsTheRun)
{
  // Discs placed overlapping by 0.7 um (> r = 0.6 um), at rest: IQS freezes the overlap.
  // The message names the entries to change in the subsections the law and the solver
  // were read from.
  ParticleSystem   placed = pair_at(2 * r - 0.7e-6, 0);
  ContactLaw       law;
  SolverParameters solver = tight();
  law.section             = {"Contact law"};
  solver.section          = {"Solver"};
  // The message for a step solved by @p method, whose accuracy entries are @p advice.
  auto placed_overlap = [](const std::string &method, const std::string &advice) {
    return "an overlap of 7e-07 m, more than the smallest disc radius (6e-07 m): contacts were "
           "missed or left unresolved (" + method + " converged). The deepest contact, between body 0 "
           "and body 1, overlapped by 7e-07 m at the step's start and closed by 0 m in the step: the "
           "overlap does not come from the step size. "
           "Either discs were placed overlapping, or the law lets it grow: with IQS, overlaps "
           "kept step after step within the solver's tolerance (high pressure: tighten " + advice +
           ", or set Contact law/Overlap recovery); with ELAS, a stiffness too low for the load "
           "(docs/laws.md)";
  };
  MoreauJean mj(0.5, law, solver, 1e-8);
  EXPECT_EQ(step_error(mj, placed, 1e-8), placed_overlap("nlgs", "Solver/Tolerance or Solver/Gap tolerance"));
  // Solved by APGD, the advice names its accuracy entry instead of NLGS's.
  solver.method = SolverParameters::Method::apgd;
  MoreauJean by_apgd(0.5, law, solver, 1e-8);
  EXPECT_EQ(step_error(by_apgd, placed, 1e-8), placed_overlap("apgd", "Solver/Residual target"));
  // APGS also reads the gap tolerance (dem/solvers/apgs.h).
  solver.method = SolverParameters::Method::apgs;
  MoreauJean by_apgs(0.5, law, solver, 1e-8);
  EXPECT_EQ(step_error(by_apgs, placed, 1e-8),
            placed_overlap("apgs", "Solver/Residual target or Solver/Gap tolerance"));
  // Closing at 200 m/s from a gap of 0.1 um in steps of 1e-8 s (2 um per step): the
  // pair is detected and stopped, but the explicit half step (1 - theta) h v carries it
  // 1 um into the overlap.
  // (Without retakes: with them the step is taken again, below.)
  ParticleSystem fast = pair_at(2 * r + 1e-7, -200);
  MoreauJean     mj2(0.5, ContactLaw{}, tight(), 1e-6);
  mj2.allow_retakes(1);
  EXPECT_EQ(step_error(mj2, fast, 1e-8),
            "an overlap of 9e-07 m, more than the smallest disc radius (6e-07 m): contacts were "
            "missed or left unresolved (nlgs converged). The farthest mover, body 1, moved 1.5e-06 m "
            "in the step (200 m/s at its start, 100 at its end); a step of at most 7.5e-10 s keeps it "
            "within a quarter of the smallest radius");
  // Overlapping by 0.95 r and closing at 12 m/s: the explicit half step carries the pair 0.1 r
  // deeper, IQS stops it there. The step made 0.1 r of the 1.05 r: the message names the
  // contact's overlap at the step's start, not a step size (which would not have helped).
  ParticleSystem deep = pair_at(2 * r - 0.95 * r, -12);
  MoreauJean     mj4(0.5, ContactLaw{}, tight(), 1e-6);
  const std::string deep_error = step_error(mj4, deep, 1e-8);
  EXPECT_EQ(deep_error.substr(0, deep_error.find(": the overlap does not come")),
            "an overlap of 6.3e-07 m, more than the smallest disc radius (6e-07 m): contacts were "
            "missed or left unresolved (nlgs converged). The deepest contact, between body 0 and "
            "body 1, overlapped by 5.7e-07 m at the step's start and closed by 6e-08 m in the step");
  // With sub-steps allowed, the same step is taken as ceil(h v / (r / 4)) = 14 sub-steps of
  // h / 14: the pair meets within one of them and IQS stops it there (a perfectly inelastic
  // impact: both discs at -100 m/s). The merged report and forces describe the whole step:
  // its energy book closes with the powers' means, and each disc's contact force times h is
  // its change of momentum.
  ParticleSystem substepped = pair_at(2 * r + 1e-7, -200);
  MoreauJean     mj5(0.5, ContactLaw{}, tight(), 1e-6);
  mj5.allow_substeps(16);
  const double     mass = substepped.bodies[1].mass, energy_before = substepped.kinetic_energy();
  const StepReport report = mj5.step(substepped, 1e-8);
  EXPECT_EQ(report.substeps, 14u);
  EXPECT_NEAR(mj5.step_length(), 1e-8 / 14, 1e-24);
  EXPECT_NEAR(substepped.bodies[0].velocity.x(), -100, 1e-9);
  EXPECT_NEAR(substepped.bodies[1].velocity.x(), -100, 1e-9);
  EXPECT_LT(report.max_overlap, 0.25 * r);
  EXPECT_NEAR(substepped.kinetic_energy() - energy_before, 1e-8 * (report.power_external + report.power_contacts),
              1e-9 * energy_before);
  EXPECT_LT(report.power_contacts, 0); // the impact dissipates half the kinetic energy
  EXPECT_NEAR(1e-8 * report.power_contacts, -0.5 * energy_before, 1e-9 * energy_before);
  EXPECT_NEAR(mj5.contact_force()[1].x() * 1e-8, mass * 100, 1e-9 * mass * 100);
  EXPECT_NEAR(mj5.contact_force()[0].x() * 1e-8, -mass * 100, 1e-9 * mass * 100);
  // By default the step that stopped mj2 is taken again from its start: the farthest mover's
  // larger speed, 200 m/s, asks for ceil(h v / (r / 4)) = 14 sub-steps, and the retake ends
  // as the sub-stepped step above, to the bit: the first attempt left nothing behind (the
  // bodies' state restored).
  ParticleSystem retaken = pair_at(2 * r + 1e-7, -200);
  MoreauJean     mj6(0.5, ContactLaw{}, tight(), 1e-6);
  const StepReport again = mj6.step(retaken, 1e-8);
  EXPECT_TRUE(again.retaken);
  EXPECT_FALSE(report.retaken);
  EXPECT_EQ(again.substeps, 14u);
  for (int b = 0; b < 2; ++b)
    {
      EXPECT_EQ(retaken.bodies[b].position, substepped.bodies[b].position);
      EXPECT_EQ(retaken.bodies[b].velocity, substepped.bodies[b].velocity);
      EXPECT_EQ(mj6.contact_force()[b], mj5.contact_force()[b]);
    }
  EXPECT_EQ(again.power_contacts, report.power_contacts);
  EXPECT_EQ(mj6.retake_reason(), "body 1 moved 2.5 r_min (200 m/s) and left an overlap of 1.5 r_min");
  // A grain the step launches from rest, farther than its contact detection foresaw: disc 1
  // strikes disc 0 at 100 m/s (the pair seen by disc 1's motion), which leaves at 50 m/s and
  // is carried theta h 50 = 2.5e-7 m into disc 2, 5e-8 m beyond it (farther than the
  // detection distance of 1e-8 m, and disc 0 was at rest). Without retakes the step stands
  // and leaves that pair 2e-7 m (0.33 r) deep, unseen until the next step, whose IQS keeps
  // it; with them the step is taken again in ceil(h 50 / (r / 4)) = 4 sub-steps, disc 2 is met
  // within one (0.125 r deep: two half sub-steps at 50 m/s), and the impacts pass the
  // momentum along the row.
  const auto row = [] {
    ParticleSystem s = pair_at(2 * r + 1e-7, -100);
    s.add_disc({-2 * r - 5e-8, 0}, r, rho);
    return s;
  };
  const auto overlap_02 = [](const ParticleSystem &s) {
    return 2 * r - (s.bodies[0].position - s.bodies[2].position).norm();
  };
  ParticleSystem unseen = row(), seen = row();
  MoreauJean     without(0.5, ContactLaw{}, tight(), 1e-8), with(0.5, ContactLaw{}, tight(), 1e-8);
  without.allow_retakes(1);
  EXPECT_FALSE(without.step(unseen, 1e-8).retaken);
  EXPECT_NEAR(overlap_02(unseen), 2.5e-7 - 5e-8, 1e-12);
  const StepReport foreseen = with.step(seen, 1e-8);
  EXPECT_TRUE(foreseen.retaken);
  EXPECT_EQ(foreseen.substeps, 4u);
  EXPECT_EQ(with.retake_reason(), "body 0 moved 0.416667 r_min farther than its contact detection foresaw (50 m/s)");
  EXPECT_LT(overlap_02(seen), 0.13 * r);
  EXPECT_NEAR(seen.bodies[0].velocity.x() + seen.bodies[1].velocity.x() + seen.bodies[2].velocity.x(), -100, 1e-9);
  // At 20 m/s the same pair ends each step with an overlap of at most (1 - theta) h v.
  ParticleSystem slow = pair_at(2 * r + 1e-7, -20);
  MoreauJean     mj3(0.5, ContactLaw{}, tight(), 1e-6);
  for (int i = 0; i < 5; ++i)
    EXPECT_EQ(step_error(mj3, slow, 1e-8), "");
}
