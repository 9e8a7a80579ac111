// The batch-means standard error (app/steady_state.h) against the known variance of the
// mean of an AR(1) series, x_t = phi x_{t-1} + e_t, e_t ~ N(0, s^2): for n >> the
// correlation time, Var(mean) = s^2 / ((1 - phi)^2 n).
#include "app/steady_state.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

using namespace tribo::app;

TEST(Statistics, BatchMeansStandardErrorOfAnAr1Series)
{
  const double       phi = 0.9, s = 1.0;
  const std::size_t  n = 20000, replicates = 400;
  const double       variance = s * s / ((1 - phi) * (1 - phi) * n); // 0.005
  std::mt19937       gen(17);
  std::normal_distribution<double> e(0.0, s);
  double mean_of_squares = 0, spread = 0, naive = 0;
  for (std::size_t r = 0; r < replicates; ++r)
    {
      std::vector<double> x(n), time(n);
      x[0] = e(gen) / std::sqrt(1 - phi * phi); // stationary start
      for (std::size_t t = 1; t < n; ++t)
        x[t] = phi * x[t - 1] + e(gen);
      for (std::size_t t = 0; t < n; ++t)
        time[t] = t;
      const auto [mean, error] = mean_and_stderr(time, x, 0.0);
      mean_of_squares += error * error / replicates;
      spread += mean * mean / replicates; // the true mean is 0
      naive += mean_and_std(time, x, 0.0).second / std::sqrt(double(n)) / replicates;
    }
  // The estimator's mean square is the variance of the mean (sampling error of 400
  // replicates of a 9-degree-of-freedom estimate: 2.4 %; batch bias about 1 %).
  EXPECT_NEAR(mean_of_squares, variance, 0.1 * variance);
  // The replicates' means do scatter that much.
  EXPECT_NEAR(spread, variance, 0.2 * variance);
  // The plain std / sqrt(n) is too small by about sqrt((1 + phi) / (1 - phi)) = 4.4.
  EXPECT_NEAR(std::sqrt(variance) / naive, std::sqrt((1 + phi) / (1 - phi)), 0.3);
}

TEST(Statistics, BatchMeansOfShortSeries)
{
  // Fewer rows than batches: one batch per row; one row: no standard error.
  EXPECT_EQ(batch_means({1.0, 2.0, 3.0}).size(), 3u);
  EXPECT_NEAR(batch_standard_error({1.0, 2.0, 3.0}), std::sqrt(2.0 / 6.0), 1e-15);
  EXPECT_TRUE(std::isnan(batch_standard_error(batch_means({4.0}))));
  // Uneven batches: rows [b n / B, (b + 1) n / B), 12 rows in 10 batches.
  std::vector<double> v(12);
  for (int i = 0; i < 12; ++i)
    v[i] = i;
  const auto m = batch_means(v);
  ASSERT_EQ(m.size(), 10u);
  EXPECT_DOUBLE_EQ(m[0], 0.0);        // rows [0, 12 / 10) = row 0
  EXPECT_DOUBLE_EQ(m[4], 4.5);        // rows [48 / 10, 60 / 10) = [4, 6)
  EXPECT_DOUBLE_EQ(m[9], 10.5);       // rows [108 / 10, 12) = [10, 12)
}
