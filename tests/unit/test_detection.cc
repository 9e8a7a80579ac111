// Cell-list detection against brute force, with and without x-periodicity, and the
// threaded search against the serial one, and the search of a band of pair midpoints.
#include "core/errors.h"
#include "dem/engine/contact.h"

#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <set>

using namespace tribo::dem;

namespace
{
  /// Every pair within @p distance, or closed by its discs' @p motion (when given).
  std::set<std::pair<unsigned, unsigned>> brute_force(const ParticleSystem &s, const std::vector<Vec2> &x,
                                                      double distance, const std::vector<Vec2> &motion = {})
  {
    std::set<std::pair<unsigned, unsigned>> pairs;
    for (unsigned i = 0; i < x.size(); ++i)
      for (unsigned j = i + 1; j < x.size(); ++j)
        {
          if (s.discs[i].body == s.discs[j].body)
            continue;
          Vec2 d = x[j] - x[i];
          if (s.period > 0)
            d.x() -= s.period * std::round(d.x() / s.period);
          const double gap     = d.norm() - s.discs[i].radius - s.discs[j].radius;
          const double closing = motion.empty() ? 0 : -(motion[j] - motion[i]).dot(d) / d.norm();
          if (gap <= distance || gap <= closing)
            pairs.insert({i, j});
        }
    return pairs;
  }

  ParticleSystem random_discs(double period)
  {
    ParticleSystem s;
    s.period = period;
    std::mt19937                           rng(7);
    std::uniform_real_distribution<double> ux(0, 20e-6), uy(0, 8e-6), ur(0.4e-6, 0.6e-6);
    for (int i = 0; i < 300; ++i)
      s.add_disc({ux(rng), uy(rng)}, ur(rng), 7800);
    return s;
  }

  /// The discs' centres, wrapped into the period.
  std::vector<Vec2> wrapped_centres(const ParticleSystem &s)
  {
    std::vector<Vec2> x;
    for (unsigned d = 0; d < s.discs.size(); ++d)
      x.push_back(s.wrap(s.disc_centre(d)));
    return x;
  }

  /// Cell list against brute force; with @p speed > 0, random disc motions of up to @p speed
  /// times the mean radius.
  void compare(double period, double speed = 0)
  {
    const ParticleSystem s = random_discs(period);
    std::vector<Vec2>    x, motion;
    std::mt19937                           rng(11);
    std::uniform_real_distribution<double> um(-speed * 0.5e-6, speed * 0.5e-6);
    for (unsigned d = 0; d < s.discs.size(); ++d)
      {
        x.push_back(s.wrap(s.disc_centre(d)));
        if (speed > 0)
          motion.emplace_back(um(rng), um(rng));
      }
    ContactDetector detector;
    const auto      contacts = detector.detect(s, x, 1e-7, 1, motion);
    std::set<std::pair<unsigned, unsigned>> found;
    for (const auto &c : contacts)
      {
        EXPECT_TRUE(found.insert({c.disc[0], c.disc[1]}).second) << "pair found twice";
        EXPECT_NEAR(c.normal.norm(), 1.0, 1e-14);
        EXPECT_NEAR(c.branch.norm() - s.discs[c.disc[0]].radius - s.discs[c.disc[1]].radius, c.gap, 1e-20);
      }
    const auto expected = brute_force(s, x, 1e-7, motion);
    EXPECT_EQ(found, expected);
    EXPECT_GT(expected.size(), 100u);
    if (speed > 0) // the motions add pairs beyond the distance
      {
        EXPECT_GT(expected.size(), brute_force(s, x, 1e-7).size() + 20);
      }
  }
} // namespace

TEST(Detection, CellListFindsTheBruteForcePairs) { compare(0); }

TEST(Detection, CellListFindsPairsAcrossThePeriodicBoundary) { compare(20e-6); }

// Pairs beyond the detection distance that the discs' motions close (relative motions up to
// 1.9 largest radii, within ContactDetector::max_motion_reach) are found as brute force
// finds them.
TEST(Detection, CellListFindsThePairsTheMotionsClose)
{
  compare(0, 0.8);
  compare(20e-6, 0.8);
}

// A narrow period that holds two reaches without motions (2.6 um in 2.8 um) still does with
// a disc moving 1 mm: the motions widen the cells only as far as the period allows, and the
// pairs within the distance are found.
TEST(Detection, FastDiscsInANarrowPeriodAreNoError)
{
  ParticleSystem s;
  s.period = 2.8e-6;
  for (int k = 0; k < 3; ++k)
    s.add_disc({1e-6, 1.25e-6 * k}, 0.6e-6, 7800); // gaps of 5e-8 m
  std::vector<Vec2> x, motion(3, Vec2::Zero());
  for (unsigned d = 0; d < s.discs.size(); ++d)
    x.push_back(s.disc_centre(d));
  motion[0] = {1e-3, 0};
  ContactDetector detector;
  const auto      contacts = detector.detect(s, x, 1e-7, 1, motion);
  std::set<std::pair<unsigned, unsigned>> found;
  for (const auto &c : contacts)
    found.insert({c.disc[0], c.disc[1]});
  EXPECT_EQ(found, (std::set<std::pair<unsigned, unsigned>>{{0, 1}, {1, 2}}));
}

TEST(Detection, AMotionPerDiscIsRequired)
{
  const ParticleSystem s = random_discs(0);
  std::vector<Vec2>    x;
  for (unsigned d = 0; d < s.discs.size(); ++d)
    x.push_back(s.disc_centre(d));
  ContactDetector detector;
  try
    {
      detector.detect(s, x, 1e-7, 1, std::vector<Vec2>(3, Vec2::Zero()));
      FAIL() << "no error";
    }
  catch (const tribo::RunError &e)
    {
      EXPECT_STREQ(e.what(), "contact detection: 3 disc motions for 300 discs");
    }
}

// Rows of cells searched in 4 T chunks concurrently and joined in order: the same
// contacts in the same order, bit for bit, as the serial pass.
TEST(Detection, ThreadedSearchIsTheSerialSearch)
{
  const ParticleSystem    s = random_discs(20e-6);
  const std::vector<Vec2> x = wrapped_centres(s);
  ContactDetector         detector;
  const auto              serial = detector.detect(s, x, 1e-7, 1);
  ASSERT_GT(serial.size(), 100u);
  for (unsigned int threads : {2u, 3u, 8u})
    {
      const auto threaded = detector.detect(s, x, 1e-7, threads);
      ASSERT_EQ(threaded.size(), serial.size()) << threads << " threads";
      for (std::size_t k = 0; k < serial.size(); ++k)
        {
          EXPECT_EQ(threaded[k].disc[0], serial[k].disc[0]) << "contact " << k << ", " << threads << " threads";
          EXPECT_EQ(threaded[k].disc[1], serial[k].disc[1]) << "contact " << k << ", " << threads << " threads";
          EXPECT_EQ(threaded[k].gap, serial[k].gap);
        }
    }
}

TEST(Detection, ABandOfMidpointsHoldsEveryPairWhoseMidpointLiesInIt)
{
  // The search of a band (a process's share of a case on several MPI ranks) finds exactly the
  // pairs of the whole search whose midpoint lies in the band, with or without threads.
  const ParticleSystem    s = random_discs(20e-6);
  const std::vector<Vec2> x = wrapped_centres(s);
  ContactDetector         detector;
  const auto              whole = detector.detect(s, x, 1e-7, 1);
  const double            inf   = std::numeric_limits<double>::infinity();
  std::vector<double>     heights;
  for (const Vec2 &c : x)
    heights.push_back(c.y());
  for (const auto &[lo, hi] : {std::pair{-inf, 2e-6}, std::pair{2e-6, 5.5e-6}, std::pair{5.5e-6, inf},
                               std::pair{3e-6, 3.1e-6}})
    for (unsigned int threads : {1u, 2u})
      {
        std::set<std::pair<unsigned, unsigned>> expected, found;
        for (const auto &c : whole)
          if (const double y = 0.5 * (x[c.disc[0]].y() + x[c.disc[1]].y()); y >= lo && y < hi)
            expected.insert({c.disc[0], c.disc[1]});
        std::vector<Contact> band;
        detector.detect(s, x, 1e-7, threads, {}, band, PairBand{lo, hi, &heights});
        for (const auto &c : band)
          found.insert({c.disc[0], c.disc[1]});
        EXPECT_EQ(found, expected) << lo << " to " << hi << ", " << threads << " threads";
        if (hi - lo > 1e-6)
          {
            EXPECT_GT(expected.size(), 30u);
          }

      }
}
