#include "core/run_control.h"

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdio>

namespace tribo
{
  namespace
  {
    volatile std::sig_atomic_t stop_signal = 0;
    extern "C" void on_stop_signal(int sig) { stop_signal = sig; }
  } // namespace

  void install_stop_handlers()
  {
    std::signal(SIGINT, on_stop_signal);
    std::signal(SIGTERM, on_stop_signal);
  }

  int stop_requested() { return stop_signal; }

  std::string shell_quote(const std::string &s)
  {
    std::string q = "'";
    for (const char c : s)
      q += (c == '\'' ? std::string("'\\''") : std::string(1, c));
    return q + "'";
  }

  RecentRate::RecentRate(double window)
    : window(window)
  {}

  void RecentRate::add(double wall, double time, unsigned long step)
  {
    const double dw = wall - last_wall;
    if (started && dw > 0)
      {
        const double dt_rate = (time - last_time) / dw;
        const double ds_rate = (static_cast<double>(step) - static_cast<double>(last_step)) / dw;
        const bool   first   = time_rate == 0 && step_rate == 0;
        const double weight  = first ? 1.0 : 1.0 - std::exp(-dw / window);
        time_rate += weight * (dt_rate - time_rate);
        step_rate += weight * (ds_rate - step_rate);
      }
    if (!started || dw > 0)
      {
        started   = true;
        last_wall = wall;
        last_time = time;
        last_step = step;
      }
  }

  double RecentRate::seconds_to(double end_time) const
  {
    return time_rate > 0 ? std::max(0.0, end_time - last_time) / time_rate : -1.0;
  }

  ProgressLine::ProgressLine(double end_time, bool enabled)
    : end_time(end_time)
    , enabled(enabled)
    , start(Clock::now())
    , last(start)
    , pace(10.0)
  {}

  void ProgressLine::update(double time, unsigned long step)
  {
    if (!enabled)
      return;
    const auto now = Clock::now();
    if (std::chrono::duration<double>(now - last).count() < 0.25)
      return;
    last = now;
    pace.add(std::chrono::duration<double>(now - start).count(), time, step);
    const double frac = end_time > 0 ? time / end_time : 0;
    const double eta  = pace.seconds_to(end_time);
    char         rate[32] = "-";
    if (eta >= 0)
      std::snprintf(rate, sizeof rate, "%.4g", pace.steps_per_second());
    std::fprintf(stderr, "\rprogress %5.1f %%  t = %.4g s  %s steps/s  ETA %s   ", 100 * frac, time, rate,
                 eta < 0 ? "-" : (std::to_string(static_cast<long>(eta + 0.5)) + " s").c_str());
    std::fflush(stderr);
    printed = true;
  }

  void ProgressLine::finish()
  {
    if (printed)
      std::fprintf(stderr, "\n");
    printed = false;
  }
} // namespace tribo
