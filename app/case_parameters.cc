#include "app/case_parameters.h"

#include "core/errors.h"

#include <deal.II/base/mpi.h>

#include <cmath>

namespace tribo::app
{
  unsigned int rank_count(MPI_Comm ranks)
  {
    return dealii::Utilities::MPI::job_supports_mpi() ? dealii::Utilities::MPI::n_mpi_processes(ranks) : 1;
  }

  unsigned int rank_in(MPI_Comm ranks)
  {
    return dealii::Utilities::MPI::job_supports_mpi() ? dealii::Utilities::MPI::this_mpi_process(ranks) : 0;
  }

  using dealii::Patterns::Bool;
  using dealii::Patterns::Double;
  using dealii::Patterns::Integer;

  void declare_common_parameters(dealii::ParameterHandler &prm)
  {
    prm.enter_subsection("Simulation");
    prm.declare_entry("Time step", "1e-9", Double(), "Time step h, s (> 0).");
    prm.declare_entry("End time", "1e-6", Double(), "Simulated time, s (> 0).");
    prm.declare_entry("Theta", "0.5", Double(0.5, 1.0),
                      "Moreau-Jean theta, in [0.5, 1]: 0.5 is the midpoint rule, 1 is implicit Euler.");
    prm.declare_entry("Most substeps", "1", Integer(1),
                      "Disc scenes with rigid first bodies: a step whose fastest body would move more than a "
                      "quarter of the smallest radius at its speed at the step's start is taken as k equal "
                      "sub-steps, k = ceil(h v_max / (r_min / 4)), at most this many (>= 1; 1: never). A grain "
                      "a solve launched is then stopped by its neighbours before the explicit half step "
                      "carries it into them (docs/laws.md).");
    prm.declare_entry("Most substeps on retake", "64", Integer(1),
                      "Disc scenes with rigid first bodies: a step whose motion carried a body into another past "
                      "the smallest radius, or a disc farther than contact detection foresaw, is taken again from "
                      "its start as k equal sub-steps, k = ceil(h v / (r_min / 4)) with v that body's larger "
                      "speed, at most this many (>= 1; 1: never, the run stops at such an overlap). Only such "
                      "steps pay (docs/laws.md).");
    prm.leave_subsection();

    prm.enter_subsection("Contact law");
    dem::ContactLaw::declare(prm);
    prm.leave_subsection();

    prm.enter_subsection("Solver");
    dem::SolverParameters::declare(prm);
    prm.leave_subsection();

    prm.enter_subsection("Output");
    prm.declare_entry("Statistics interval", "1", Integer(1), "Steps between rows of statistics.csv, >= 1.");
    prm.declare_entry("Field interval", "0", Integer(0),
                      "Steps between VTU snapshots in fields/; 0 writes only the first and the last.");
    prm.declare_entry("Checkpoint interval", "600", Double(0),
                      "Wall-clock seconds between checkpoints (checkpoint.bin in the output directory, "
                      "for `tribo run CASE.prm --resume DIR`); 0: none on a timer. An interrupted run "
                      "(SIGINT, SIGTERM) also writes one.");
    prm.declare_entry("Checkpoint step interval", "0", Integer(0),
                      "Steps between checkpoints, in addition to the timer; 0: none.");
    prm.declare_entry("Plots", "true", Bool(),
                      "Write PNG plots (mu.png, power.png, profiles.png) of a shear run with "
                      "scripts/plot_run.py (Debian's python3-matplotlib).");
    prm.leave_subsection();

  }

  CaseParameters read_case_parameters(const ParameterFile &f)
  {

    CaseParameters p;
    p.scene     = f.get("Simulation/Scene");
    p.time_step = f.get_checked("Simulation/Time step", is_positive, "a positive time step in s");
    p.end_time  = f.get_checked("Simulation/End time", is_positive, "a positive end time in s");
    p.theta     = f.get_double("Simulation/Theta");
    p.most_substeps = f.get_integer("Simulation/Most substeps");
    p.most_retake_substeps = f.get_integer("Simulation/Most substeps on retake");

    p.law    = dem::ContactLaw::parse(f, "Contact law");
    p.solver = dem::SolverParameters::parse(f, "Solver");

    p.statistics_interval = f.get_integer("Output/Statistics interval");
    p.field_interval      = f.get_integer("Output/Field interval");
    p.plots               = f.get_bool("Output/Plots");
    p.checkpoint_interval      = f.get_double("Output/Checkpoint interval");
    p.checkpoint_step_interval = f.get_integer("Output/Checkpoint step interval");

    return p;
  }

} // namespace tribo::app
