// NLGS throughput on a dense packing: compacts a case (default
// cases/shear/bench.prm, ~3000 discs at 100 MPa), then times
//  (1) fixed sweeps over the frozen contact set: contact updates per second;
//  (2) full steps at the case's tolerance: sweeps, contacts and wall time per step, split
//      into detection, NLGS and the rest (free state, local problems, update);
//  and the resident memory the packing added, per disc.
// Usage: bench_nlgs [CASE.prm] [compaction steps] [timed steps] [--set "Section/Entry=value"]...
// (bench/nlgs_scaling.sh runs it on 1k to 64k discs.)
#include "bench/bench_case.h"

#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

using namespace tribo;
using Clock = std::chrono::steady_clock;

namespace
{
  double seconds_since(Clock::time_point t0)
  {
    return std::chrono::duration<double>(Clock::now() - t0).count();
  }

  /// Resident memory of the process now, MB (/proc/self/status VmRSS).
  double resident_mb()
  {
    std::ifstream in("/proc/self/status");
    std::string   key;
    double        kib = 0;
    while (in >> key)
      if (key == "VmRSS:" && in >> kib)
        break;
    return kib / 1024.0;
  }
} // namespace

int main(int argc, char **argv)
{
  const double     memory_before = resident_mb();
  bench::BenchCase bench_case(argc, argv, "cases/shear/bench.prm");
  const std::string case_file     = bench_case.case_file("cases/shear/bench.prm");
  const unsigned    compact_steps = bench_case.count(1, 3000);
  const unsigned    timed_steps   = bench_case.count(2, 100);
  const app::CaseParameters &p      = bench_case.parameters;
  auto                      &scene  = bench_case.scene;
  dem::ParticleSystem       &system = bench_case.system;
  const double               h      = bench_case.h;
  dem::MoreauJean           &mj     = *bench_case.integrator;

  std::printf("case %s: %zu discs, h = %g s\n", case_file.c_str(), system.discs.size(), h);
  app::NscdWorld world{system};
  auto t0 = Clock::now();
  for (unsigned s = 0; s < compact_steps; ++s)
    {
      world.step = s;
      scene->before_step(world);
      mj.step(system, h);
    }
  std::printf("compaction: %u steps in %.2f s\n", compact_steps, seconds_since(t0));

  // (2) steps at the case's tolerance (warm-started, as in a run).
  const double  memory_per_disc = 1e6 * (resident_mb() - memory_before) / system.discs.size();
  unsigned long sweeps = 0, contacts = 0, active = 0;
  double        detection = 0, solver_time = 0, step_total = 0;
  t0 = Clock::now();
  for (unsigned s = 0; s < timed_steps; ++s)
    {
      world.step = compact_steps + s;
      scene->before_step(world);
      const auto r = mj.step(system, h);
      sweeps += r.solver.iterations;
      contacts += r.n_contacts;
      active += r.n_active;
      detection += r.time_detection;
      solver_time += r.time_solver;
      step_total += r.time_step;
    }
  const double step_time = seconds_since(t0) / timed_steps;
  std::printf("steps at tol %g (%s, check every %u): %.4f s per step, %.1f sweeps, %.0f contacts "
              "(%.0f active) per step\n",
              p.solver.tolerance, p.solver.norm == dem::SolverParameters::Norm::quad ? "Quad" : "Maxm",
              p.solver.check_interval, step_time, double(sweeps) / timed_steps,
              double(contacts) / timed_steps, double(active) / timed_steps);
  std::printf("per step: detection %.3f ms, NLGS %.3f ms, rest (free state, local problems, "
              "update) %.3f ms; per disc: detection %.1f ns, rest %.1f ns\n",
              1e3 * detection / timed_steps, 1e3 * solver_time / timed_steps,
              1e3 * (step_total - detection - solver_time) / timed_steps,
              1e9 * detection / timed_steps / system.discs.size(),
              1e9 * (step_total - detection - solver_time) / timed_steps / system.discs.size());
  std::printf("memory: %.0f bytes per disc (resident growth after compaction, %.1f MB in all)\n",
              memory_per_disc, resident_mb() - memory_before);

  // (1) fixed sweeps on the last step's contacts, from their converged impulses.
  std::vector<dem::Contact> frozen = mj.contacts();
  dem::BodyState            state  = dem::BodyState::of(system);
  dem::SolverParameters fixed = p.solver;
  fixed.tolerance           = 1e-300; // never converges: exactly max_iterations sweeps
  fixed.max_iterations      = 200;
  fixed.check_interval      = 1000000;
  dem::NlgsSolver solver(fixed);
  t0 = Clock::now();
  const auto   rep     = solver.solve(frozen, state, mj.law());
  const double elapsed = seconds_since(t0);
  const double updates = double(rep.iterations + rep.check_passes) * frozen.size();
  std::printf("NLGS: %u sweeps over %zu contacts in %.3f s: %.3g contact updates per second "
              "(%.1f ns per update)\n",
              rep.iterations, frozen.size(), elapsed, updates / elapsed, 1e9 * elapsed / updates);

  // The same sweeps in 1, 2, 4 and 8 interleaved streams (Solver/Streams), each from
  // the converged impulses, three rounds in turn: the least cost per update of each
  // (single timings on this shared machine scatter by up to 30 %).
  const std::vector<unsigned int> stream_counts = {1, 2, 4, 8};
  std::vector<double>             best(stream_counts.size(), 1e300);
  for (unsigned int round = 0; round < 3; ++round)
    for (std::size_t k = 0; k < stream_counts.size(); ++k)
      {
        std::vector<dem::Contact> copy = mj.contacts();
        dem::BodyState            s    = dem::BodyState::of(system);
        fixed.streams                  = stream_counts[k];
        dem::NlgsSolver sweeper(fixed);
        t0                   = Clock::now();
        const auto   r       = sweeper.solve(copy, s, mj.law());
        const double seconds = seconds_since(t0);
        best[k] = std::min(best[k], 1e9 * seconds / (double(r.iterations + r.check_passes) * copy.size()));
      }
  std::printf("streams (least of 3):");
  for (std::size_t k = 0; k < stream_counts.size(); ++k)
    std::printf(" %u: %.1f ns", stream_counts[k], best[k]);
  std::printf(" per update\n");
  return 0;
}
