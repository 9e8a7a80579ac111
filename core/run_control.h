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

  /// A run's recent pace: the simulated time and the steps advanced per second of wall
  /// time, averaged exponentially over the last @p window seconds of wall time,
  /// rate <- rate + (1 - exp(-dw / window)) (dt / dw - rate) for each sample dw apart.
  /// So an estimate of the time left follows a change of pace (a compaction's cheap steps,
  /// then the shear's dearer ones) and ignores what a resumed run did before.
  class RecentRate
  {
  public:
    explicit RecentRate(double window);
    /// A sample: @p wall seconds on any fixed clock, @p time the simulated time (s),
    /// @p step the step count.
    void add(double wall, double time, unsigned long step);
    /// Simulated seconds per wall second; 0 before two samples.
    double time_per_second() const { return time_rate; }
    double steps_per_second() const { return step_rate; }
    /// Wall seconds until the simulated time reaches @p end_time at the recent pace; a
    /// negative value before the pace is known.
    double seconds_to(double end_time) const;

  private:
    double        window;
    bool          started = false;
    double        last_wall = 0, last_time = 0;
    unsigned long last_step = 0;
    double        time_rate = 0, step_rate = 0;
  };

  /// "progress  42.0 %  t = 1.2e-06 s  3100 steps/s  ETA 12 s", rewritten in
  /// place on stderr at most a few times a second; the rate and ETA from the last
  /// 10 s of the run (RecentRate).
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
    RecentRate        pace;
  };
} // namespace tribo
