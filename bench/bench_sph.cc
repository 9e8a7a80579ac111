/// @file Throughput of the solid-SPH force loop: pair interactions per second
/// for 1 and 2 threads on a ~5500-particle 3D granite block, and the time per
/// RK2 step (two rate evaluations). Prints figures; asserts nothing.

#include "sph/lattice.h"
#include "sph/solver.h"

#include <deal.II/base/multithread_info.h>

#include <chrono>
#include <cstdio>
#include <random>

using namespace tribo::sph;

int main()
{
  const double a = 2.5e-4; // m, the paper's particle size
  Tensor<1, 3> origin, size;
  size[0] = 22 * a;
  size[1] = 25 * a;
  size[2] = 10 * a;
  const auto pts = lattice_points<3>(LatticeType::cubic, origin, size, a);

  SolverParameters prm;
  Solver<3>        solver({Material::granite()}, prm);
  add_particles(solver.state, pts, 2680, volume_per_particle<3>(LatticeType::cubic, a), 1.2 * a, 0, 0);
  std::mt19937_64                        rng(1);
  std::uniform_real_distribution<double> u(-0.01, 0.01);
  for (auto &v : solver.state.v)
    for (unsigned int d = 0; d < 3; ++d)
      v[d] = u(rng);
  std::printf("particles %u\n", solver.state.size());

  for (unsigned int threads : {1U, 2U})
    {
      dealii::MultithreadInfo::set_thread_limit(threads);
      Rates<3> k;
      solver.compute_rates(solver.state, 0, k); // warm-up
      const unsigned int n_eval = 20;
      auto               t0     = std::chrono::steady_clock::now();
      for (unsigned int r = 0; r < n_eval; ++r)
        solver.compute_rates(solver.state, 0, k);
      const double t_eval =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / n_eval;
      // Interacting pairs: those within the cut-off 2 h (the solver's list also holds
      // the Verlet skin's).
      NeighbourSearch<3> ns;
      t0 = std::chrono::steady_clock::now();
      for (unsigned int r = 0; r < n_eval; ++r)
        ns.build(solver.state.x, 2.4 * a);
      const double t_search =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / n_eval;
      const double        pairs   = static_cast<double>(ns.n_pairs());
      const unsigned int  n_steps = 10;
      const unsigned long builds0 = solver.n_neighbour_builds();
      t0 = std::chrono::steady_clock::now();
      for (unsigned int s = 0; s < n_steps; ++s)
        solver.step();
      const double t_step =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / n_steps;
      std::printf("threads %u: pairs %.0f, rate evaluation %.3f ms (list kept: no rebuild), "
                  "one neighbour search %.3f ms, %.3g pair interactions/s, RK2 step %.3f ms "
                  "(%lu list builds in %u steps)\n",
                  threads, pairs, 1e3 * t_eval, 1e3 * t_search, pairs / t_eval, 1e3 * t_step,
                  solver.n_neighbour_builds() - builds0, n_steps);
    }
  return 0;
}
