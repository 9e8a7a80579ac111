#pragma once
/// @file The shear cell's upper first body as the scene sees it, whatever its model: the
/// rigid wall (a clump of discs in the particle system, free in y under the load P L,
/// with the mass of the first body it stands for) or a deformable body
/// (coupling::FirstBody: fem, reduced, sph, mlp, touched through half-disc elements).
/// The scene places it, loads it, measures it, writes and checkpoints it through this
/// one interface; only the factory names the models.
/// Units per unit depth: m, N/m, J/m, W/m.

#include "core/checkpoint.h"
#include "coupling/first_body.h"
#include "dem/moreau_jean.h"
#include "dem/particle_system.h"

#include <memory>
#include <string>
#include <vector>

namespace tribo::app
{
  /// What the statistics need from the upper first body.
  struct UpperState
  {
    double y, vy;          ///< wall centre line (rigid) or mean bottom face (deformable), m and m/s
    double surface;        ///< the surface the grains touch, m
    double power;          ///< power of its external load over the step, W/m
    double kinetic_energy; ///< J/m
    double stored_energy;  ///< J/m (0 for the rigid wall)
  };

  class UpperBody
  {
  public:
    virtual ~UpperBody() = default;
    /// Its body in the particle system (the rigid wall), LayerProfiles::no_body if none.
    virtual unsigned int system_body() const = 0;
    /// From its reference height (UpperState::y) down to the surface the grains touch, m:
    /// the wall's mean disc radius, or the half-disc radius.
    virtual double y_to_surface() const = 0;
    /// Diameter of the half-disc elements on its face, m (0: none, the rigid wall).
    virtual double half_disc_diameter() const { return 0; }
    /// The time the pressure ramp counts from at run time @p t, s: a deformable body
    /// placed on a state takes its load from the state's time @p start on, on its own
    /// clock; the rigid wall of a state goes on with the state's ramp.
    virtual double load_time(double t, double start) const = 0;
    /// Couple it to the integrator (once, before the first step).
    virtual void attach(dem::MoreauJean &) {}
    /// Before a step at time @p t: the load @p normal_force = P L times the ramp (N/m),
    /// @p sliding once the lower wall slides; @p speed_cap caps the rigid wall's |v_y|
    /// during compaction (m/s, 0: none).
    virtual void before_step(dem::ParticleSystem &s, double normal_force, bool sliding, double speed_cap) = 0;
    /// Its state after a step; @p power the integrator's external power per body.
    virtual UpperState state(const dem::ParticleSystem &s, const std::vector<double> &power) const = 0;
    /// Mean x-displacement of its contact face since the start, m, minimum image over the
    /// period (0 for the rigid wall, whose x is imposed). About tau H / G in steady shear.
    virtual double face_shift() const { return 0; }
    /// True when its kinetic and stored energy count in the energy balance (a deformable
    /// body; the rigid wall's vertical motion is the load's work, counted in its power).
    virtual bool in_energy_balance() const { return false; }
    /// Its own field snapshot @p index in @p dir; the file names written.
    virtual std::vector<std::string> write_fields(const std::string &, unsigned int) const { return {}; }
    /// A line for the log ("" for none).
    virtual std::string describe() const { return ""; }
    /// Its own figures for summary.json.
    virtual void summarize(JsonObject &) const {}
    virtual void save(CheckpointOut &) const {}
    virtual void load(CheckpointIn &) {}
  };

  /// The rigid wall: clump @p wall of @p s made free in y and given the mass
  /// density x @p thickness x @p length (its inertia scaled alike); @p y_to_surface its
  /// mean disc radius, m.
  std::unique_ptr<UpperBody> make_rigid_upper_wall(dem::ParticleSystem &s, unsigned int wall, double density,
                                                   double thickness, double length, double y_to_surface);

  /// The deformable body of @p p (coupling/first_body.h) with the half-disc elements'
  /// bottom, the surface the grains touch, at @p surface (m); the half-disc diameter is
  /// p.half_disc_diameter, or the chain spacing L / chain_nodes when that is 0.
  std::unique_ptr<UpperBody> make_deformable_upper_body(coupling::FirstBodyParameters p, double surface);
} // namespace tribo::app
