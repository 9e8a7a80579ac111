#pragma once
/// @file A deformable upper first body (fem, reduced, sph, mlp): the solver's coupling
/// interface (dem::BoundaryBody, ../shared/DESIGN.md section 3), whose boundary nodes are
/// the chain of its bottom face, plus what the scene measures, writes and checkpoints.
/// The grains touch it through half-disc elements on the chain (coupling/half_disc_body.cc
/// makes it a FirstBody).
///
/// Its top face is held in x and loaded by the pressure P(t) = P min(1, t / ramp), on its
/// own clock; until start_shearing() a compaction damping acts towards rest
/// (FirstBodyParameters::compaction_damping).
/// Units per unit depth: m, kg/m, N/m, J/m, W/m.

#include "coupling/first_body.h"
#include "dem/engine/boundary.h"

#include <memory>
#include <string>

namespace tribo::coupling
{
  /// Number of chain nodes the model places along L for @p p (fem: cells along x;
  /// sph: at least 8 columns, the kernel support must fit 3 times in the period;
  /// mlp: at least 4 columns). Throws InputError for an unknown model.
  unsigned int chain_nodes(const FirstBodyParameters &p);

  /// P-wave speed of the plane-strain material, sqrt(E (1 - nu) / ((1 + nu)(1 - 2 nu) rho)), m/s.
  double p_wave_speed(const FirstBodyParameters &p);

  /// A deformable first body: the coupling interface plus the scene's measurements.
  class DeformableBody : public dem::BoundaryBody
  {
  public:
    /// Mean y of the chain nodes at the start of the next step, m.
    virtual double mean_bottom_y() const = 0;
    /// Mean y-velocity of the chain nodes, m/s.
    virtual double mean_bottom_vy() const = 0;
    /// J/m.
    virtual double kinetic_energy() const = 0;
    /// Energy stored in the body, J/m: elastic (fem), internal (sph: elastic work plus
    /// the heat of its artificial viscosity), potential (mlp).
    virtual double stored_energy() const = 0;
    /// Kinetic plus stored energy, J/m.
    double energy() const final { return kinetic_energy() + stored_energy(); }
    /// Drop the compaction damping (the shearing phase starts).
    virtual void start_shearing() = 0;
    /// Write a VTU snapshot with index @p index into directory @p dir; returns its file
    /// name (deformable_body_snapshot_name()).
    virtual std::string write_fields(const std::string &dir, unsigned int index) const = 0;
    /// One line for the log: model, resolution, counts.
    virtual std::string describe() const = 0;
    /// The coupling's own figures for summary.json (none by default).
    virtual void summarize(JsonObject &) const {}
    virtual void save(CheckpointOut &ar) const = 0;
    virtual void load(CheckpointIn &ar) = 0;
  };

  /// The deformable body of model p.model (check_first_body() passed), its chain at
  /// p.bottom. Throws InputError for a model this build left out (naming the CMake option),
  /// std::logic_error for a wall of discs.
  std::unique_ptr<DeformableBody> make_deformable_body(const FirstBodyParameters &p);

  /// "upper_body_NNNNN.vtu" for snapshot @p index.
  std::string deformable_body_snapshot_name(unsigned int index);
} // namespace tribo::coupling
