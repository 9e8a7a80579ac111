// The banded NLGS (SolverParameters::threads > 1) and the interleaved streams: each is the
// serial Gauss-Seidel sweep in its own order, bit for bit, and a banded run solves the
// law as the serial run does.
#include "tests/unit/tall_layer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace tribo::dem;
using namespace tribo::dem::test;

TEST(NlgsBands, ConcurrentSweepIsTheSerialSweepInBandOrder)
{
  const ColdStart             cold;
  const ParticleSystem       &s        = cold.system;
  const std::vector<Contact> &contacts = cold.contacts;
  ASSERT_GT(contacts.size(), 300u);
  SolverParameters fixed = fixed_sweeps(40);
  fixed.check_interval = 10;
  fixed.threads        = 2;
  fixed.streams        = 1; // the band order alone (streams reorder within a band)

  std::vector<Contact> banded = contacts;
  BodyState            banded_state = BodyState::of(s);
  const SolveReport     rep          = NlgsSolver(fixed).solve(banded, banded_state, cold.law);
  EXPECT_TRUE(rep.concurrent);
  EXPECT_EQ(rep.iterations, 40u);

  // The same contacts reordered band 0, 2, 1, 3 and swept serially.
  const std::size_t    n = contacts.size();
  std::vector<Contact> serial;
  for (const unsigned int k : {0u, 2u, 1u, 3u})
    for (std::size_t i = n * k / 4; i < n * (k + 1) / 4; ++i)
      serial.push_back(contacts[i]);
  fixed.threads          = 1;
  BodyState serial_state = BodyState::of(s);
  NlgsSolver(fixed).solve(serial, serial_state, cold.law);

  unsigned int moved = 0;
  for (std::size_t j = 0, i = 0; j < 4; ++j)
    {
      const unsigned int k = j == 0 ? 0 : j == 1 ? 2 : j == 2 ? 1 : 3;
      for (std::size_t a = n * k / 4; a < n * (k + 1) / 4; ++a, ++i)
        {
          EXPECT_EQ(banded[a].r.x(), serial[i].r.x()) << "contact " << a;
          EXPECT_EQ(banded[a].r.y(), serial[i].r.y()) << "contact " << a;
          moved += banded[a].r.x() != 0 ? 1 : 0;
        }
    }
  EXPECT_GT(moved, 100u);
  for (std::size_t b = 0; b < s.bodies.size(); ++b)
    EXPECT_EQ(banded_state.velocity[b], serial_state.velocity[b]) << "body " << b;
}

TEST(NlgsBands, BandedRunSolvesTheLawAsTheSerialRunDoes)
{
  // 100 steps of the loaded layer on two bands at once and serially: each step's law
  // residual (measured apart from NLGS's own norms) stays at what the tolerance allows,
  // and the two runs carry the same load on the lower wall.
  auto run = [](unsigned int threads, double &force, double &worst_residual) {
    ParticleSystem   s = tall_layer();
    SolverParameters prm;
    prm.method    = SolverParameters::Method::nlgs;
    prm.tolerance = 1e-4;
    prm.threads   = threads;
    MoreauJean   mj(0.5, ContactLaw{}, prm, 5e-8);
    unsigned int concurrent = 0;
    force = worst_residual = 0;
    for (int i = 0; i < 100; ++i)
      {
        const auto rep = mj.step(s, 1e-9);
        EXPECT_TRUE(rep.solver.converged) << "step " << i;
        concurrent += rep.solver.concurrent ? 1 : 0;
        worst_residual = std::max(worst_residual, rep.solver.law_residual);
        if (i >= 50)
          force += mj.contact_force()[0].y() / 50;
      }
    return concurrent;
  };
  double force1, residual1, force2, residual2;
  EXPECT_EQ(run(1, force1, residual1), 0u);
  EXPECT_GT(run(2, force2, residual2), 90u);
  // Quad 1e-4 leaves a worst law residual of 0.9-1.3e-3 here; a solve stopped short
  // (Tolerance 1e-2) leaves 0.10-0.13.
  EXPECT_LT(residual1, 2e-3);
  EXPECT_LT(residual2, 2e-3);
  // The layer still settles under the wall (it started moving down at 1 m/s), so the mean
  // over the last 50 steps is near the 800 N/m load, and the two orders agree closely.
  EXPECT_NEAR(force1, -800.0, 40.0);
  EXPECT_NEAR(force2, force1, 5e-3 * std::abs(force1));
}

TEST(NlgsBands, StreamsAreTheSerialSweepInInterleavedOrder)
{
  // Streams = 4, spacing 16: in each window of 64 contacts starting at w, contacts w,
  // w + q, w + 2q, w + 3q, w + 1, ... (q = 16, or the last window's size / 4 rounded up):
  // the same sweep as the detection-order solver run on the contacts in that order.
  const ColdStart             cold;
  const ParticleSystem       &s        = cold.system;
  const std::vector<Contact> &contacts = cold.contacts;
  SolverParameters              fixed    = fixed_sweeps(40);
  fixed.streams                        = 4;
  fixed.stream_spacing                 = 16;
  std::vector<Contact> streamed = contacts;
  BodyState            streamed_state = BodyState::of(s);
  NlgsSolver(fixed).solve(streamed, streamed_state, cold.law);

  const std::size_t        n = contacts.size();
  ASSERT_GT(n, 3 * 64u); // several windows, the last one partial unless n % 64 = 0
  std::vector<std::size_t> order;
  for (std::size_t w = 0; w < n; w += 64)
    {
      const std::size_t size = std::min<std::size_t>(64, n - w), q = (size + 3) / 4;
      for (std::size_t j = 0; j < q; ++j)
        for (std::size_t k = 0; k < 4; ++k)
          if (k * q + j < size)
            order.push_back(w + k * q + j);
    }
  ASSERT_EQ(order.size(), n);
  std::vector<Contact> serial;
  for (const std::size_t a : order)
    serial.push_back(contacts[a]);
  fixed.streams          = 1;
  BodyState serial_state = BodyState::of(s);
  NlgsSolver(fixed).solve(serial, serial_state, cold.law);
  for (std::size_t i = 0; i < n; ++i)
    EXPECT_EQ(streamed[order[i]].r, serial[i].r) << "contact " << order[i];
  for (std::size_t b = 0; b < s.bodies.size(); ++b)
    EXPECT_EQ(streamed_state.velocity[b], serial_state.velocity[b]) << "body " << b;
}

namespace
{
  /// 50 steps of tall_layer() with @p method on 1 and 2 threads give the same bits and
  /// balance their energy.
  void expect_same_state_on_any_number_of_threads(SolverParameters::Method method)
{
  auto run = [method](unsigned int threads, std::vector<double> &balance) {
    ParticleSystem   s = tall_layer();
    SolverParameters prm;
    prm.method          = method;
    prm.residual_target  = 1e-6;
    prm.predictor_sweeps = 0;
    prm.threads          = threads;
    MoreauJean mj(0.5, ContactLaw{}, prm, 5e-8);
    std::size_t most = 0;
    for (int i = 0; i < 50; ++i)
      {
        const double ke0 = s.kinetic_energy();
        const auto   rep = mj.step(s, 1e-9);
        const double dke = rep.kinetic_energy - ke0;
        const double rhs = 1e-9 * (rep.power_external + rep.power_contacts);
        balance.push_back(std::abs(dke - rhs) / (std::abs(dke) + std::abs(rhs) + 1e-300));
        EXPECT_TRUE(rep.solver.converged) << "step " << i;
        // The target is relative to the warm start's mean impulse, the residual to the
        // final one's.
        EXPECT_LT(rep.solver.law_residual, 1e-5) << "step " << i;
        most = std::max<std::size_t>(most, rep.n_contacts);
      }
    EXPECT_GT(most, 512u); // at least three chunks: the threads share the work
    std::vector<double> v;
    for (const auto &b : s.bodies)
      v.insert(v.end(), {b.velocity.x(), b.velocity.y(), b.spin, b.position.x(), b.position.y()});
    return v;
  };
  std::vector<double> balance;
  const auto          serial   = run(1, balance);
  const auto          threaded = run(2, balance);
  EXPECT_EQ(serial, threaded);
  for (const double b : balance)
    EXPECT_LT(b, 1e-9);
}
} // namespace

TEST(NlgsBands, ApgsGivesTheSameStateOnAnyNumberOfThreads)
{
  // APGS sweeps its slabs of one colour concurrently (dem/solvers/apgs.cc): they share no contact's
  // row, so the order of their updates does not matter.
  expect_same_state_on_any_number_of_threads(SolverParameters::Method::apgs);
  // ... and on this layer the slabs are separate, so the threads did share the sweeps.
  ParticleSystem   s = tall_layer();
  SolverParameters prm;
  prm.method           = SolverParameters::Method::apgs;
  prm.predictor_sweeps = 0;
  prm.threads          = 2;
  MoreauJean   mj(0.5, ContactLaw{}, prm, 5e-8);
  unsigned int concurrent = 0;
  for (int i = 0; i < 20; ++i)
    concurrent += mj.step(s, 1e-9).solver.concurrent;
  EXPECT_GT(concurrent, 0u);
}

TEST(NlgsBands, MprgpGivesTheSameStateOnAnyNumberOfThreads)
{
  // The products and sums of MPRGP are made per fixed chunk of 256 contacts and added in
  // chunk order: 1 and 2 threads give the same bits (without the predictor sweeps, which
  // are NLGS's and run in band order), and the energy balance holds.
  expect_same_state_on_any_number_of_threads(SolverParameters::Method::mprgp);
}

TEST(NlgsBands, ApgdGivesTheSameStateOnAnyNumberOfThreads)
{
  // APGD's passes run over the same fixed chunks (dem/linalg/scaled_operator.h).
  expect_same_state_on_any_number_of_threads(SolverParameters::Method::apgd);
}
