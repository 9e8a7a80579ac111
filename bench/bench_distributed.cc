// The contact solve of one step across MPI ranks (dem/parallel/): how many more sweeps the
// coupling across ranks takes than the same sweeps on one rank, and the time per sweep, for
// the Gauss-Seidel sweeps in velocity form and APGS's in operator form, with and without momentum.
// Every rank runs the same serial trajectory of CASE for STEPS steps (no distributed
// engine yet), then takes the last step's own problem (its free velocities: the end
// velocities less the impulses' effect), warm-started as the engine does (each contact from
// its impulse of the step before) or cold, splits it into bands and solves it on all ranks,
// and on one rank, to each target. docs/scaling.md records it.
// With two ranks it first measures a ping-pong between them (the latency and bandwidth that
// scripts/scaling_model.py takes).
// Usage: mpirun -np N bench_distributed [CASE.prm] [STEPS] [--set "Section/Entry=value"]...
#include "bench/bench_case.h"
#include "dem/parallel/distributed_apgs.h"
#include "dem/parallel/distributed_gauss_seidel.h"
#include "dem/laws/law_residual.h"
#include "dem/solvers/contact_solver.h"

#include <deal.II/base/mpi.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <map>
#include <cstdio>
#include <string>
#include <vector>

using namespace tribo;
using Clock = std::chrono::steady_clock;

int main(int argc, char **argv)
{
  dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  const MPI_Comm     world = MPI_COMM_WORLD;
  const unsigned int rank = dealii::Utilities::MPI::this_mpi_process(world);
  const unsigned int n    = dealii::Utilities::MPI::n_mpi_processes(world);
  if (n == 2)
    for (const std::size_t bytes : {std::size_t(8), std::size_t(1) << 16})
      {
        // Half the round trip of a message of @p bytes, the best of 5 batches of 1000.
        std::vector<char> buffer(bytes);
        double            best = 1e300;
        for (int batch = 0; batch < 5; ++batch)
          {
            MPI_Barrier(world);
            const auto t0 = Clock::now();
            for (int i = 0; i < 1000; ++i)
              if (rank == 0)
                {
                  MPI_Send(buffer.data(), int(bytes), MPI_CHAR, 1, 0, world);
                  MPI_Recv(buffer.data(), int(bytes), MPI_CHAR, 1, 0, world, MPI_STATUS_IGNORE);
                }
              else
                {
                  MPI_Recv(buffer.data(), int(bytes), MPI_CHAR, 0, 0, world, MPI_STATUS_IGNORE);
                  MPI_Send(buffer.data(), int(bytes), MPI_CHAR, 0, 0, world);
                }
            best = std::min(best, std::chrono::duration<double>(Clock::now() - t0).count() / 2000);
          }
        if (rank == 0)
          std::printf("ping-pong: %zu bytes in %.2f us one way (%.2f GB/s)\n", bytes, 1e6 * best, bytes / best / 1e9);
      }
  bench::BenchCase bench_case(argc, argv, "cases/shear/reference_bench_sample.prm");
  const std::string case_file = bench_case.case_file("cases/shear/reference_bench_sample.prm");
  const unsigned    steps     = bench_case.count(1, 50);
  const app::CaseParameters &p      = bench_case.parameters;
  dem::ParticleSystem       &system = bench_case.system;
  const double               h      = bench_case.h;
  dem::MoreauJean           &mj     = *bench_case.integrator;
  app::NscdWorld             nscd{system};
  std::map<std::uint64_t, Eigen::Vector2d> before_last;
  for (unsigned s = 0; s < steps; ++s)
    {
      if (s + 1 == steps)
        for (const auto &c : mj.contacts())
          before_last[c.key()] = c.r;
      nscd.step = s;
      bench_case.scene->before_step(nscd);
      mj.step(system, h);
    }
  // The last step's problem: its free velocities, its contacts cold.
  std::vector<dem::Contact> contacts = mj.contacts();
  dem::BodyState            free     = dem::BodyState::of(system);
  for (auto &c : contacts)
    {
      free.apply_impulse(c, -c.r);
      c.r.setZero();
    }
  // Warm-started: the impulses of the step before, their effect in the state.
  std::vector<dem::Contact> warm_contacts = contacts;
  dem::BodyState            warm          = free;
  for (auto &c : warm_contacts)
    if (const auto it = before_last.find(c.key()); it != before_last.end())
      {
        c.r = it->second;
        warm.apply_impulse(c, c.r);
      }
  if (rank == 0)
    std::printf("case %s after %u steps: %zu discs, %zu contacts, %u ranks\n", case_file.c_str(), steps,
                system.discs.size(), contacts.size(), n);

  for (const bool warm_start : {true, false})
    for (const double target : {1e-3, 1e-4})
      {
        const auto &problem = warm_start ? warm_contacts : contacts;
        const auto &state   = warm_start ? warm : free;
        // The distributed solve on @p comm's ranks, in APGS's operator form or not, with or
        // without momentum: its report, the slowest rank's time and the ghosts on all ranks.
        auto solve_on = [&](MPI_Comm comm, bool operator_form, bool momentum) {
          const unsigned int         ranks = dealii::Utilities::MPI::n_mpi_processes(comm);
          dem::parallel::RankProblem share =
            dem::parallel::share_of(system, problem, free, dem::parallel::contact_bands(system, problem, ranks),
                                    dealii::Utilities::MPI::this_mpi_process(comm));
          dem::parallel::DistributedControls controls;
          controls.residual_target = target;
          controls.max_sweeps      = 200000;
          controls.momentum        = momentum;
          dem::parallel::DistributedGaussSeidel gauss_seidel(share, comm);
          dem::parallel::DistributedApgs        apgs_form(share, comm);
          dem::parallel::DistributedSolver     &solver = operator_form
                                                            ? static_cast<dem::parallel::DistributedSolver &>(apgs_form)
                                                            : gauss_seidel;
          dem::parallel::DistributedReport      warm_exchange;
          solver.add_impulses(share, warm_exchange); // every rank's warm start on the free state
          MPI_Barrier(comm);
          const auto   t0     = Clock::now();
          const auto   report = solver.solve(share, mj.law(), controls, p.theta * h);
          const double t      = std::chrono::duration<double>(Clock::now() - t0).count();
          return std::make_tuple(report, dealii::Utilities::MPI::max(t, comm),
                                 dealii::Utilities::MPI::sum(double(share.n_ghost), comm));
        };
        // Rank 0's counters per sweep.
        auto traffic = [](const dem::parallel::DistributedReport &r) {
          return std::make_tuple(double(r.bytes_sent) / r.sweeps, double(r.exchanges) / r.sweeps,
                                 double(r.reductions) / r.sweeps, r.neighbours);
        };
        // The engine's serial APGS on one core, to the same law residual.
        dem::SolverParameters apgs = p.solver;
        apgs.method                = dem::SolverParameters::Method::apgs;
        apgs.residual_target       = target;
        apgs.threads               = 1;
        std::vector<dem::Contact> apgs_contacts = problem;
        dem::BodyState            apgs_state    = state;
        const auto                t0            = Clock::now();
        const auto apgs_report = dem::make_contact_solver(apgs)->solve(apgs_contacts, apgs_state, mj.law(), p.theta * h);
        const double apgs_time = std::chrono::duration<double>(Clock::now() - t0).count();
        // The engine takes the law residual after the solve (MoreauJean::assess_solve): so here.
        const double apgs_residual = dem::law_residual(apgs_contacts, apgs_state, mj.law(), p.theta * h).relative;
        for (const bool operator_form : {false, true})
        for (const bool momentum : {false, true})
          {
            const auto [serial, serial_time, unused] = solve_on(MPI_COMM_SELF, operator_form, momentum);
            const auto [here, here_time, ghosts]     = solve_on(world, operator_form, momentum);
            (void)unused;
            const auto [bytes, exchanges, reductions, neighbours] = traffic(here);
            if (rank == 0 && n > 1)
              std::printf("  rank 0 per sweep: %.0f bytes sent, %.2f exchanges with %u neighbours, %.2f sums over the ranks\n",
                          bytes, exchanges, neighbours, reductions);
            if (rank == 0)
              std::printf("%s, target %g, %s %s: %u ranks %u sweeps (law residual %.2e) in %.4f s, one rank %u sweeps "
                          "in %.4f s (sweeps x %.3f, T1 / (N TN) %.2f), %.0f ghosts; APGS one core %u iterations "
                          "in %.4f s (law residual %.2e)\n",
                          warm_start ? "warm" : "cold", target, operator_form ? "APGS sweeps" : "Gauss-Seidel",
                          momentum ? "momentum" : "plain", n, here.sweeps,
                          here.law_residual, here_time, serial.sweeps, serial_time,
                          double(here.sweeps) / serial.sweeps, serial_time / (n * here_time), ghosts,
                          apgs_report.iterations, apgs_time, apgs_residual);
          }
      }
  return 0;
}
