#pragma once
/// @file Rigid bodies in the plane made of discs: single grains and clumps.
///
/// Everything is per unit depth (2D plane): mass in kg/m, moment of inertia in
/// kg m^2/m = kg m, forces in N/m, torques in N m/m = N, impulses in N s/m.
/// Angles are counter-clockwise in radians, spins in rad/s.

#include "core/checkpoint.h"

#include <Eigen/Core>

#include <array>
#include <cmath>
#include <vector>

namespace tribo::dem
{
  using Vec2 = Eigen::Vector2d;

  /// z-component of the cross product a x b.
  inline double cross(const Vec2 &a, const Vec2 &b) { return a.x() * b.y() - a.y() * b.x(); }

  /// Counter-clockwise rotation of @p v by @p angle.
  inline Vec2 rotate(const Vec2 &v, double angle)
  {
    const double c = std::cos(angle), s = std::sin(angle);
    return {c * v.x() - s * v.y(), s * v.x() + c * v.y()};
  }

  /// How one degree of freedom (x, y or rotation) of a body is driven.
  enum class Drive
  {
    free,     ///< moves under contact forces only
    velocity, ///< velocity imposed (infinite effective mass for contacts)
    force     ///< moves under contact forces plus an imposed force or torque
  };

  /// A rigid body: a grain (one disc) or a clump of discs moved as one.
  struct RigidBody
  {
    double mass    = 0; ///< kg/m
    double inertia = 0; ///< kg m, about the centre of mass
    Vec2   position = Vec2::Zero(); ///< centre of mass, m
    double angle    = 0;            ///< rad
    Vec2   velocity = Vec2::Zero(); ///< m/s
    double spin     = 0;            ///< rad/s
    /// Drive of x, y and rotation.
    std::array<Drive, 3> drive = {{Drive::free, Drive::free, Drive::free}};
    /// Imposed force (N/m) in x and y and torque (N) for Drive::force dofs.
    std::array<double, 3> load = {{0, 0, 0}};

    /// 1/m, 1/m, 1/I for free or force-driven dofs, 0 for velocity-driven ones.
    std::array<double, 3> inverse_mass() const
    {
      return {{drive[0] == Drive::velocity ? 0 : 1 / mass,
               drive[1] == Drive::velocity ? 0 : 1 / mass,
               drive[2] == Drive::velocity ? 0 : 1 / inertia}};
    }
    /// True if no degree of freedom has an imposed velocity.
    bool is_free() const
    {
      return drive[0] != Drive::velocity && drive[1] != Drive::velocity &&
             drive[2] != Drive::velocity;
    }
    /// (1/2) m |v|^2 + (1/2) I w^2, J/m.
    double kinetic_energy() const
    {
      return 0.5 * mass * velocity.squaredNorm() + 0.5 * inertia * spin * spin;
    }
  };

  /// A disc attached to a body, at @p offset from its centre in the body frame.
  struct Disc
  {
    unsigned int body;
    Vec2         offset;
    double       radius;
  };

  /// The bodies and discs of a scene, optionally periodic along x.
  class ParticleSystem
  {
  public:
    /// Period along x in m; 0 for a non-periodic domain.
    double period = 0;

    std::vector<RigidBody> bodies;
    std::vector<Disc>      discs;

    /// A free disc of radius @p r and density @p rho (kg/m^3) centred at @p x.
    unsigned int add_disc(const Vec2 &x, double r, double rho);

    /// A clump of discs at world positions @p centres with radii @p radii and
    /// density @p rho: mass and inertia summed (parallel axes), centre of mass
    /// as the body position.
    unsigned int add_clump(const std::vector<Vec2> &centres, const std::vector<double> &radii,
                           double rho);

    /// World position of the centre of disc @p d (not wrapped).
    Vec2 disc_centre(unsigned int d) const
    {
      const auto &b = bodies[discs[d].body];
      return b.position + rotate(discs[d].offset, b.angle);
    }

    /// @p x with its x-coordinate wrapped into [0, period) when periodic.
    Vec2 wrap(Vec2 x) const
    {
      if (period > 0)
        x.x() -= period * std::floor(x.x() / period);
      return x;
    }

    /// Sum of the kinetic energies, J/m.
    double kinetic_energy() const;
    /// Checkpoint: every body's state and load (the discs are rebuilt with the scene and
    /// checked against the saved count).
    void save(CheckpointOut &ar) const;
    void load(CheckpointIn &ar);
    /// Smallest disc radius, m.
    double min_radius() const;
    /// Largest disc radius, m.
    double max_radius() const;
  };
} // namespace tribo::dem
