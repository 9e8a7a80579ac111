// A step's own error: a shear case runs with its solver, and every EVERY-th step the same
// contact problem (the same contacts, warm-start impulses and free velocities) is also solved
// by a reference solver, whose answer is dropped. The contact impulse on the bodies of imposed
// velocity (the lower wall) of the two solves is compared on the same state:
//     d = P(case's solve) - P(reference)   (N s/m; P_x over P L h is the step's mu).
// This is the error of one step from the state the run reached, not the run's error on mu: a
// loose solve leaves part of each step's load unpaid, the state carries that debt, and the
// reference pays it at once (docs/performance.md, "A step's own error is not mu's").
//
// Usage: bench_shadow CASE.prm STEPS EVERY [--set "Section/Entry=value"]...
//            [--reference "Section/Entry=value"]...
// --reference entries change the reference's Solver subsection only (default: APGS at a law
// residual of 1e-8 from the case's warm start; the interior point's crossover fails from
// another method's iterate). Skips the first step (no warm start after an initial state).
// Prints the mean impulse of the reference, the mean difference relative to it with its
// standard error (batch means over 10 batches), the mean law residuals of both, and the case's
// solve's time per step.
#include "bench/bench_case.h"

#include "app/steady_state.h"

#include "dem/laws/law_residual.h"
#include "dem/solvers/methods.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

using namespace tribo;
using Clock = std::chrono::steady_clock;

namespace
{
  /// (P_x, P_y) of the contacts' impulses on the bodies of imposed velocity (zero inverse
  /// mass in every dof: the lower wall), N s/m. Side s of a contact takes
  /// sign_s (r_n n + r_t t), sign_0 = -1, sign_1 = +1 (dem/linalg/delassus.cc).
  Eigen::Vector2d driver_impulse(const std::vector<dem::Contact> &contacts, const dem::BodyState &state)
  {
    Eigen::Vector2d p = Eigen::Vector2d::Zero();
    for (const dem::Contact &c : contacts)
      for (int s = c.on_boundary() ? 1 : 0; s < 2; ++s)
        {
          const auto &m = state.inverse_mass[c.body[s]];
          if (m[0] != 0 || m[1] != 0 || m[2] != 0)
            continue;
          const Eigen::Vector2d n(c.normal.x(), c.normal.y()), t(-c.normal.y(), c.normal.x());
          p += (s == 0 ? -1.0 : 1.0) * (c.r[0] * n + c.r[1] * t);
        }
    return p;
  }

  /// The case's solver, and every `every`-th call the reference on a copy of the problem.
  class Shadowed : public dem::ContactSolver
  {
  public:
    struct Sample
    {
      Eigen::Vector2d solved, reference;
      double          residual, reference_residual;
    };

    Shadowed(const dem::SolverParameters &p, const dem::SolverParameters &reference_prm, unsigned int every)
      : ContactSolver(p)
      , solver(dem::make_contact_solver(p))
      , reference(dem::make_contact_solver(reference_prm))
      , every(every)
    {}
    dem::SolveReport solve(std::vector<dem::Contact> &contacts, dem::BodyState &state, const dem::ContactLaw &law,
                           double theta_h) override
    {
      const bool                shadow = !contacts.empty() && ++calls % every == 0; // not the first step
      std::vector<dem::Contact> ref_contacts;
      dem::BodyState            ref_state;
      if (shadow)
        {
          ref_contacts = contacts;
          ref_state    = state;
        }
      const auto       t0     = Clock::now();
      dem::SolveReport report = solver->solve(contacts, state, law, theta_h);
      solve_seconds += std::chrono::duration<double>(Clock::now() - t0).count();
      ++solves;
      if (shadow)
        {
          reference->solve(ref_contacts, ref_state, law, theta_h);
          samples.push_back({driver_impulse(contacts, state), driver_impulse(ref_contacts, ref_state),
                             dem::law_residual(contacts, state, law, theta_h).relative,
                             dem::law_residual(ref_contacts, ref_state, law, theta_h).relative});
        }
      return report;
    }
    bool        solves_friction() const override { return solver->solves_friction(); }
    std::string random_state() const override { return solver->random_state(); }
    void        set_random_state(const std::string &s) override { solver->set_random_state(s); }

    std::vector<Sample> samples;
    double              solve_seconds = 0;
    unsigned long       solves        = 0;

  private:
    std::unique_ptr<dem::ContactSolver> solver, reference;
    unsigned int                        every;
    unsigned long                       calls = 0;
  };

  /// Mean and standard error of @p x by batch means (app/steady_state.h, 10 batches).
  std::pair<double, double> mean_and_error(const std::vector<double> &x)
  {
    if (x.size() < 2 * app::standard_error_batches)
      throw std::runtime_error("fewer than 20 shadow solves: run more steps");
    const std::vector<double> means = app::batch_means(x);
    double                    mean  = 0;
    for (const double m : means)
      mean += m / double(means.size());
    return {mean, app::batch_standard_error(means)};
  }
} // namespace

int main(int argc, char **argv)
{
  // --reference entries are taken out before BenchCase sees the command line.
  std::vector<char *>      args;
  std::vector<std::string> reference_entries = {"Solver/Method=apgs", "Solver/Residual target=1e-8",
                                                "Solver/Maximum iterations=1000000"};
  for (int i = 0; i < argc; ++i)
    if (std::string(argv[i]) == "--reference" && i + 1 < argc)
      reference_entries.push_back(argv[++i]);
    else
      args.push_back(argv[i]);
  bench::BenchCase bench_case(int(args.size()), args.data(), "cases/shear/reference_bench_sample.prm");
  const unsigned long steps = bench_case.count(1, 1000);
  const unsigned int  every = static_cast<unsigned int>(bench_case.count(2, 10));

  // The gap tolerance and target relative to the smallest radius, as a run sets them (app/nscd_simulation.cc).
  const auto with_gaps = [&](dem::SolverParameters s) {
    s.gap_tolerance = s.relative_gap_tolerance * bench_case.system.min_radius();
    s.gap_target    = s.relative_gap_target * bench_case.system.min_radius();
    return s;
  };
  const dem::SolverParameters case_prm = with_gaps(bench_case.parameters.solver);
  for (const auto &e : reference_entries)
    bench_case.file.set(e);
  const dem::SolverParameters reference_prm = with_gaps(dem::SolverParameters::parse(bench_case.file, "Solver"));

  dem::MoreauJean &mj       = *bench_case.integrator;
  auto             shadowed = std::make_unique<Shadowed>(case_prm, reference_prm, every);
  Shadowed        &shadow   = *shadowed;
  mj.use_solver(std::move(shadowed));
  bench_case.scene->attach(mj);

  app::NscdWorld      world{bench_case.system};
  world.integrator            = &mj;
  const unsigned long first   = std::lround(bench_case.scene->start_time() / bench_case.h);
  const auto          t0      = Clock::now();
  for (unsigned long s = first; s < first + steps; ++s)
    {
      world.step = s;
      bench_case.scene->before_step(world);
      world.report = mj.step(bench_case.system, bench_case.h);
      bench_case.scene->after_step(world);
    }
  const double wall = std::chrono::duration<double>(Clock::now() - t0).count();

  std::vector<double> px, dx, dy, py, res, ref_res;
  for (const auto &sample : shadow.samples)
    {
      px.push_back(sample.reference.x());
      py.push_back(sample.reference.y());
      dx.push_back(sample.solved.x() - sample.reference.x());
      dy.push_back(sample.solved.y() - sample.reference.y());
      res.push_back(sample.residual);
      ref_res.push_back(sample.reference_residual);
    }
  const auto [mean_px, se_px] = mean_and_error(px);
  const auto [mean_py, se_py] = mean_and_error(py);
  const auto [mean_dx, se_dx] = mean_and_error(dx);
  const auto [mean_dy, se_dy] = mean_and_error(dy);
  const auto [mean_res, se_res] = mean_and_error(res);
  const auto [mean_ref, se_ref] = mean_and_error(ref_res);
  std::printf("steps %lu from step %lu, %zu shadow solves (every %u); case's solve %.2f ms per step, "
              "whole loop %.2f ms per step (with the shadows)\n",
              steps, first, shadow.samples.size(), every, 1e3 * shadow.solve_seconds / double(shadow.solves),
              1e3 * wall / double(steps));
  std::printf("law residual: case's solve %.3g, reference %.3g (means over the shadow steps)\n", mean_res,
              mean_ref);
  std::printf("lower wall impulse (reference): P_x %.6g +/- %.2g, P_y %.6g +/- %.2g N s/m\n", mean_px, se_px,
              mean_py, se_py);
  std::printf("solve's error: d P_x / |P_x| = %+.2e +/- %.1e, d P_y / |P_y| = %+.2e +/- %.1e\n",
              mean_dx / std::abs(mean_px), se_dx / std::abs(mean_px), mean_dy / std::abs(mean_py),
              se_dy / std::abs(mean_py));
  return 0;
}
