#pragma once
/// @file `tribo run` and `tribo check`: read a case, build its scene, step it,
/// and write the output directory (docs/outputs.md).

#include "core/checkpoint.h"

#include <mpi.h>

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
    /// The MPI ranks the case runs on (CaseParameters::ranks); all of them call run_case(),
    /// the first writes.
    MPI_Comm ranks = MPI_COMM_SELF;
  };

  /// Run (or only check) a case; returns the process exit code. Input errors
  /// are thrown as InputError before anything is written.
  int run_case(const RunOptions &options);

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
