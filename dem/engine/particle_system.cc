#include "dem/engine/particle_system.h"

#include "core/errors.h"

#include <boost/archive/binary_iarchive.hpp>
#include <boost/archive/binary_oarchive.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace tribo::dem
{
  unsigned int ParticleSystem::add_disc(const Vec2 &x, double r, double rho)
  {
    RigidBody b;
    b.mass     = rho * M_PI * r * r;
    b.inertia  = 0.5 * b.mass * r * r;
    b.position = x;
    bodies.push_back(b);
    discs.push_back({static_cast<unsigned int>(bodies.size() - 1), Vec2::Zero(), r});
    return bodies.size() - 1;
  }

  unsigned int ParticleSystem::add_clump(const std::vector<Vec2> &centres,
                                         const std::vector<double> &radii, double rho)
  {
    if (centres.empty() || centres.size() != radii.size())
      throw std::invalid_argument("add_clump: need as many radii as centres, at least one");
    RigidBody b;
    Vec2      first_moment = Vec2::Zero();
    for (std::size_t i = 0; i < centres.size(); ++i)
      {
        const double m = rho * M_PI * radii[i] * radii[i];
        b.mass += m;
        first_moment += m * centres[i];
      }
    b.position = first_moment / b.mass;
    for (std::size_t i = 0; i < centres.size(); ++i)
      {
        const double m = rho * M_PI * radii[i] * radii[i];
        b.inertia += 0.5 * m * radii[i] * radii[i] + m * (centres[i] - b.position).squaredNorm();
      }
    bodies.push_back(b);
    const auto id = static_cast<unsigned int>(bodies.size() - 1);
    for (std::size_t i = 0; i < centres.size(); ++i)
      discs.push_back({id, centres[i] - b.position, radii[i]});
    return id;
  }

  double ParticleSystem::kinetic_energy() const
  {
    double e = 0;
    for (const auto &b : bodies)
      e += b.kinetic_energy();
    return e;
  }

  double ParticleSystem::min_radius() const
  {
    double r = std::numeric_limits<double>::infinity();
    for (const auto &d : discs)
      r = std::min(r, d.radius);
    return r;
  }

  double ParticleSystem::max_radius() const
  {
    double r = 0;
    for (const auto &d : discs)
      r = std::max(r, d.radius);
    return r;
  }
  namespace
  {
    /// Both directions of a body's checkpoint, field by field (Ar: either archive).
    template <class Ar, class Body>
    void body_state(Ar &ar, Body &b)
    {
      ar &b.mass &b.inertia &b.position.x() &b.position.y() &b.angle &b.velocity.x() &b.velocity.y() &b.spin;
      for (int k = 0; k < 3; ++k)
        {
          int drive = static_cast<int>(b.drive[k]);
          ar &drive;
          b.drive[k] = static_cast<Drive>(drive);
          ar &b.load[k];
        }
    }
  } // namespace

  void ParticleSystem::save(CheckpointOut &ar) const
  {
    std::size_t n_bodies = bodies.size(), n_discs = discs.size();
    ar << period << n_bodies << n_discs;
    for (RigidBody b : bodies)
      body_state(ar, b);
  }

  void ParticleSystem::load(CheckpointIn &ar)
  {
    std::size_t n_bodies, n_discs;
    double      saved_period;
    ar >> saved_period >> n_bodies >> n_discs;
    if (n_bodies != bodies.size() || n_discs != discs.size() || saved_period != period)
      throw InputError("checkpoint: it holds " + std::to_string(n_bodies) + " bodies and " +
                       std::to_string(n_discs) + " discs, this case builds " +
                       std::to_string(bodies.size()) + " and " + std::to_string(discs.size()));
    for (RigidBody &b : bodies)
      body_state(ar, b);
  }
} // namespace tribo::dem
