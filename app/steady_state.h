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
} // namespace tribo::app
