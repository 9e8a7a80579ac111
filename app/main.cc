// tribo: the command-line front end.
#include "app/run.h"
#include "app/sample_file.h"
#include "app/study.h"
#include "core/errors.h"

#include <deal.II/base/mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

namespace
{
  const char *usage = R"(tribo: third-body tribology simulations (NSCD discs; rigid, deal.II, SPH and MLP first bodies; SPH and MLP scenes)

Usage:
  tribo run CASE.prm [--output DIR] [--set "Subsection/Entry=value" ...] [--quiet]
      Run a case; outputs go to DIR (default output/<case name>), see docs/outputs.md.
  mpirun -np N tribo run CASE.prm ...
      One disc case on N ranks: each step's contact solve split into N horizontal bands
      (Solver/Method = apgs or nlgs); rank 0 writes (docs/scaling.md).
  tribo run CASE.prm --resume DIR [--set ...] [--quiet]
      Continue the run in DIR from its checkpoint.bin (Output/Checkpoint interval); only
      Solver/*, Output/*, Simulation/End time, Simulation/Most substeps, Simulation/Most
      substeps on retake and Shear cell/Upper body prediction depth may differ from the
      checkpointed run.
  tribo check CASE.prm [--set ...]
      Read and validate a case without running it.
  tribo study STUDY.prm [--output DIR] [--quiet]
      Run every combination of a study (app/study.h); in parallel with mpirun -np N.
  tribo tradeoff STUDY.prm [--output DIR] [--quiet]
      A study with Design = tradeoff: ladders of settings, cost and error against the
      reference in tradeoff.csv/.md/.png (docs/tradeoff.md).
  tribo sample DIR [--time T] > sample.csv
      Print a shear run's snapshot (the one nearest T s, else the last) as a sample file
      that Shear cell/Sample file takes (docs/outputs.md, "Sample files").
  tribo params
      Print every parameter with its default, allowed values and unit: a case to start from.
  tribo --help | --version

Exit codes: 0 success, 1 the run failed, 2 bad input, 128+N interrupted by signal N.
)";

  [[noreturn]] void usage_error(const std::string &message)
  {
    throw tribo::InputError(message + " (see `tribo --help`)");
  }

  /// The number of processes mpirun started this one among (Open MPI's and MPICH's
  /// launchers say so in the environment), 1 without a launcher.
  int launched_ranks()
  {
    for (const char *name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"})
      if (const char *value = std::getenv(name))
        return std::max(1, std::atoi(value));
    return 1;
  }

  /// This process's rank among them (0 without a launcher): only the first reports errors.
  int launched_rank()
  {
    for (const char *name : {"OMPI_COMM_WORLD_RANK", "PMI_RANK"})
      if (const char *value = std::getenv(name))
        return std::atoi(value);
    return 0;
  }
} // namespace

int main(int argc, char **argv)
{
  try
    {
      std::vector<std::string> args(argv + 1, argv + argc);
      if (args.empty() || args[0] == "--help" || args[0] == "-h" || args[0] == "help")
        {
          std::cout << usage;
          return args.empty() ? tribo::exit_input_error : tribo::exit_ok;
        }
      if (args[0] == "--version")
        {
          std::cout << "tribo " << TRIBO_VERSION << std::endl;
          return tribo::exit_ok;
        }
      if (args[0] == "params")
        {
          if (args.size() > 1)
            usage_error("'tribo params' takes no arguments");
          std::cout << tribo::app::parameter_reference();
          return tribo::exit_ok;
        }
      if (args[0] == "sample")
        {
          std::string dir;
          double      time = NAN;
          for (std::size_t i = 1; i < args.size(); ++i)
            {
              if (args[i] == "--time")
                {
                  if (i + 1 >= args.size())
                    usage_error("--time needs a value (a time in s)");
                  const std::string &v = args[++i];
                  std::size_t        used = 0;
                  try
                    {
                      time = std::stod(v, &used);
                    }
                  catch (const std::exception &)
                    {
                      used = 0;
                    }
                  if (used != v.size() || v.empty() || !std::isfinite(time))
                    usage_error("--time '" + v + "': expected a time in s");
                }
              else if (!args[i].empty() && args[i][0] == '-')
                usage_error("unknown option '" + args[i] + "' for 'tribo sample'");
              else if (dir.empty())
                dir = args[i];
              else
                usage_error("more than one run directory");
            }
          if (dir.empty())
            usage_error("'tribo sample' needs a run directory");
          const tribo::app::SampleSnapshot s = tribo::app::sample_snapshot(dir, time);
          std::cerr << "tribo sample: " << s.path << " (t = " << s.time << " s)" << std::endl;
          std::cout << s.text;
          return tribo::exit_ok;
        }
      if (args[0] == "study" || args[0] == "tradeoff")
        {
          tribo::app::StudyOptions s;
          s.require_tradeoff = args[0] == "tradeoff";
          for (std::size_t i = 1; i < args.size(); ++i)
            {
              if (args[i] == "--output" && i + 1 < args.size())
                s.output_dir = args[++i];
              else if (args[i] == "--quiet")
                s.quiet = true;
              else if (!args[i].empty() && args[i][0] == '-')
                usage_error("unknown option '" + args[i] + "' for 'tribo " + args[0] + "'");
              else if (s.study_file.empty())
                s.study_file = args[i];
              else
                usage_error("more than one study file");
            }
          if (s.study_file.empty())
            usage_error("'tribo " + args[0] + "' needs a study file");
          // TBB threads (the deal.II body's loops): the node's cores shared among the ranks, so that a
          // case of a serial study runs as `tribo run` does.
          dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv);
          return tribo::app::run_study(s);
        }
      if (args[0] != "run" && args[0] != "check")
        usage_error("unknown command '" + args[0] + "'");

      tribo::app::RunOptions o;
      o.check_only = args[0] == "check";
      for (std::size_t i = 1; i < args.size(); ++i)
        {
          const std::string &a = args[i];
          if (a == "--output" || a == "--set" || a == "--resume")
            {
              if (i + 1 >= args.size())
                usage_error(a + " needs a value");
              (a == "--output" ? o.output_dir : a == "--resume" ? o.resume_dir : o.overrides.emplace_back()) = args[++i];
            }
          else if (a == "--quiet")
            o.quiet = true;
          else if (!a.empty() && a[0] == '-')
            usage_error("unknown option '" + a + "'");
          else if (o.case_file.empty())
            o.case_file = a;
          else
            usage_error("more than one case file ('" + o.case_file + "', '" + a + "')");
        }
      if (o.case_file.empty())
        usage_error("'tribo " + args[0] + "' needs a case file");
      if (launched_ranks() > 1 && !o.check_only)
        {
          // One case on every rank: its contacts split over them (docs/scaling.md).
          dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv);
          o.ranks = MPI_COMM_WORLD;
          return tribo::app::run_case(o);
        }
      return tribo::app::run_case(o);
    }
  catch (const tribo::InputError &e)
    {
      if (launched_rank() == 0)
        std::cerr << "error: " << e.what() << std::endl;
      return tribo::exit_input_error;
    }
  catch (const std::exception &e)
    {
      if (launched_rank() == 0)
        std::cerr << "error: " << e.what() << std::endl;
      return tribo::exit_run_error;
    }
}
