#include "mlp/langevin.h"

#include "core/errors.h"
#include "core/serialization.h"
#include "mlp/linear_theory.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace tribo::mlp
{
  LangevinIntegrator::LangevinIntegrator(ForceField &forces, const Particles &particles,
                                         const LangevinParameters &p)
    : field(forces), prm(p), rng(p.seed)
  {
    if (!(p.time_step > 0))
      throw InputError("MLP Langevin: time step must be > 0 s, got " + to_text(p.time_step));
    if (!(p.damping >= 0) || !(p.thermal_energy >= 0))
      throw InputError("MLP Langevin: damping and thermal energy must be >= 0, got eta = " +
                       to_text(p.damping) + " kg/(m s), k_B T = " + to_text(p.thermal_energy) +
                       " J/m");
    if (!(p.safety > 0 && p.safety <= 1))
      throw InputError("MLP Langevin: safety must be in (0, 1], got " + to_text(p.safety));
    double m_min = std::numeric_limits<double>::max();
    for (unsigned int i = 0; i < particles.size(); ++i)
      if (particles.fixed[i] != fix_xy)
        m_min = std::min(m_min, particles.mass[i]);
    if (m_min == std::numeric_limits<double>::max())
      m_min = 1; // nothing moves: any step is stable
    const auto  &ip   = forces.interaction().parameters();
    const double k_t  = forces.interaction().transverse_stiffness();
    const auto   type = ip.n == 6 ? LatticeType::hexagonal : LatticeType::square;
    omega_max         = max_angular_frequency(type, ip.stiffness, k_t, m_min);
    const double limit = max_time_step();
    if (p.time_step > limit)
      throw InputError("MLP Langevin: time step " + to_text(p.time_step) +
                       " s exceeds the stable limit " + to_text(limit) + " s (" +
                       to_text(p.safety) + " x 2/omega_max, omega_max = " + to_text(omega_max) +
                       " rad/s from the stiffest bond k = " +
                       to_text(std::max(ip.stiffness, k_t)) + " N/m^2 and mass m = " +
                       to_text(m_min) + " kg/m); use a time step of at most " + to_text(limit) +
                       " s, e.g. " + to_text(0.5 * limit) + " s");
  }

  void LangevinIntegrator::prepare(const Particles &particles)
  {
    const unsigned int n = particles.size();
    decay.resize(n);
    kick.resize(n);
    for (unsigned int i = 0; i < n; ++i)
      {
        const double c = std::exp(-prm.damping * prm.time_step / particles.mass[i]);
        decay[i]       = c;
        kick[i]        = std::sqrt((1 - c * c) * prm.thermal_energy / particles.mass[i]);
      }
  }

  void LangevinIntegrator::set_damping(double eta)
  {
    if (!(eta >= 0))
      throw InputError("MLP Langevin: damping must be >= 0, got eta = " + to_text(eta) + " kg/(m s)");
    prm.damping = eta;
    decay.clear(); // prepare() again at the next step
  }

  void LangevinIntegrator::check_finite(const Particles &particles, double time)
  {
    for (unsigned int i = 0; i < particles.size(); ++i)
      if (!particles.position[i].allFinite() || !particles.velocity[i].allFinite() ||
          !particles.force[i].allFinite())
        throw RunError("MLP: particle " + std::to_string(i) + " (group " +
                       std::to_string(particles.group[i]) +
                       ") has a non-finite state at t = " + to_text(time) + " s: x = (" +
                       to_text(particles.position[i].x()) + ", " +
                       to_text(particles.position[i].y()) + ") m, v = (" +
                       to_text(particles.velocity[i].x()) + ", " +
                       to_text(particles.velocity[i].y()) + ") m/s, F = (" +
                       to_text(particles.force[i].x()) + ", " + to_text(particles.force[i].y()) +
                       ") N/m; lower the time step or check the loads");
  }

  void LangevinIntegrator::step(Particles &particles, const Box &box)
  {
    const unsigned int n  = particles.size();
    const double       dt = prm.time_step, h = 0.5 * dt;
    if (decay.size() != n)
      prepare(particles);
    if (!forces_current)
      {
        field.compute(particles, box);
        forces_current = true;
      }
    auto kick_half = [&]() {
      for (unsigned int i = 0; i < n; ++i)
        {
          const double w = h / particles.mass[i];
          if (!(particles.fixed[i] & fix_x))
            particles.velocity[i].x() += w * particles.force[i].x();
          if (!(particles.fixed[i] & fix_y))
            particles.velocity[i].y() += w * particles.force[i].y();
        }
    };
    kick_half();
    for (unsigned int i = 0; i < n; ++i)
      particles.position[i] += h * particles.velocity[i];
    const bool noisy = prm.thermal_energy > 0;
    if (prm.damping > 0)
      for (unsigned int i = 0; i < n; ++i)
        for (unsigned int c = 0; c < 2; ++c)
          if (!(particles.fixed[i] & (1u << c)))
            {
              double &v = particles.velocity[i][c];
              const double before = v;
              v         = decay[i] * v + (noisy ? kick[i] * rng.normal() : 0.0);
              to_bath += 0.5 * particles.mass[i] * (before * before - v * v);
            }
    for (unsigned int i = 0; i < n; ++i)
      {
        particles.position[i] += h * particles.velocity[i];
        particles.position[i] = box.wrap(particles.position[i]);
      }
    field.compute(particles, box);
    kick_half();
    t += dt;
    ++steps;
    check_finite(particles, t);
  }

  void LangevinIntegrator::run(Particles &particles, const Box &box, unsigned int n)
  {
    for (unsigned int k = 0; k < n; ++k)
      step(particles, box);
  }

  void RandomSource::save(CheckpointOut &ar) const
  {
    ar << engine_state(engine) << spare << has_spare;
  }

  void RandomSource::load(CheckpointIn &ar)
  {
    std::string state;
    ar >> state >> spare >> has_spare;
    set_engine_state(engine, state);
  }

  void LangevinIntegrator::save(CheckpointOut &ar) const
  {
    rng.save(ar);
    ar << t << steps << to_bath << prm.damping << forces_current;
  }

  void LangevinIntegrator::load(CheckpointIn &ar)
  {
    rng.load(ar);
    ar >> t >> steps >> to_bath >> prm.damping >> forces_current;
    decay.clear(); // prepare() again for the restored damping
  }
} // namespace tribo::mlp
