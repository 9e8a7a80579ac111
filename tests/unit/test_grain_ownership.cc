// The state of a case split over MPI ranks (dem/parallel/grain_ownership.h), run by ctest on
// 1 to 4 ranks with the distributed solve's tests (tests/unit/CMakeLists.txt). A reference
// copy of the system moves its grains across the bands; each rank advances only the grains
// it owns and exchanges them, its copies of the grains it does not hold made NaN. Every
// assertion follows the collective calls.
#include "dem/parallel/grain_ownership.h"
#include "tests/unit/ranks.h"
#include "tests/unit/tall_layer.h"

#include <deal.II/base/mpi.h>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

using namespace tribo::dem;
using namespace tribo::dem::parallel;
using namespace tribo::dem::test;

namespace
{
  /// The reference motion of step @p k: grains left of the middle rise and the others sink
  /// (0.2 um per step, so that they cross the bands), with a jitter of up to 0.05 um and a
  /// turn, the same on every rank.
  void advance(ParticleSystem &s, const std::vector<bool> &grain, int k)
  {
    for (unsigned int b = 0; b < s.bodies.size(); ++b)
      if (grain[b])
        {
          RigidBody   &body   = s.bodies[b];
          const double jitter = 0.05e-6 * std::sin(1.7 * b + 0.9 * k);
          body.velocity       = {0.1 * std::cos(0.3 * b + k), (body.position.x() < 0.5 * s.period ? 0.2 : -0.2) + jitter * 1e6};
          body.position += 1e-6 * body.velocity;
          body.position.x() -= s.period * std::floor(body.position.x() / s.period);
          body.spin = std::sin(0.11 * b * k);
          body.angle += 0.01 * body.spin;
        }
  }

  bool same_state(const RigidBody &a, const RigidBody &b)
  {
    return a.position == b.position && a.angle == b.angle && a.velocity == b.velocity && a.spin == b.spin;
  }

  void make_stale(RigidBody &body)
  {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    body.position    = {nan, nan};
    body.velocity    = {nan, nan};
    body.angle = body.spin = nan;
  }
} // namespace

TEST(GrainOwnership, NoGrainIsLostOrOwnedTwiceAcrossMigrations)
{
  ParticleSystem          truth = test::tall_layer(8, 24);
  const std::vector<bool> grain = grains_of(truth);
  const unsigned int      n     = truth.bodies.size();
  std::vector<double>     heights;
  for (unsigned int b = 0; b < n; ++b)
    if (grain[b])
      heights.push_back(truth.bodies[b].position.y());
  const BandPartition bands  = BandPartition::balanced(heights, n_ranks());
  const double        margin = 1.5e-6; // a diameter and a half
  const auto widened = [&](double y) { return y >= bands.cut[my_rank()] - margin && y < bands.cut[my_rank() + 1] + margin; };

  ParticleSystem local = truth;
  GrainOwnership own(world(), margin);
  own.start(local, bands);
  unsigned long migrations = 0, ghosts = 0;
  bool          lost_or_twice = false, stale_held = false, wrong_holding = false, wrong_owner = false,
       wrong_number = false, wrong_sum = false, wrong_gather = false;
  std::vector<unsigned int> last_owner(n);
  for (unsigned int b = 0; b < n; ++b)
    last_owner[b] = bands.band_of(truth.bodies[b].position.y());
  for (int k = 1; k <= 40; ++k)
    {
      advance(truth, grain, k);
      for (const unsigned int b : own.owned())
        local.bodies[b] = truth.bodies[b]; // the owner advances its grains
      const std::vector<unsigned int> held_before = own.held();
      own.send_states(local);
      wrong_holding = wrong_holding || own.held() != held_before; // kept until the step stands
      own.settle(local);
      for (unsigned int b = 0; b < n; ++b)
        if (grain[b] && !own.holds(b))
          make_stale(local.bodies[b]);

      // Each grain owned once, the held ones current, exactly the widened band held.
      std::vector<double> owned_count(n, 0.0), at_number(own.n_grains(), 0.0);
      for (unsigned int b = 0; b < n; ++b)
        if (grain[b])
          {
            const double y = truth.bodies[b].position.y();
            owned_count[b] = own.owns(b);
            stale_held     = stale_held || (own.holds(b) && !same_state(local.bodies[b], truth.bodies[b]));
            wrong_holding  = wrong_holding || own.holds(b) != (bands.band_of(y) == my_rank() || widened(y));
            if (own.holds(b))
              {
                wrong_owner = wrong_owner || own.owner(b) != bands.band_of(y);
                ghosts += !own.owns(b);
              }
            if (own.owns(b))
              {
                at_number[own.global_number(b)] = b + 1;
                migrations += last_owner[b] != my_rank();
                last_owner[b] = my_rank();
              }
          }
      const std::vector<double> counts = summed(owned_count), numbered = summed(at_number);
      for (unsigned int b = 0; b < n; ++b)
        {
          lost_or_twice = lost_or_twice || (grain[b] && counts[b] != 1.0);
          if (grain[b])
            last_owner[b] = bands.band_of(truth.bodies[b].position.y());
          if (grain[b] && own.holds(b))
            wrong_number = wrong_number || numbered[own.global_number(b)] != b + 1;
        }
      // The owned numbers: one contiguous range per rank, in rank order.
      for (std::size_t i = 1; i < own.owned().size(); ++i)
        wrong_number = wrong_number || own.global_number(own.owned()[i]) != own.global_number(own.owned()[0]) + i;

      // Sums where the bodies are advanced (integers: exact in any order).
      std::vector<Eigen::Vector3d> part(n, Eigen::Vector3d::Zero());
      std::vector<double>          flat(3 * n, 0.0);
      for (const unsigned int b : own.held())
        {
          part[b] = double((my_rank() + 1) * (b + 1)) * Eigen::Vector3d(1, 2, 3);
          for (int d = 0; d < 3; ++d)
            flat[3 * b + d] = part[b][d];
        }
      const std::vector<double> total = summed(flat);
      own.sum_on_owners(part);
      for (unsigned int b = 0; b < n; ++b)
        {
          const Eigen::Vector3d expected(total[3 * b], total[3 * b + 1], total[3 * b + 2]);
          if (!grain[b] || own.owns(b))
            wrong_sum = wrong_sum || part[b] != expected;
          else
            wrong_sum = wrong_sum || !part[b].isZero();
        }

      if (k % 10 == 0)
        {
          own.gather(local);
          for (unsigned int b = 0; b < n; ++b)
            wrong_gather = wrong_gather || !same_state(local.bodies[b], truth.bodies[b]);
        }
    }
  const double all_migrations = dealii::Utilities::MPI::sum(double(migrations), world());
  EXPECT_FALSE(lost_or_twice);
  EXPECT_FALSE(stale_held);
  EXPECT_FALSE(wrong_holding);
  EXPECT_FALSE(wrong_owner);
  EXPECT_FALSE(wrong_number);
  EXPECT_FALSE(wrong_sum);
  EXPECT_FALSE(wrong_gather);
  if (n_ranks() > 1)
    {
      EXPECT_GT(all_migrations, 20); // grains did cross the bands
      EXPECT_GT(ghosts, 0u);
    }
  else
    EXPECT_EQ(all_migrations, 0);
}
