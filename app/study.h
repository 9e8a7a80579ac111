#pragma once
/// @file `tribo study STUDY.prm`: every combination of lists of parameter values
/// run as cases of one base case, one case per MPI rank at a time (or one after
/// another without mpirun), resumable, summarised in one table.
///
/// A study file:
///
///     subsection Study
///       set Base case  = ../shear/default.prm     # relative to the study file
///       set Parameters = Contact law/Cohesion = 0, 60, 120; Contact law/Law = IQS, ELAS
///       set Fixed      = Simulation/End time = 4e-5; Output/Plots = false
///     end
///
/// Cases are numbered in the order of the Cartesian product (the last list varies
/// fastest) and written to OUTPUT/case_NNN/. A case whose summary.json says
/// "complete" and whose study.prm holds the same overrides is not run again, so a
/// study interrupted at any point resumes where it stopped and never mixes results
/// of different parameter sets. A failed case is a row with its status and error;
/// the others go on. OUTPUT/study_summary.csv and .md hold one row per case.

#include <string>

namespace tribo::app
{
  struct StudyOptions
  {
    std::string study_file;
    std::string output_dir; ///< empty: output/<study file stem>
    bool        quiet = false;
  };

  /// Run a study; returns the exit code (0 even if some cases failed: see the table).
  int run_study(const StudyOptions &options);
} // namespace tribo::app
