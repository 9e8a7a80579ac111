// The contact solve across MPI ranks (dem/parallel/): run by ctest on 1, 2, 3 and 4 ranks
// (tests/unit/CMakeLists.txt). Every assertion follows the collective calls, so that a
// failure on one rank cannot leave the others waiting.
#include "dem/parallel/distributed_apgs.h"
#include "dem/parallel/distributed_gauss_seidel.h"
#include "dem/parallel/band_split.h"
#include "dem/parallel/solve_across_ranks.h"
#include "dem/laws/law_residual.h"
#include "dem/solvers/nlgs.h"
#include "tests/unit/lumped_chain.h"
#include "tests/unit/ranks.h"
#include "tests/unit/tall_layer.h"
#include "core/checkpoint.h"

#include <boost/archive/binary_iarchive.hpp>
#include <boost/archive/binary_oarchive.hpp>

#include <deal.II/base/mpi.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <map>
#include <cmath>
#include <numeric>
#include <vector>

using namespace tribo::dem;
using namespace tribo::dem::parallel;
using namespace tribo::dem::test;

namespace
{
  /// The velocities of every body of the serial numbering after a distributed solve: each
  /// grain's from its owner, the replicated bodies' from rank 0 (summed over the ranks,
  /// each body written by exactly one).
  std::vector<Eigen::Vector3d> gathered_velocities(const RankProblem &p, std::size_t n_bodies)
  {
    std::vector<double> v(3 * n_bodies, 0.0);
    for (unsigned int l = 0; l < p.serial_body.size(); ++l)
      if (l < p.n_owned || (l >= p.n_owned + p.n_ghost && my_rank() == 0))
        for (unsigned int k = 0; k < 3; ++k)
          v[3 * p.serial_body[l] + k] = p.state.velocity[l][k];
    const std::vector<double> sum = summed(v);
    std::vector<Eigen::Vector3d> out(n_bodies);
    for (std::size_t b = 0; b < n_bodies; ++b)
      out[b] = {sum[3 * b], sum[3 * b + 1], sum[3 * b + 2]};
    return out;
  }

  /// The impulse (x, y) the contacts put on body @p body, summed
  /// over every rank's contacts, N s/m.
  Eigen::Vector2d impulse_on(const std::vector<Contact> &contacts, const std::vector<unsigned int> &local_to_serial,
                             unsigned int body, bool distributed)
  {
    double f[2] = {0, 0};
    for (const Contact &c : contacts)
      for (int s = 0; s < 2; ++s)
        if (local_to_serial[c.body[s]] == body)
          {
            const Vec2 t(-c.normal.y(), c.normal.x());
            const Vec2 on = (s == 0 ? -1.0 : 1.0) * (c.r.x() * c.normal + c.r.y() * t);
            f[0] += on.x();
            f[1] += on.y();
          }
    if (!distributed)
      return {f[0], f[1]};
    double total[2];
    dealii::Utilities::MPI::sum(f, world(), total);
    return {total[0], total[1]};
  }

  std::vector<unsigned int> identity(std::size_t n)
  {
    std::vector<unsigned int> i(n);
    std::iota(i.begin(), i.end(), 0u);
    return i;
  }

  /// The serial reference: NLGS to a tight tolerance.
  struct SerialReference
  {
    std::vector<Contact> contacts;
    BodyState            state;
    SolveReport          report;
    SerialReference(const ColdStart &cold, double tolerance)
      : contacts(cold.contacts)
      , state(BodyState::of(cold.system))
    {
      SolverParameters prm;
      prm.method         = SolverParameters::Method::nlgs;
      prm.tolerance      = tolerance;
      prm.max_iterations = 200000;
      report             = NlgsSolver(prm).solve(contacts, state, cold.law);
    }
  };
} // namespace

TEST(Distributed, BandsHoldEqualCountsAndEveryHeightHasOneBand)
{
  std::vector<double> y;
  for (int i = 0; i < 1000; ++i)
    y.push_back(std::sin(0.37 * i) * 1e-5); // distinct heights, not sorted
  for (unsigned int n = 1; n <= 7; ++n)
    {
      const BandPartition bands = BandPartition::balanced(y, n);
      ASSERT_EQ(bands.n_bands(), n);
      std::vector<unsigned int> count(n, 0);
      for (const double h : y)
        ++count[bands.band_of(h)];
      for (unsigned int k = 0; k < n; ++k)
        {
          EXPECT_GE(count[k], 1000 / n) << n << " bands, band " << k;
          EXPECT_LE(count[k], 1000 / n + 1) << n << " bands, band " << k;
          EXPECT_LT(bands.cut[k], bands.cut[k + 1]);
        }
      EXPECT_LE(bands.imbalance(y), double(1000 / n + 1) * n / 1000);
    }
  // All heights in one band of two: imbalance 2.
  const BandPartition halves = BandPartition::balanced(y, 2);
  EXPECT_DOUBLE_EQ(halves.imbalance(std::vector<double>(10, -1.0)), 2.0);
}

TEST(Distributed, EveryGrainAndContactHasExactlyOneOwner)
{
  const ColdStart     cold;
  const BandPartition bands = contact_bands(cold.system, cold.contacts, n_ranks());
  const RankProblem   p     = share_of(cold.system, cold.contacts, BodyState::of(cold.system), bands, my_rank());

  // Owned grains: one contiguous range of global numbers per rank, the ranges tiling
  // [0, n_grains) in rank order; owned contacts: each serial contact on exactly one rank.
  const std::size_t   n_bodies = cold.system.bodies.size();
  std::vector<double> owner_count(n_bodies, 0.0), contact_count(cold.contacts.size(), 0.0);
  for (unsigned int l = 0; l < p.n_owned; ++l)
    owner_count[p.serial_body[l]] += 1;
  for (const unsigned int i : p.serial_contact)
    contact_count[i] += 1;
  owner_count   = summed(owner_count);
  contact_count = summed(contact_count);
  const auto first = dealii::Utilities::MPI::all_gather(world(), p.n_owned ? p.global_grain[0] : p.n_grains);
  const auto sizes = dealii::Utilities::MPI::all_gather(world(), p.n_owned);

  const unsigned int n_grains = n_bodies - 2; // the two walls are clumps
  EXPECT_EQ(p.n_grains, n_grains);
  EXPECT_EQ(p.n_replicated(), 2u);
  for (std::size_t b = 0; b < n_bodies; ++b)
    EXPECT_EQ(owner_count[b], b == 0 || b == n_bodies - 1 ? 0.0 : 1.0) << "body " << b;
  for (std::size_t i = 0; i < contact_count.size(); ++i)
    EXPECT_EQ(contact_count[i], 1.0) << "contact " << i;
  std::uint64_t next = 0;
  for (unsigned int r = 0; r < n_ranks(); ++r)
    {
      if (sizes[r] > 0)
        {
          EXPECT_EQ(first[r], next) << "rank " << r;
        }
      next += sizes[r];
    }
  EXPECT_EQ(next, n_grains);
  for (unsigned int l = 1; l < p.n_owned; ++l)
    EXPECT_EQ(p.global_grain[l], p.global_grain[l - 1] + 1);
  // Every rank has work, and the bands hold equal contact counts as far as ties allow: a
  // row of the lattice puts its horizontal contacts at one height, which one band takes.
  EXPECT_GT(p.n_owned, 0u);
  std::map<double, unsigned int> at_height;
  unsigned int                   most_tied = 1;
  for (const Contact &c : cold.contacts)
    most_tied = std::max(most_tied, ++at_height[0.5 * (cold.system.disc_centre(c.disc[0]).y() +
                                                        cold.system.disc_centre(c.disc[1]).y())]);
  EXPECT_NEAR(double(p.contacts.size()), double(cold.contacts.size()) / n_ranks(), most_tied);
  // A ghost is a grain of another band that an owned contact touches.
  for (unsigned int l = p.n_owned; l < p.n_owned + p.n_ghost; ++l)
    EXPECT_EQ(owner_count[p.serial_body[l]], 1.0);
  if (n_ranks() == 1)
    {
      EXPECT_EQ(p.n_ghost, 0u);
    }
}

TEST(Distributed, OnOneRankTheSweepsAreTheSerialNlgsSweeps)
{
  // Without momentum, bit for bit: the same local solves in the same (detection) order.
  if (n_ranks() != 1)
    GTEST_SKIP() << "one rank only";
  const ColdStart      cold;
  std::vector<Contact> serial = cold.contacts;
  BodyState            state  = BodyState::of(cold.system);
  NlgsSolver(fixed_sweeps(37)).solve(serial, state, cold.law);

  RankProblem p = share_of(cold.system, cold.contacts, BodyState::of(cold.system),
                           contact_bands(cold.system, cold.contacts, 1), 0);
  DistributedControls controls;
  controls.residual_target = 0; // never met
  controls.momentum        = false;
  controls.max_sweeps      = 37;
  DistributedGaussSeidel(p, world()).solve(p, cold.law, controls);
  ASSERT_EQ(p.contacts.size(), serial.size());
  for (std::size_t i = 0; i < serial.size(); ++i)
    EXPECT_EQ(p.contacts[i].r, serial[p.serial_contact[i]].r) << "contact " << i;
  for (unsigned int l = 0; l < p.serial_body.size(); ++l)
    EXPECT_EQ(p.state.velocity[l], state.velocity[p.serial_body[l]]) << "body " << p.serial_body[l];
}

namespace
{
  /// The loaded upper wall, which lands on the layer: the last body of tall_layer().
  unsigned int upper_wall(const ColdStart &cold) { return static_cast<unsigned int>(cold.system.bodies.size()) - 1; }

  /// The distributed solves: Gauss-Seidel in velocity form, APGS's sweeps in operator form, and
  /// the plain Gauss-Seidel sweeps stopped by NLGS's test (Solver/Method = nlgs on N ranks).
  enum class Sweeps
  {
    gauss_seidel,
    apgs,
    nlgs
  };

  /// Solve @p cold's problem on @p comm's ranks (MPI_COMM_SELF: the serial solve) to
  /// @p target (with Sweeps::nlgs: NLGS's Tolerance, Quad); the report, this rank's problem,
  /// and the gathered velocities and upper wall's impulse.
  struct Distributed
  {
    DistributedReport            report;
    RankProblem                  p;
    std::vector<Eigen::Vector3d> velocity;
    Eigen::Vector2d              wall_impulse;
    Distributed(const ColdStart &cold, double target, MPI_Comm comm, bool momentum = true,
                Sweeps sweeps = Sweeps::gauss_seidel)
      : p(share_of(cold.system, cold.contacts, BodyState::of(cold.system),
                   contact_bands(cold.system, cold.contacts, dealii::Utilities::MPI::n_mpi_processes(comm)),
                   dealii::Utilities::MPI::this_mpi_process(comm)))
    {
      DistributedControls controls;
      controls.residual_target = target;
      controls.max_sweeps      = 100000;
      controls.momentum        = momentum;
      if (sweeps == Sweeps::nlgs)
        {
          controls.momentum       = false;
          controls.nlgs_stop      = true;
          controls.nlgs_tolerance = target;
        }
      report       = sweeps == Sweeps::apgs ? DistributedApgs(p, comm).solve(p, cold.law, controls)
                                                : DistributedGaussSeidel(p, comm).solve(p, cold.law, controls);
      wall_impulse = impulse_on(p.contacts, p.serial_body, upper_wall(cold), true);
      if (comm == world())
        velocity = gathered_velocities(p, cold.system.bodies.size());
    }
  };

  /// The distributed solve against the serial interior point (frictionless) or NLGS
  /// (friction) converged far below @p target: velocities and the upper wall's impulse.
  void expect_serial_answer(const ColdStart &cold, double target, double velocity_bound, double impulse_bound,
                            Sweeps sweeps = Sweeps::gauss_seidel)
  {
    SerialReference reference(cold, 1e-12);
    const Distributed     here(cold, target, world(), true, sweeps);
    const Distributed     one_rank(cold, target, MPI_COMM_SELF, true, sweeps);
    const Distributed     plain(cold, target, MPI_COMM_SELF, false, sweeps);
    EXPECT_TRUE(here.report.converged);
    EXPECT_LE(here.report.law_residual, target);
    double worst = 0;
    for (std::size_t b = 0; b < here.velocity.size(); ++b)
      worst = std::max(worst, (here.velocity[b] - reference.state.velocity[b]).head<2>().lpNorm<Eigen::Infinity>());
    EXPECT_LT(worst, velocity_bound);
    const Eigen::Vector2d serial_impulse = impulse_on(reference.contacts, identity(cold.system.bodies.size()), upper_wall(cold), false);
    EXPECT_LT((here.wall_impulse - serial_impulse).norm(), impulse_bound * serial_impulse.norm());
    // The coupling across ranks costs sweeps; how many is what docs/scaling.md reports.
    std::cout << "[ measure  ] " << (sweeps == Sweeps::apgs ? "APGS sweeps, " : "Gauss-Seidel, ") << n_ranks() << " ranks: " << here.report.sweeps << " sweeps (one rank "
              << one_rank.report.sweeps << ", without momentum " << plain.report.sweeps << "), law residual " << here.report.law_residual
              << ", worst velocity difference " << worst << " m/s, upper wall impulse " << here.wall_impulse.transpose()
              << " against serial " << serial_impulse.transpose() << " N s/m" << std::endl;
    EXPECT_LE(here.report.sweeps, 2 * plain.report.sweeps);
    // The counters: bands have one neighbour at the ends, two inside; every exchange sums the
    // walls' changes, every check two figures; nothing travels on one rank.
    const DistributedReport &r = here.report;
    EXPECT_EQ(r.neighbours, n_ranks() == 1 ? 0u : my_rank() == 0 || my_rank() + 1 == n_ranks() ? 1u : 2u);
    EXPECT_GE(r.exchanges, r.sweeps);
    EXPECT_EQ(r.bytes_sent == 0, n_ranks() == 1);
    const bool plain_sweeps = cold.law.friction > 0 && sweeps == Sweeps::gauss_seidel;
    if (plain_sweeps) // no restart sums
      {
        EXPECT_EQ(r.reductions, r.exchanges + 2 * r.checks);
      }
    if (sweeps == Sweeps::apgs) // one exchange per sweep, one more on a check with momentum,
      {                          // one at the end; the final check in velocity form
        EXPECT_EQ(r.exchanges, r.sweeps + r.checks - 1);
      }
    if (!plain_sweeps) // the momentum still pays across ranks
      {
        EXPECT_LT(here.report.sweeps, plain.report.sweeps);
      }
  }
} // namespace

TEST(Distributed, FrictionlessSolveGivesTheSerialVelocitiesAndWallForce)
{
  // Without friction the velocities and the walls' impulses of a step are unique
  // (docs/validation.md), so every rank count must give the serial ones.
  expect_serial_answer(ColdStart(), 1e-9, 1e-6, 1e-6);
}

TEST(Distributed, CoulombFrictionSolveGivesTheSerialAnswer)
{
  ContactLaw law;
  law.friction = 0.3;
  expect_serial_answer(ColdStart(law), 1e-9, 1e-6, 1e-6);
}

TEST(Distributed, ApgsSweepsGiveTheSerialVelocitiesAndWallForce)
{
  // APGS's operator-form sweeps, the other ranks' impulses in each rank's b': the same answer.
  expect_serial_answer(ColdStart(), 1e-9, 1e-6, 1e-6, Sweeps::apgs);
}

TEST(Distributed, ApgsSweepsWithCoulombFrictionGiveTheSerialAnswer)
{
  ContactLaw law;
  law.friction = 0.3;
  expect_serial_answer(ColdStart(law), 1e-9, 1e-6, 1e-6, Sweeps::apgs);
}

TEST(Distributed, NlgsStopsAsTheSerialNlgsAndGivesItsAnswerOnEveryRankCount)
{
  // Solver/Method = nlgs on N ranks: plain sweeps stopped by the established code's norm over
  // every rank's contacts. On one rank it is the serial NLGS, bit for bit, at its check and
  // stop; on more, its tight answer is the serial one.
  const ColdStart cold;
  for (const double tolerance : {1e-4, 1e-10})
    {
      SolverParameters prm;
      prm.method              = SolverParameters::Method::nlgs;
      prm.tolerance           = tolerance;
      prm.max_iterations      = 100000;
      std::vector<Contact> serial = cold.contacts;
      BodyState            state  = BodyState::of(cold.system);
      const SolveReport    nlgs   = NlgsSolver(prm).solve(serial, state, cold.law);
      ASSERT_TRUE(nlgs.converged);

      const Distributed alone(cold, tolerance, MPI_COMM_SELF, false, Sweeps::nlgs);
      EXPECT_TRUE(alone.report.converged);
      EXPECT_EQ(alone.report.sweeps, nlgs.iterations);
      EXPECT_EQ(alone.report.nlgs_residual, nlgs.residual);
      for (std::size_t i = 0; i < alone.p.contacts.size(); ++i)
        EXPECT_EQ(alone.p.contacts[i].r, serial[alone.p.serial_contact[i]].r) << "contact " << i;

      const Distributed here(cold, tolerance, world(), false, Sweeps::nlgs);
      EXPECT_TRUE(here.report.converged);
      EXPECT_LT(here.report.nlgs_residual, tolerance);
      // The coupling across ranks costs a few sweeps (docs/scaling.md).
      EXPECT_LE(here.report.sweeps, nlgs.iterations + nlgs.iterations / 2);
      if (tolerance < 1e-8)
        {
          double worst = 0;
          for (std::size_t b = 0; b < here.velocity.size(); ++b)
            worst = std::max(worst, (here.velocity[b] - state.velocity[b]).head<2>().lpNorm<Eigen::Infinity>());
          EXPECT_LT(worst, 1e-6) << n_ranks() << " ranks";
        }
      std::cout << "[ measure  ] NLGS's test, " << n_ranks() << " ranks, tolerance " << tolerance << ": "
                << here.report.sweeps << " sweeps (serial NLGS " << nlgs.iterations << ")" << std::endl;
    }
}

namespace
{
  /// MoreauJean with a BandSplit cutting its bands again past @p rebalance_at: each rank
  /// detects and solves only its band's contacts and advances only its band's grains (the
  /// state split, made whole for the comparison). Against the serial steps, both solved by
  /// APGS to 1e-10: every contact held by exactly one rank, the same bodies' velocities, the
  /// law residual over all ranks, the whole state the same bits on every rank, and a
  /// checkpoint's warm start holding every rank's loaded contacts. Returns how many times the
  /// bands were cut.
  unsigned long expect_split_steps_give_the_serial_steps(double rebalance_at)
  {
    const ColdStart  cold;
    SolverParameters prm;
    prm.method          = SolverParameters::Method::apgs;
    prm.residual_target = 1e-10;
    prm.max_iterations  = 200000;
    // 20 steps split (the bands cut and kept, the warm starts kept or gathered), then one
    // more from the same state split and serial: a trajectory's own round-off grows from step
    // to step where contacts open and close, so the two are compared over one step.
    ParticleSystem split_system = cold.system;
    MoreauJean     many(0.5, cold.law, prm, 5e-8);
    auto           split = std::make_shared<BandSplit>(world(), 3 * cold.system.max_radius() + 5e-8, rebalance_at);
    many.use_split(split);
    many.use_solver(std::make_unique<SolveAcrossRanks>(prm, split_system, split));
    unsigned int shares = 0;
    for (int i = 0; i < 20; ++i)
      {
        many.step(split_system, 1e-9);
        shares += split->holds_share();
      }
    many.make_whole(split_system);
    ParticleSystem serial = split_system;
    // A rank reads nothing of the grains it does not hold (their copies are stale in a run):
    // moved a metre up here, the split step must still be the serial one. A solve numbering
    // the grains band by band from every copy, not from the ownership, fails this on 3 and 4
    // ranks: its ghosts take other grains' velocities.
    if (split->held())
      for (std::size_t b = 0; b < split_system.bodies.size(); ++b)
        if (!split->holds(static_cast<unsigned int>(b)))
          split_system.bodies[b].position.y() += 1.0;
    MoreauJean       one(0.5, cold.law, prm, 5e-8);
    const StepReport serial_report = one.step(serial, 1e-9);
    const StepReport split_report  = many.step(split_system, 1e-9);
    many.make_whole(split_system);
    // Each contact on one rank: the keys of every rank's contacts, against the serial ones.
    std::vector<double> keys;
    for (const Contact &c : many.contacts())
      keys.push_back(double(c.key()));
    std::vector<double> all_keys;
    for (const auto &k : dealii::Utilities::MPI::all_gather(world(), keys))
      all_keys.insert(all_keys.end(), k.begin(), k.end());
    std::vector<double> serial_keys;
    for (const Contact &c : one.contacts())
      serial_keys.push_back(double(c.key()));
    std::sort(all_keys.begin(), all_keys.end());
    std::sort(serial_keys.begin(), serial_keys.end());
    // The same bits on every rank: the least and largest of each body's velocity.
    std::vector<double> v;
    for (const RigidBody &b : split_system.bodies)
      v.insert(v.end(), {b.velocity.x(), b.velocity.y(), b.spin, b.position.x(), b.position.y()});
    std::vector<double> least(v.size()), largest(v.size());
    dealii::Utilities::MPI::min(dealii::ArrayView<const double>(v), world(), dealii::ArrayView<double>(least));
    dealii::Utilities::MPI::max(dealii::ArrayView<const double>(v), world(), dealii::ArrayView<double>(largest));

    EXPECT_EQ(least, largest);
    EXPECT_EQ(all_keys, serial_keys);
    EXPECT_EQ(split_report.n_contacts, serial_report.n_contacts);
    EXPECT_EQ(split_report.n_contacts, serial_keys.size());
    // On 2-4 ranks every step in shares (the first one's bands from every pair).
    if (n_ranks() > 1)
      {
        EXPECT_EQ(shares, 20u);
      }
    EXPECT_TRUE(split_report.solver.law_assessed);
    EXPECT_TRUE(split_report.solver.converged);
    EXPECT_LE(split_report.solver.law_residual, prm.residual_target);
    double fastest = 0;
    for (const RigidBody &b : serial.bodies)
      fastest = std::max(fastest, b.velocity.norm());
    for (std::size_t b = 0; b < serial.bodies.size(); ++b)
      {
        EXPECT_NEAR(split_system.bodies[b].velocity.x(), serial.bodies[b].velocity.x(), 1e-6 * fastest) << b;
        EXPECT_NEAR(split_system.bodies[b].velocity.y(), serial.bodies[b].velocity.y(), 1e-6 * fastest) << b;
        EXPECT_NEAR(split_system.bodies[b].position.y(), serial.bodies[b].position.y(), 1e-9 * 1e-6 * fastest) << b;
      }
    EXPECT_NEAR(split_report.power_contacts, serial_report.power_contacts, 1e-6 * std::abs(serial_report.power_contacts));
    // Each contact's power at the mid-step velocities, a ghost's from its owner's end state.
    double split_power = 0, serial_power = 0;
    for (const double p : many.contact_power())
      split_power += p;
    for (const double p : one.contact_power())
      serial_power += p;
    split_power = dealii::Utilities::MPI::sum(split_power, world());
    EXPECT_NEAR(split_power, serial_power, 1e-6 * std::abs(serial_power));
    EXPECT_NEAR(split_report.epsilon, serial_report.epsilon, 1e-6 * std::abs(serial_report.epsilon));

    // A checkpoint's warm start (Simulation::prepare_checkpoint gathers it first): every
    // rank's loaded contacts once, with their impulses bit for bit, on every rank.
    std::vector<double> loaded;
    for (const Contact &c : many.contacts())
      if (c.r.x() != 0 || c.r.y() != 0)
        loaded.insert(loaded.end(), {double(c.key()), c.r.x(), c.r.y()});
    std::vector<std::array<double, 3>> expected;
    for (const auto &part : dealii::Utilities::MPI::all_gather(world(), loaded))
      for (std::size_t k = 0; k < part.size(); k += 3)
        expected.push_back({{part[k], part[k + 1], part[k + 2]}});
    std::sort(expected.begin(), expected.end());
    many.gather_warm_start();
    const std::string path = "split_warm_start." + std::to_string(my_rank()) + ".bin";
    tribo::write_checkpoint(path, [&](tribo::CheckpointOut &ar) { many.save(ar); });
    std::vector<std::array<double, 3>> saved;
    tribo::read_checkpoint(path, [&](tribo::CheckpointIn &ar) {
      std::size_t n;
      ar >> n;
      for (std::size_t k = 0; k < n; ++k)
        {
          std::uint64_t key;
          double        rn, rt;
          ar >> key >> rn >> rt;
          saved.push_back({{double(key), rn, rt}});
        }
    }, false);
    std::remove(path.c_str());
    EXPECT_GT(saved.size(), 100u);
    EXPECT_EQ(saved, expected);
    return split->cuts();
  }
} // namespace

TEST(Distributed, StepsSplitOverTheRanksGiveTheSerialSteps)
{
  // The bands cut at the first step and kept (5 %) on 1 and 2 ranks; on 3 and 4 the 140-190
  // contacts of a band drift past it (4 and 9 cuts in 21 steps).
  const unsigned long cuts = expect_split_steps_give_the_serial_steps(1.05);
  if (n_ranks() <= 2)
    {
      EXPECT_EQ(cuts, 1u);
    }
}

TEST(Distributed, BandsCutAgainEveryStepKeepTheSerialSteps)
{
  // Any imbalance cuts the bands again: every pair detected, the warm starts gathered from
  // every rank before the contacts change owners.
  const unsigned long cuts = expect_split_steps_give_the_serial_steps(1 + 1e-12);
  if (n_ranks() > 1)
    {
      EXPECT_GE(cuts, 10u);
    }
}

namespace
{
  /// A step's problem as MoreauJean hands it to its solver (the contacts, and the state with
  /// the boundary bodies' nodes and compliance), kept; NLGS solves the step.
  class KeepingSolver : public ContactSolver
  {
  public:
    KeepingSolver()
      : ContactSolver(fixed_sweeps(500))
      , nlgs(prm)
    {}
    SolveReport solve(std::vector<Contact> &contacts, BodyState &state, const ContactLaw &law,
                      double theta_h) override
    {
      kept_contacts = contacts;
      kept_state    = state;
      return nlgs.solve(contacts, state, law, theta_h);
    }
    bool        solves_friction() const override { return true; }
    std::string random_state() const override { return ""; }
    void        set_random_state(const std::string &) override {}

    NlgsSolver           nlgs;
    std::vector<Contact> kept_contacts;
    BodyState            kept_state;
  };

  /// tall_layer's grains under a chain of lumped masses (a deformable first body's boundary,
  /// dem/engine/boundary.h) instead of the upper wall, pressed onto them at 1 m/s: the 20th
  /// step's problem, cold (its impulses taken back out of the state).
  struct UnderChain
  {
    ParticleSystem       system = tall_layer(8, 24, false);
    // The top row's centres at 1.02 um + 23 dy, the half-discs' (d = 1 um) lowest points
    // 5 nm above its discs.
    LumpedChain          chain{8, 8e-6, 1.02e-6 + 23 * 1.02e-6 * std::sqrt(3.0) / 2 + 1.005e-6, 1e-8, {0, -100}};
    std::vector<Contact> contacts;
    BodyState            state;
    explicit UnderChain(const ContactLaw &law)
    {
      for (Vec2 &v : chain.v)
        v = {0, -1};
      MoreauJean mj(0.5, law, fixed_sweeps(500), 5e-8);
      mj.attach(chain, 1e-6, {0, -1}, system.period);
      auto keeping = std::make_unique<KeepingSolver>();
      KeepingSolver &kept = *keeping;
      mj.use_solver(std::move(keeping));
      for (int i = 0; i < 20; ++i)
        mj.step(system, 1e-9);
      contacts = kept.kept_contacts;
      state    = kept.kept_state;
      for (Contact &c : contacts)
        {
          state.apply_impulse(c, -c.r);
          c.r.setZero();
        }
    }
  };
} // namespace

TEST(Distributed, HalfDiscContactsAreSolvedOnTheTopBandAndGiveTheSerialAnswer)
{
  // A deformable first body's half-disc contacts all belong to the top band (one rank holds
  // the body's nodes); the grains' and the nodes' velocities are the serial ones, which the
  // step's problem makes unique without friction (docs/validation.md).
  const UnderChain cold{ContactLaw{}};
  unsigned int     on_chain = 0;
  for (const Contact &c : cold.contacts)
    on_chain += c.on_boundary();
  ASSERT_GE(on_chain, 8u);
  std::vector<Contact> serial = cold.contacts;
  BodyState            serial_state = cold.state;
  SolverParameters     tight;
  tight.method         = SolverParameters::Method::nlgs;
  tight.tolerance      = 1e-12;
  tight.max_iterations = 200000;
  NlgsSolver(tight).solve(serial, serial_state, ContactLaw{});

  for (const Sweeps sweeps : {Sweeps::gauss_seidel, Sweeps::apgs})
    {
      RankProblem p = share_of(cold.system, cold.contacts, cold.state,
                               contact_bands(cold.system, cold.contacts, n_ranks()), my_rank());
      unsigned int mine = 0;
      for (const Contact &c : p.contacts)
        mine += c.on_boundary();
      DistributedControls controls;
      controls.residual_target = 1e-9;
      controls.max_sweeps      = 100000;
      const DistributedReport report = sweeps == Sweeps::apgs ? DistributedApgs(p, world()).solve(p, ContactLaw{}, controls)
                                                              : DistributedGaussSeidel(p, world()).solve(p, ContactLaw{}, controls);
      const std::vector<Eigen::Vector3d> velocity = gathered_velocities(p, cold.system.bodies.size());
      Eigen::VectorXd nodes = my_rank() + 1 == n_ranks() ? p.state.node_velocity : Eigen::VectorXd::Zero(cold.state.node_velocity.size());
      MPI_Bcast(nodes.data(), int(nodes.size()), MPI_DOUBLE, int(n_ranks() - 1), world());

      EXPECT_EQ(mine, my_rank() + 1 == n_ranks() ? on_chain : 0u);
      EXPECT_TRUE(report.converged);
      double worst = 0;
      for (std::size_t b = 0; b < velocity.size(); ++b)
        worst = std::max(worst, (velocity[b] - serial_state.velocity[b]).head<2>().lpNorm<Eigen::Infinity>());
      EXPECT_LT(worst, 1e-6) << (sweeps == Sweeps::apgs ? "APGS sweeps" : "Gauss-Seidel");
      EXPECT_LT((nodes - serial_state.node_velocity).lpNorm<Eigen::Infinity>(), 1e-6)
        << (sweeps == Sweeps::apgs ? "APGS sweeps" : "Gauss-Seidel");
    }
}

int main(int argc, char **argv)
{
  dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
