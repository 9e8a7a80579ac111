// Cell-list detection against brute force, with and without x-periodicity.
#include "dem/contact.h"

#include <gtest/gtest.h>

#include <random>
#include <set>

using namespace tribo::dem;

namespace
{
  std::set<std::pair<unsigned, unsigned>> brute_force(const ParticleSystem &s, const std::vector<Vec2> &x,
                                                      double distance)
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
          if (d.norm() - s.discs[i].radius - s.discs[j].radius <= distance)
            pairs.insert({i, j});
        }
    return pairs;
  }

  void compare(double period)
  {
    ParticleSystem s;
    s.period = period;
    std::mt19937                           rng(7);
    std::uniform_real_distribution<double> ux(0, 20e-6), uy(0, 8e-6), ur(0.4e-6, 0.6e-6);
    for (int i = 0; i < 300; ++i)
      s.add_disc({ux(rng), uy(rng)}, ur(rng), 7800);
    std::vector<Vec2> x;
    for (unsigned d = 0; d < s.discs.size(); ++d)
      x.push_back(s.wrap(s.disc_centre(d)));
    ContactDetector detector;
    const auto      contacts = detector.detect(s, x, 1e-7);
    std::set<std::pair<unsigned, unsigned>> found;
    for (const auto &c : contacts)
      {
        EXPECT_TRUE(found.insert({c.disc[0], c.disc[1]}).second) << "pair found twice";
        EXPECT_NEAR(c.normal.norm(), 1.0, 1e-14);
        EXPECT_NEAR(c.branch.norm() - s.discs[c.disc[0]].radius - s.discs[c.disc[1]].radius, c.gap, 1e-20);
      }
    const auto expected = brute_force(s, x, 1e-7);
    EXPECT_EQ(found, expected);
    EXPECT_GT(expected.size(), 100u);
  }
} // namespace

TEST(Detection, CellListFindsTheBruteForcePairs) { compare(0); }

TEST(Detection, CellListFindsPairsAcrossThePeriodicBoundary) { compare(20e-6); }
