#include "core/run_control.h"

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

  ProgressLine::ProgressLine(double end_time, bool enabled)
    : end_time(end_time)
    , enabled(enabled)
    , start(Clock::now())
    , last(start)
  {}

  void ProgressLine::update(double time, unsigned long step)
  {
    if (!enabled)
      return;
    const auto now = Clock::now();
    if (std::chrono::duration<double>(now - last).count() < 0.25)
      return;
    last                 = now;
    const double elapsed = std::chrono::duration<double>(now - start).count();
    const double frac    = end_time > 0 ? time / end_time : 0;
    const double rate    = elapsed > 0 ? step / elapsed : 0;
    const double eta     = frac > 0 ? elapsed * (1 - frac) / frac : 0;
    std::fprintf(stderr, "\rprogress %5.1f %%  t = %.4g s  %.4g steps/s  ETA %.0f s   ",
                 100 * frac, time, rate, eta);
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
