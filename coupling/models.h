#pragma once
/// @file The models behind the table of coupling/models.cc, one file each: what the
/// table's rows point to, declared once for the table and the model files.

#include "coupling/deformable_body.h"
#include "coupling/first_body.h"

#include <memory>

namespace tribo::coupling
{
  /// rigid (rigid_wall.cc): the wall of discs where.add_wall() puts it, made free in y and
  /// given the mass rho H L (its inertia scaled alike).
  std::unique_ptr<FirstBody> place_rigid_wall(const FirstBodyParameters &p, const FirstBodyPlacement &where);

  /// Any deformable model (half_disc_body.cc): make_deformable_body() with its half-disc
  /// elements' bottom, the surface the grains touch, at where.surface.
  std::unique_ptr<FirstBody> place_on_half_discs(const FirstBodyParameters &p, const FirstBodyPlacement &where);

  /// fem, reduced (fem_first_body.cc): at most 4e6 cells; reduced: at most the body's
  /// interior unknowns less 2 modes.
  void check_fem_body(const FirstBodyParameters &p);
  std::unique_ptr<DeformableBody> make_fem_body(const FirstBodyParameters &p);

  /// sph (sph_first_body.cc).
  std::unique_ptr<DeformableBody> make_sph_body(const FirstBodyParameters &p);

  /// mlp (mlp_first_body.cc): nu <= 1/4.
  void check_mlp_body(const FirstBodyParameters &p);
  std::unique_ptr<DeformableBody> make_mlp_body(const FirstBodyParameters &p);
} // namespace tribo::coupling
