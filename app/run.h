#pragma once
/// @file `tribo run` and `tribo check`: read a case, build its scene, step it,
/// and write the output directory (docs/outputs.md).

#include <string>
#include <vector>

namespace tribo
{
  class Log; // core/output.h
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

  /// Run (or only check) a case; returns the process exit code. Input errors
  /// are thrown as InputError before anything is written.
  int run_case(const RunOptions &options);

  /// The end of every scene's run: log the error or the signal and return the exit code
  /// (0 complete, 1 failed with @p failure, 128 + signal interrupted).
  int finish_run(Log &log, const std::string &status, const std::string &failure);

  /// The "status" of DIR/summary.json (running, complete, interrupted, failed), or "" if
  /// there is none or it cannot be read.
  std::string run_status(const std::string &dir);

  /// The full documented parameter tree with defaults (`tribo params`).
  std::string parameter_reference();
} // namespace tribo::app
