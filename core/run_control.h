#pragma once
/// @file Controls of a running job: the stop request from SIGINT/SIGTERM and
/// the progress line on the terminal.

#include <chrono>
#include <string>

namespace tribo
{
  /// Catch SIGINT and SIGTERM: the time loop polls stop_requested() and ends
  /// cleanly (flushing outputs, marking the run incomplete).
  void install_stop_handlers();
  /// The signal that asked to stop, or 0.
  int stop_requested();

  /// @p s as one single-quoted POSIX shell word (for commands run with std::system).
  std::string shell_quote(const std::string &s);

  /// "progress  42.0 %  t = 1.2e-06 s  3100 steps/s  ETA 12 s", rewritten in
  /// place on stderr at most a few times a second.
  class ProgressLine
  {
  public:
    ProgressLine(double end_time, bool enabled);
    void update(double time, unsigned long step);
    /// End the line (newline) if anything was printed.
    void finish();

  private:
    using Clock = std::chrono::steady_clock;
    double            end_time;
    bool              enabled;
    bool              printed = false;
    Clock::time_point start, last;
  };
} // namespace tribo
