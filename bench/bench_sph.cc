/// @file Throughput of the solid-SPH force loop: pair interactions per second for 1 and
/// 2 threads, and the time per RK2 step (two rate evaluations) and per leapfrog step, on two blocks:
/// - a ~5500-particle 3D granite block (the SPH paper's particle size);
/// - the shear cell's plane-strain upper body at the paper's size (coupling/, sph model):
///   104 x 156 particles on a square lattice of spacing 0.96 um, periodic along x, linear
///   equation of state with E = 100 GPa, nu = 0.25, rho = 7800 kg/m^3, h = 1.2 spacings.
/// Prints figures; asserts nothing.

#include "sph/lattice.h"
#include "sph/solver.h"

#include <deal.II/base/multithread_info.h>

#include <chrono>
#include <cstdio>
#include <random>

using namespace tribo::sph;

namespace
{
  /// Small random velocities (m/s), so that the viscosity's branch is taken.
  template <int dim>
  void stir(Solver<dim> &solver)
  {
    std::mt19937_64                        rng(1);
    std::uniform_real_distribution<double> u(-0.01, 0.01);
    for (auto &v : solver.state.v)
      for (unsigned int d = 0; d < dim; ++d)
        v[d] = u(rng);
  }

  template <int dim>
  void measure(const char *name, Solver<dim> &solver, double interaction_cutoff)
  {
    std::printf("%s: particles %u\n", name, solver.state.size());
    for (unsigned int threads : {1U, 2U})
      {
        dealii::MultithreadInfo::set_thread_limit(threads);
        Rates<dim> k;
        solver.compute_rates(solver.state, 0, k); // warm-up
        const unsigned int n_eval = 20;
        auto               t0     = std::chrono::steady_clock::now();
        for (unsigned int r = 0; r < n_eval; ++r)
          solver.compute_rates(solver.state, 0, k);
        const double t_eval =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / n_eval;
        // Interacting pairs: those within the cut-off 2 h (the solver's list also holds
        // the Verlet skin's).
        NeighbourSearch<dim> ns(solver.parameters().period);
        t0 = std::chrono::steady_clock::now();
        for (unsigned int r = 0; r < n_eval; ++r)
          ns.build(solver.state.x, interaction_cutoff);
        const double t_search =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / n_eval;
        const double        pairs   = static_cast<double>(ns.n_pairs());
        const unsigned int  n_steps = 10;
        const unsigned long builds0 = solver.n_neighbour_builds();
        const double        time0   = solver.time;
        t0 = std::chrono::steady_clock::now();
        for (unsigned int s = 0; s < n_steps; ++s)
          solver.step();
        const double t_step =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / n_steps;
        std::printf("  threads %u: pairs %.0f, rate evaluation %.3f ms (list kept: no rebuild), "
                    "one neighbour search %.3f ms, %.3g pair interactions/s, RK2 step %.3f ms "
                    "(%lu list builds in %u steps)\n",
                    threads, pairs, 1e3 * t_eval, 1e3 * t_search, pairs / t_eval, 1e3 * t_step,
                    solver.n_neighbour_builds() - builds0, n_steps);
        // The leapfrog over the same span of time from the same state (its steps reuse the
        // last one's forces within an advance_to()).
        SolverParameters leap_prm = solver.parameters();
        leap_prm.integrator       = Integrator::leapfrog;
        Solver<dim> leap(solver.materials(), leap_prm);
        leap.state = solver.state;
        const double span = solver.time - time0;
        leap.advance_to(span / n_steps); // warm-up: the list
        t0                = std::chrono::steady_clock::now();
        const unsigned int leap_steps = leap.advance_to(leap.time + span);
        const double       t_leap =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / leap_steps;
        std::printf("  threads %u: leapfrog step %.3f ms (%u steps over that time)\n", threads, 1e3 * t_leap,
                    leap_steps);
      }
  }
} // namespace

int main()
{
  {
    const double a = 2.5e-4; // m, the paper's particle size
    Tensor<1, 3> origin, size;
    size[0]        = 22 * a;
    size[1]        = 25 * a;
    size[2]        = 10 * a;
    const auto pts = lattice_points<3>(LatticeType::cubic, origin, size, a);
    Solver<3>  solver({Material::granite()}, SolverParameters());
    add_particles(solver.state, pts, 2680, volume_per_particle<3>(LatticeType::cubic, a), 1.2 * a, 0, 0);
    stir(solver);
    measure("3D granite block", solver, 2.4 * a);
  }
  {
    const double     s = 0.96e-6, length = 104 * s, E = 1e11, nu = 0.25, rho = 7800;
    SolverParameters prm;
    prm.period = length;
    Solver<2>  solver({Material::linear(rho, E / (3 * (1 - 2 * nu)), E / (2 * (1 + nu)))}, prm);
    const auto pts = lattice_points<2>(LatticeType::cubic, Tensor<1, 2>(), Tensor<1, 2>({length, 156 * s}), s);
    add_particles(solver.state, pts, rho, s * s, 1.2 * s, 0, 0);
    stir(solver);
    measure("shear cell's upper body at the paper's size (2D, periodic)", solver, 2.4 * s);
  }
  return 0;
}
