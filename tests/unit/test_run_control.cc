// The progress line's pace (core/run_control.h): the ETA follows the recent rate, not the
// mean since the start, so a run whose steps get dearer (a compaction, then the shear) or a
// resumed run reads the time it has left.
#include "core/run_control.h"

#include <gtest/gtest.h>

using tribo::RecentRate;

TEST(RunControl, EtaFollowsTheRecentPaceAfterTheStepsGetDearer)
{
  // 20 s at 1e-6 simulated s per s (4000 steps/s), then 60 s at 1e-7 (400 steps/s); a
  // sample every 0.25 s as the progress line takes them. End at 5e-5 s.
  RecentRate    pace(10.0);
  double        wall = 0, time = 0;
  unsigned long step = 0;
  for (; wall < 20.0; wall += 0.25, time += 0.25e-6, step += 1000)
    pace.add(wall, time, step);
  EXPECT_NEAR(pace.time_per_second(), 1e-6, 1e-12);
  EXPECT_NEAR(pace.seconds_to(5e-5), (5e-5 - (time - 0.25e-6)) / 1e-6, 1e-6);
  for (const double stop = wall + 60.0; wall < stop; wall += 0.25, time += 0.25e-7, step += 100)
    pace.add(wall, time, step);
  const double last_time = time - 0.25e-7, left = (5e-5 - last_time) / 1e-7;
  // Six windows after the change the average has forgotten the old pace but for
  // 9e-7 exp(-6) = 2.2e-9 s/s, 2 % of the new one.
  EXPECT_NEAR(pace.time_per_second(), 1e-7, 0.03e-7);
  EXPECT_NEAR(pace.steps_per_second(), 400.0, 12.0);
  EXPECT_NEAR(pace.seconds_to(5e-5), left, 0.03 * left);
  // (The mean since the start, 2.6e-5 s over 80 s, would give 0.31 times this ETA.)
}

TEST(RunControl, EtaIsUnknownBeforeTwoSamplesAndIgnoresAResumedRunsPast)
{
  RecentRate pace(10.0);
  EXPECT_LT(pace.seconds_to(1.0), 0.0);
  // A run resumed at t = 0.5 s of simulated time: its first sample says nothing of the pace.
  pace.add(3.0, 0.5, 50000);
  EXPECT_LT(pace.seconds_to(1.0), 0.0);
  pace.add(4.0, 0.51, 50100);
  EXPECT_NEAR(pace.time_per_second(), 0.01, 1e-12);
  EXPECT_NEAR(pace.steps_per_second(), 100.0, 1e-9);
  EXPECT_NEAR(pace.seconds_to(1.0), 49.0, 1e-9);
  EXPECT_EQ(pace.seconds_to(0.2), 0.0);
}
