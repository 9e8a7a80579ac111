#pragma once
/// @file Detection of the steady state of a sheared layer from its time series.
///
/// Rule: the candidates are the starts s = t0 + k (t1 - t0)/10, k = 1..5, over the
/// shearing phase [t0, t1]. The steady state starts at the earliest candidate for
/// which the rows after s split into two halves (in time) whose means agree, for
/// every given series, within @p tolerance relative to the larger |mean| (or within
/// @p absolute, whichever is larger). If no candidate passes, the last half is
/// used and `reached` is false.

#include <vector>

namespace tribo::app
{
  struct SteadyState
  {
    bool   reached = false;
    double start   = 0; ///< s
  };

  SteadyState detect_steady_state(const std::vector<double> &time,
                                  const std::vector<std::vector<double>> &series, double t0,
                                  double t1, double tolerance = 0.1,
                                  const std::vector<double> &absolute = {});

  /// Mean and standard deviation of @p v over the rows with time >= @p start.
  std::pair<double, double> mean_and_std(const std::vector<double> &time, const std::vector<double> &v,
                                         double start);

  /// Number of batches of the batch-means estimator.
  constexpr unsigned int standard_error_batches = 10;

  /// The B = min(10, n) batch means of @p series (time order): contiguous batches of
  /// (nearly) equal size, batch b holding rows [b n / B, (b + 1) n / B).
  std::vector<double> batch_means(const std::vector<double> &series);

  /// Standard error of the mean of a series from its batch means @p m_b (B of them):
  /// sqrt(sum_b (m_b - m)^2 / ((B - 1) B)), m their mean; NaN for B < 2. Batches longer
  /// than the series' correlation time make this account for the correlation, which the
  /// plain std / sqrt(n) does not (for an AR(1) series with coefficient phi that one is
  /// too small by sqrt((1 + phi) / (1 - phi))).
  double batch_standard_error(const std::vector<double> &batch_means);

  /// Mean of @p v over the rows with time >= @p start and its batch-means standard error.
  std::pair<double, double> mean_and_stderr(const std::vector<double> &time, const std::vector<double> &v,
                                            double start);
} // namespace tribo::app
