#pragma once
/// @file The parameters of a case: declaration (with patterns, defaults and
/// units) and validated reading into plain structs.

#include "core/parameter_file.h"
#include "dem/laws/contact_law.h"
#include "dem/solvers/contact_solver.h"

#include <deal.II/base/parameter_handler.h>

#include <mpi.h>

#include <string>

namespace tribo::app
{
  /// The entries every case has: Simulation, Contact law, Solver and Output. A scene's
  /// own subsection is its own (app/scenes.h: declared, checked and read by its file).
  struct CaseParameters
  {
    std::string scene;
    double      time_step;
    double      end_time;
    double      theta;
    unsigned int most_substeps; ///< Simulation/Most substeps (dem::MoreauJean::allow_substeps)
    unsigned int most_retake_substeps; ///< Simulation/Most substeps on retake (dem::MoreauJean::allow_retakes)
    dem::ContactLaw     law;
    dem::SolverParameters solver;
    unsigned int statistics_interval; ///< steps between rows of statistics.csv
    unsigned int field_interval;      ///< steps between VTU snapshots (0: first and last)
    bool         plots;               ///< PNG plots of a shear run (scripts/plot_run.py)
    double       checkpoint_interval;      ///< wall-clock seconds between checkpoints (0: none)
    unsigned int checkpoint_step_interval; ///< steps between checkpoints (0: none)
    /// The MPI ranks the case runs on, not an entry: `tribo run` under mpirun runs one case on
    /// all of them (its contact solve split into bands, dem/parallel/solve_across_ranks.h); a
    /// case of `tribo study` runs on its own rank.
    MPI_Comm ranks = MPI_COMM_SELF;
  };

  /// The number of ranks of @p ranks, 1 when MPI is not initialised (`tribo run` without mpirun).
  unsigned int rank_count(MPI_Comm ranks);
  /// This process's rank in @p ranks, 0 when MPI is not initialised.
  unsigned int rank_in(MPI_Comm ranks);

  /// Declare the entries every case has (Simulation, Contact law, Solver, Output): the
  /// part of declare_case_parameters() (app/scenes.h) that is not a scene's.
  void declare_common_parameters(dealii::ParameterHandler &prm);

  /// Read and check a parsed case's common entries (not the scene's own, which its row
  /// checks: app/scenes.h); InputError names the entry and what was expected.
  CaseParameters read_case_parameters(const ParameterFile &file);
} // namespace tribo::app
