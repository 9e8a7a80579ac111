#pragma once
/// @file Langevin dynamics of the MLP particles (paper, eqs. 12-17):
///   m dv/dt = F - eta v + xi,  <xi_a(t) xi_b(t')> = 2 eta k_B T delta_ab delta(t - t'),
/// integrated with the BAOAB splitting (Leimkuhler and Matthews 2013).

#include "mlp/interaction.h"
#include "mlp/particles.h"
#include "mlp/random.h"

#include <cstdint>
#include <vector>

namespace tribo::mlp
{
  /// Parameters of the Langevin integrator (2D, per unit depth).
  struct LangevinParameters
  {
    double        time_step      = 0; ///< dt, s
    double        damping        = 0; ///< eta, N s/m^2 = kg/(m s) (force per unit depth per m/s)
    double        thermal_energy = 0; ///< k_B T per particle and degree of freedom, J/m
    std::uint64_t seed           = 1; ///< seed of std::mt19937_64 for the noise
    /// Accepted fraction of the linear stability limit 2/omega_max; the
    /// margin covers the stiffening of U under compression.
    double safety = 0.5;
  };

  /// BAOAB Langevin integrator. One step of size dt:
  ///   B: v += (dt/2) F/m;  A: x += (dt/2) v;
  ///   O: v = c v + sqrt((1 - c^2) k_B T / m) N(0, 1),  c = exp(-eta dt / m);
  ///   A: x += (dt/2) v;  F = F(x);  B: v += (dt/2) F/m.
  /// The O step is the exact Ornstein-Uhlenbeck update; for eta dt/m << 1 it is
  /// the discretised noise xi = sqrt(2 eta k_B T / dt) N(0, 1) per component
  /// with friction -eta v. It gives <m v_x^2> = k_B T exactly for a free
  /// particle at any dt, and a velocity autocorrelation c^k = exp(-eta t/m).
  /// Without damping it is velocity Verlet, stable for dt < 2/omega_max.
  ///
  /// Held components (Particles::fixed) keep their velocity (no force, no
  /// noise) and move with it. Positions are wrapped into the periodic box after
  /// each step. The noise is drawn in particle order, x then y, so a seed gives
  /// the same trajectory on every run and any number of threads.
  class LangevinIntegrator
  {
  public:
    /// Checks the step against the stable limit of the stiffest bond:
    /// dt <= safety * 2/omega_max, omega_max from max_angular_frequency() with
    /// the interaction's k_c, k_t and the smallest particle mass. Throws
    /// InputError naming the step, the limit and a step that would work.
    LangevinIntegrator(ForceField &forces, const Particles &particles,
                       const LangevinParameters &p);

    /// Advances @p particles by one step.
    void step(Particles &particles, const Box &box);
    /// Advances by @p n steps.
    void run(Particles &particles, const Box &box, unsigned int n);
    /// Change the damping eta (kg/(m s), >= 0) for the following steps.
    void set_damping(double eta);
    /// Energy given to the heat bath by the O steps since construction, J/m:
    /// sum of the kinetic-energy drops of the O steps (> 0 for friction at T = 0;
    /// the noise gives energy back at T > 0).
    double bath_work() const { return to_bath; }
    /// Forces are recomputed before the next step (call after moving particles
    /// or changing loads by hand).
    void invalidate_forces() { forces_current = false; }

    /// Simulated time, s.
    double time() const { return t; }
    /// Steps taken.
    unsigned long long n_steps() const { return steps; }
    /// omega_max of the stiffest bond, rad/s.
    double max_frequency() const { return omega_max; }
    /// The largest accepted step, safety * 2/omega_max, s.
    double max_time_step() const { return prm.safety * 2 / omega_max; }

    /// Checkpoint: what a step carries to the next, bit for bit: the noise generator's
    /// state, time, step count, bath work, the damping (set_damping() may have changed it)
    /// and whether the forces are current. The force field saves its own neighbour list
    /// (ForceField::save()), the particles their own state.
    void save(CheckpointOut &ar) const;
    void load(CheckpointIn &ar);

    /// Throws RunError naming the first particle with a non-finite position,
    /// velocity or force.
    static void check_finite(const Particles &particles, double time);

  private:
    ForceField         &field;
    LangevinParameters  prm;
    double              omega_max = 0;
    RandomSource        rng;
    std::vector<double> decay, kick; ///< c and sqrt((1 - c^2) k_B T / m) per particle
    bool                forces_current = false;
    double              t              = 0;
    unsigned long long  steps          = 0;
    double              to_bath        = 0;

    void prepare(const Particles &particles);
  };
} // namespace tribo::mlp
