#pragma once
/// @file `tribo run` and `tribo check`: read a case, build its scene, step it,
/// and write the output directory (docs/outputs.md).

#include "core/checkpoint.h"

#include <chrono>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace tribo
{
  class Log;           // core/output.h
  class ParameterFile; // core/parameter_file.h
}

namespace tribo::app
{
  struct RunOptions
  {
    std::string              case_file;
    std::string              output_dir; ///< empty: output/<case file stem>
    std::vector<std::string> overrides;  ///< "Subsection/Entry=value"
    bool                     quiet      = false;
    bool                     check_only = false;
    /// Resume the run whose outputs are in this directory from its checkpoint.bin
    /// (the outputs go on there); empty: a new run.
    std::string              resume_dir;
  };

  /// The checkpoints of one run, written and read by the driver (app/driver.h): where they go
  /// (DIR/checkpoint.bin), when one is due (every Output/Checkpoint interval seconds of wall
  /// time and every Output/Checkpoint step interval steps), what each starts with (the
  /// resolved parameters, which run_case() compares with the case through
  /// resume_changes() before anything is written, then the wall time of the run so far)
  /// and its removal once the run is complete. The loop saves and loads its own state
  /// after that header, in one order.
  class RunCheckpoint
  {
  public:
    /// @p interval wall seconds and @p step_interval steps between checkpoints (0: none of
    /// that kind); @p changes the log text of resume_changes() when @p resuming.
    RunCheckpoint(const std::string &dir, std::map<std::string, std::string> resolved,
                  double interval, unsigned long step_interval, bool resuming, std::string changes);

    /// True for a run continued with --resume: the loop loads its state with read().
    bool resuming() const { return resume; }
    /// True if a checkpoint is due after step @p step: the wall interval has passed since
    /// the last one (or the start), or @p step is a multiple of the step interval.
    bool due(unsigned long step) const;
    /// Write the checkpoint (atomically): the header, then @p save. Restarts the timer.
    void write(const std::function<void(CheckpointOut &)> &save);
    /// Read the checkpoint: the header (logged as "resuming from FILE" and the changes),
    /// then @p load; the wall time of the run before it goes on in wall_time().
    void read(Log &log, const std::function<void(CheckpointIn &)> &load);
    /// Wall time of the run so far, s: this process's plus that of the processes before
    /// the resumption.
    double wall_time() const;
    /// Remove the checkpoint: call once the run is complete.
    void remove() const;

  private:
    using Clock = std::chrono::steady_clock;
    std::string                        path;
    std::map<std::string, std::string> parameters;
    double                             interval;
    unsigned long                      step_interval;
    bool                               resume;
    std::string                        changes;
    Clock::time_point                  start, last;
    double                             wall_before = 0; ///< s, of the processes before
  };

  /// Run (or only check) a case; returns the process exit code. Input errors
  /// are thrown as InputError before anything is written.
  int run_case(const RunOptions &options);

  /// The end of every scene's run: log the error or the signal and return the exit code
  /// (0 complete, 1 failed with @p failure, 128 + signal interrupted).
  int finish_run(Log &log, const std::string &status, const std::string &failure);

  /// The "status" of DIR/summary.json (running, complete, interrupted, failed), or "" if
  /// there is none or it cannot be read.
  std::string run_status(const std::string &dir);

  /// What a resumed run may change: how it solves and what it writes, and how long it
  /// runs ("Solver/*", "Output/*", "Simulation/End time"). Anything else (the scene, the
  /// law, the loading) would not continue the same run.
  bool may_change_on_resume(const std::string &entry);

  /// The entries of @p now that differ from @p saved (the checkpoint's resolved
  /// parameters), as a log text "; changed: A x -> y, ..."; InputError naming the entry
  /// and @p dir for one that may not change. An entry the checkpoint does not have
  /// (declared by a later version of the program) is accepted when @p now leaves it at
  /// its default, which is how the program that wrote the checkpoint behaved.
  std::string resume_changes(const std::map<std::string, std::string> &saved,
                             const ParameterFile &now, const std::string &dir);

  /// The full documented parameter tree with defaults (`tribo params`).
  std::string parameter_reference();
} // namespace tribo::app
