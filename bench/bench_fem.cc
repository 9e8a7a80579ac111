// Factorisation and solve times of the iteration matrix Mt = M + theta h C + theta^2 h^2 K
// of the deal.II elastic body with CHOLMOD and UMFPACK, on the paper's body
// (L = 1e-4 m, H = 1.5e-4 m, Q1): 72 x 107 cells (the paper's 7704), 104 x 156 and
// 208 x 312 (twice as fine each way); the Craig-Bampton reduced body with 0, 20 and 80
// modes (rows "CB k": dofs of the reduced model, build includes the reduction); then the
// assembly's time on 1 and 2 threads.
// Usage: bench_fem [repeats (default 5)]     (docs/fem.md records the figures)
#include "fem/elastic_body.h"

#include <deal.II/base/multithread_info.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <random>
#include <string>

using Clock = std::chrono::steady_clock;

namespace
{
  double seconds_since(Clock::time_point t0)
  {
    return std::chrono::duration<double>(Clock::now() - t0).count();
  }

  struct Timing
  {
    double build = 0, factorize = 1e300, predict = 1e300, finalize = 1e300, compliance = 0;
    Eigen::MatrixXd G;
  };

  /// @p modes < 0: the full model; otherwise the Craig-Bampton body with that many modes.
  Timing run(unsigned int nx, unsigned int ny, const std::string &solver, unsigned int repeats, int modes = -1)
  {
    tribo::fem::ElasticBodyParameters p; // the paper's body: E = 100 GPa, nu = 0.33, rho = 7800
    p.length       = 1e-4;
    p.thickness    = 1.5e-4;
    p.cells_x      = nx;
    p.cells_y      = ny;
    p.time_step    = 2e-9;
    p.top_pressure = 1e8;
    p.solver       = solver;
    p.reduced      = modes >= 0;
    p.modes        = std::max(modes, 0);
    Timing t;
    auto   t0 = Clock::now();
    tribo::fem::ElasticBody body(p);
    t.build = seconds_since(t0); // mesh, assembly, the reduction and the first factorisation
    std::mt19937                           rng(1);
    std::uniform_real_distribution<double> U(-1e-8, 1e-8);
    std::vector<Eigen::Vector2d>           R(body.n_boundary_nodes());
    for (unsigned int r = 0; r < repeats; ++r)
      {
        t0 = Clock::now();
        body.set_time_step(p.time_step * (1 + 1e-6 * (r + 1))); // forces a refactorisation
        t.factorize = std::min(t.factorize, seconds_since(t0));
      }
    for (unsigned int r = 0; r < repeats; ++r)
      {
        t0 = Clock::now();
        body.predict();
        t.predict = std::min(t.predict, seconds_since(t0));
        for (auto &x : R)
          x = Eigen::Vector2d(U(rng), U(rng));
        t0 = Clock::now();
        body.finalize(R);
        t.finalize = std::min(t.finalize, seconds_since(t0));
      }
    t0           = Clock::now();
    t.G          = body.boundary_compliance();
    t.compliance = seconds_since(t0);
    const std::string name = modes < 0 ? solver : "CB " + std::to_string(modes);
    std::printf("%4u x %-4u %8u  %-8s %9.3f %10.3f %9.4f %9.4f %11.2f\n", nx, ny, body.n_model_dofs(), name.c_str(),
                t.build, t.factorize, t.predict, t.finalize, t.compliance);
    std::fflush(stdout);
    return t;
  }
} // namespace

int main(int argc, char **argv)
{
  const unsigned int repeats = argc > 1 ? std::stoul(argv[1]) : 5;
  std::printf("times in s; factorise: set_time_step (Mt = combination of M and K, then analyse + factorise),\n"
              "min of %u; predict: one SpMV + one solve; finalize: one solve + updates, min of %u;\n"
              "compliance: the 2n solves of the boundary block (CHOLMOD: blocks of 32 right-hand sides)\n\n",
              repeats, repeats);
  std::printf("%-11s %8s  %-8s %9s %10s %9s %9s %11s\n", "cells", "dofs", "solver", "build", "factorise", "predict",
              "finalize", "compliance");
  // 72 x 107 = 7704 cells of 1.39 x 1.40 um: the paper's cell count (our reading, docs/fem.md).
  const unsigned int meshes[3][2] = {{72, 107}, {104, 156}, {208, 312}};
  for (const auto &mesh : meshes)
    {
      const Timing c = run(mesh[0], mesh[1], "cholmod", repeats);
      const Timing u = run(mesh[0], mesh[1], "umfpack", repeats);
      for (const int modes : {0, 20, 80})
        {
          const Timing r = run(mesh[0], mesh[1], "cholmod", repeats, modes);
          std::printf("  Craig-Bampton, %d modes: compliance differs from the full model's by %.1e (relative, "
                      "Frobenius), step (predict + finalize) %.0f times cheaper\n",
                      modes, (r.G - c.G).norm() / c.G.norm(), (c.predict + c.finalize) / (r.predict + r.finalize));
        }
      const double diff = (c.G - u.G).cwiseAbs().maxCoeff() / u.G.cwiseAbs().maxCoeff();
      std::printf("  faster: factorise %s (x%.1f), predict %s (x%.1f), compliance %s (x%.1f); "
                  "compliances agree to %.1e\n\n",
                  c.factorize < u.factorize ? "cholmod" : "umfpack",
                  std::max(c.factorize, u.factorize) / std::min(c.factorize, u.factorize),
                  c.predict < u.predict ? "cholmod" : "umfpack", std::max(c.predict, u.predict) / std::min(c.predict, u.predict),
                  c.compliance < u.compliance ? "cholmod" : "umfpack",
                  std::max(c.compliance, u.compliance) / std::min(c.compliance, u.compliance), diff);
    }

  // The assembly (WorkStream over the cells) on 1 and 2 threads.
  std::printf("assembly of M, K and the unit load, s (best of %u):\n%-11s %8s %10s %10s %8s\n", repeats, "cells",
              "dofs", "1 thread", "2 threads", "speed-up");
  for (const auto &mesh : meshes)
    {
      double best[2] = {1e300, 1e300};
      unsigned int dofs = 0;
      for (unsigned int threads : {1U, 2U})
        for (unsigned int r = 0; r < repeats; ++r)
          {
            dealii::MultithreadInfo::set_thread_limit(threads);
            tribo::fem::ElasticBodyParameters p;
            p.cells_x = mesh[0];
            p.cells_y = mesh[1];
            const tribo::fem::ElasticBody body(p);
            best[threads - 1] = std::min(best[threads - 1], body.assembly_seconds());
            dofs              = body.n_dofs();
          }
      std::printf("%4u x %-4u %8u %10.4f %10.4f %8.2f\n", mesh[0], mesh[1], dofs, best[0], best[1], best[0] / best[1]);
    }
  dealii::MultithreadInfo::set_thread_limit();
  return 0;
}
