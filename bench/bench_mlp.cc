// Benchmark of the MLP force loop and Langevin step: pair interactions per
// second and time per step for 10k and 40k particles, 1 and 2 threads.
// Prints figures; asserts nothing.
#include "mlp/interaction.h"
#include "mlp/langevin.h"
#include "mlp/particles.h"
#include "mlp/random.h"

#include <deal.II/base/multithread_info.h>

#include <chrono>
#include <cmath>
#include <cstdio>

using namespace tribo::mlp;

int main()
{
  const double c = 1e-6, kc = 1e9;
  const double mass = 7800 * area_per_particle(LatticeType::hexagonal, c);
  std::printf("# MLP benchmark: hexagonal patch periodic along x, Morse + paper return force "
              "(k_t = k_c/2), Langevin BAOAB at k_B T = 1e-3 D\n");
  std::printf("# %9s %8s %12s %16s %14s %14s\n", "particles", "threads", "pairs", "pairs/s (force)",
              "force ms", "step ms");
  for (unsigned int side : {100u, 200u})
    for (unsigned int threads : {1u, 2u})
      {
        dealii::MultithreadInfo::set_thread_limit(threads);
        Particles particles;
        add_lattice_patch(particles, LatticeType::hexagonal, Vec2(0.25 * c, 0.25 * c), side, side,
                          c, mass);
        Box box;
        box.periodic_x = true;
        box.lx         = side * c;
        InteractionParameters p;
        p.r0        = c;
        p.stiffness = kc;
        p.f0        = 0.5 * kc * c / 6;
        ForceField field(p);
        field.set_parallel(threads > 1);
        LangevinParameters lp;
        lp.time_step      = 2e-10;
        lp.damping        = 0.01 * mass / lp.time_step;
        lp.thermal_energy = 1e-3 * field.interaction().potential().depth();
        LangevinIntegrator integrator(field, particles, lp);
        integrator.run(particles, box, 20); // warm-up, builds the list

        using clock          = std::chrono::steady_clock;
        const unsigned int n_force = 50;
        auto               t0      = clock::now();
        for (unsigned int k = 0; k < n_force; ++k)
          field.compute(particles, box);
        const double t_force =
          std::chrono::duration<double>(clock::now() - t0).count() / n_force;
        const unsigned int n_steps = 50;
        t0                         = clock::now();
        integrator.run(particles, box, n_steps);
        const double t_step = std::chrono::duration<double>(clock::now() - t0).count() / n_steps;
        const double pairs  = static_cast<double>(field.neighbours().pairs().size());
        std::printf("  %9u %8u %12.0f %16.3e %14.3f %14.3f\n", particles.size(), threads, pairs,
                    pairs / t_force, 1e3 * t_force, 1e3 * t_step);
      }
  return 0;
}
