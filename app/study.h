#pragma once
/// @file `tribo study STUDY.prm`: every combination of lists of parameter values
/// run as cases of one base case, one case per MPI rank at a time (or one after
/// another without mpirun), resumable, summarised in one table. With more ranks than
/// cases (and no tradeoff design), each case runs on a group of ranks, its contact solve
/// split over them (docs/scaling.md), when every case can be split (Solver/Method = apgs or
/// nlgs, a disc scene); otherwise one rank per case still.
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
///
/// Shear cases that differ only in entries acting after Shear start (End time, Sliding
/// velocity, Profile samples, Layer thickness, Output/*, and `set Shear-phase entries =
/// ...`) share their compaction: each distinct one runs once as OUTPUT/preparation_NNN/
/// (End time = Shear start) and the cases shear from its state (Shear cell/Initial
/// state); `set Share compaction = false` turns this off (docs/outputs.md, "Studies").
///
/// With `set Design = tradeoff` the Parameters lists are ladders of the knobs that cost
/// time (time step, tolerance, mesh, model, ...): case 0 is the Reference (the finest
/// setting, `set Reference = Solver/Tolerance = 1e-5; ...`), then each ladder is run
/// alone from the base case. scripts/tradeoff.py then writes tradeoff.csv, tradeoff.md
/// and tradeoff.png: the cost (wall time per simulated time) and the error against the
/// reference in what users read (docs/tradeoff.md).

#include <string>

namespace tribo::app
{
  struct StudyOptions
  {
    std::string study_file;
    std::string output_dir; ///< empty: output/<study file stem>
    bool        quiet = false;
    /// `tribo tradeoff`: the file must have Design = tradeoff.
    bool        require_tradeoff = false;
  };

  /// Run a study; returns the exit code (0 even if some cases failed: see the table).
  int run_study(const StudyOptions &options);
} // namespace tribo::app
