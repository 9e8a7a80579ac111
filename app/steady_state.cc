#include "app/steady_state.h"

#include <algorithm>
#include <cmath>

namespace tribo::app
{
  namespace
  {
    double mean_between(const std::vector<double> &time, const std::vector<double> &v, double a, double b)
    {
      double sum = 0;
      int    n   = 0;
      for (std::size_t i = 0; i < time.size(); ++i)
        if (time[i] >= a && time[i] < b)
          {
            sum += v[i];
            ++n;
          }
      return n ? sum / n : NAN;
    }
  } // namespace

  SteadyState detect_steady_state(const std::vector<double> &time,
                                  const std::vector<std::vector<double>> &series, double t0, double t1,
                                  double tolerance, const std::vector<double> &absolute)
  {
    for (int k = 1; k <= 5; ++k)
      {
        const double s   = t0 + k * (t1 - t0) / 10;
        const double mid = 0.5 * (s + t1);
        bool         ok  = true;
        for (std::size_t j = 0; j < series.size() && ok; ++j)
          {
            const double a = mean_between(time, series[j], s, mid);
            const double b = mean_between(time, series[j], mid, t1 + 1e-30 + 1e-12 * std::abs(t1));
            const double allowed = std::max(tolerance * std::max(std::abs(a), std::abs(b)),
                                            j < absolute.size() ? absolute[j] : 0.0);
            ok = std::isfinite(a) && std::isfinite(b) && std::abs(a - b) <= allowed;
          }
        if (ok)
          return {true, s};
      }
    return {false, 0.5 * (t0 + t1)};
  }

  std::pair<double, double> mean_and_std(const std::vector<double> &time, const std::vector<double> &v,
                                         double start)
  {
    double sum = 0, sum2 = 0;
    int    n   = 0;
    for (std::size_t i = 0; i < time.size(); ++i)
      if (time[i] >= start)
        {
          sum += v[i];
          sum2 += v[i] * v[i];
          ++n;
        }
    if (n == 0)
      return {NAN, NAN};
    const double m = sum / n;
    return {m, std::sqrt(std::max(0.0, sum2 / n - m * m))};
  }

  std::vector<double> batch_means(const std::vector<double> &series)
  {
    const std::size_t   n = series.size();
    const std::size_t   B = std::min<std::size_t>(standard_error_batches, n);
    std::vector<double> m(B, 0.0);
    for (std::size_t b = 0; b < B; ++b)
      {
        const std::size_t first = b * n / B, last = (b + 1) * n / B;
        for (std::size_t i = first; i < last; ++i)
          m[b] += series[i] / (last - first);
      }
    return m;
  }

  double batch_standard_error(const std::vector<double> &m)
  {
    const std::size_t B = m.size();
    if (B < 2)
      return NAN;
    double mean = 0, square = 0;
    for (const double x : m)
      mean += x / B;
    for (const double x : m)
      square += (x - mean) * (x - mean);
    return std::sqrt(square / ((B - 1) * B));
  }

  std::pair<double, double> mean_and_stderr(const std::vector<double> &time, const std::vector<double> &v,
                                            double start)
  {
    std::vector<double> window;
    for (std::size_t i = 0; i < time.size(); ++i)
      if (time[i] >= start)
        window.push_back(v[i]);
    if (window.empty())
      return {NAN, NAN};
    const auto m = batch_means(window);
    double     mean = 0;
    for (const double x : window)
      mean += x / window.size();
    return {mean, batch_standard_error(m)};
  }
} // namespace tribo::app
