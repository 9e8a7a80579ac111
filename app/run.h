#pragma once
/// @file `tribo run` and `tribo check`: read a case, build its scene, step it,
/// and write the output directory (docs/outputs.md).

#include <string>
#include <vector>

namespace tribo::app
{
  struct RunOptions
  {
    std::string              case_file;
    std::string              output_dir; ///< empty: output/<case file stem>
    std::vector<std::string> overrides;  ///< "Subsection/Entry=value"
    bool                     quiet      = false;
    bool                     check_only = false;
  };

  /// Run (or only check) a case; returns the process exit code. Input errors
  /// are thrown as InputError before anything is written.
  int run_case(const RunOptions &options);

  /// The full documented parameter tree with defaults (`tribo params`).
  std::string parameter_reference();
} // namespace tribo::app
