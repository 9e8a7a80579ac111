#pragma once
/// @file Lattice builders for SPH blocks and their surface modifiers
/// (Maveyraud et al. 1999, sections 2.5 and 3: tilted and incommensurate
/// lattices, steps, holes, random heights, self-affine fractal surfaces), and the
/// rest position of one body on another.
///
/// The vertical axis is the last one (y in 2D, z in 3D); "top" is the largest
/// vertical coordinate. Lengths in m, angles in rad (counter-clockwise in the
/// x-vertical plane). The mesh ratio of two bodies (e.g. the golden mean) is set
/// by their spacings.

#include "sph/particles.h"

#include <cstdint>
#include <vector>

namespace tribo::sph
{
  /// Lattice types: square (2D) / simple cubic (3D), or hexagonal (2D) /
  /// hexagonal close-packed ABAB (3D).
  enum class LatticeType
  {
    cubic,
    hexagonal
  };

  /// Points of a lattice of nearest-neighbour spacing @p a (m) filling the box
  /// [origin, origin + size) (m). Square/cubic: a^dim per particle. Hexagonal 2D:
  /// rows a sqrt(3)/2 apart, odd rows shifted by a/2, (sqrt(3)/2) a^2 per
  /// particle. HCP: hexagonal layers a sqrt(2/3) apart, B layers shifted by
  /// (a/2, a/(2 sqrt 3)), a^3/sqrt(2) per particle. For a block periodic in x,
  /// give size[0] = n a.
  template <int dim>
  std::vector<Tensor<1, dim>> lattice_points(LatticeType type, const Tensor<1, dim> &origin,
                                             const Tensor<1, dim> &size, double a);

  /// Volume (area in 2D, m^2) per particle of the lattice: the particle's mass
  /// is rho0 times this (kg, or kg/m in 2D).
  template <int dim>
  double volume_per_particle(LatticeType type, double a);

  /// Distance between the horizontal layers of the lattice of spacing @p a (m): a for
  /// square/cubic, a sqrt(3)/2 between hexagonal rows (2D), a sqrt(2/3) between HCP
  /// layers (3D).
  template <int dim>
  double layer_spacing(LatticeType type, double a);

  /// Rotates @p points by @p angle (rad, from x towards @p axis) about @p centre in the
  /// plane of x and @p axis: the vertical (dim - 1, a tilt) or, in 3D, y (1, a twist
  /// about the vertical axis).
  template <int dim>
  void tilt(std::vector<Tensor<1, dim>> &points, const Tensor<1, dim> &centre, double angle,
            unsigned int axis = dim - 1);

  /// Points of the lattice of spacing @p a (m) rotated by @p angle (rad) as tilt() does,
  /// about the centre of the box [0, size) (m), and cut to that box: the lattice fills the
  /// box widened by its diagonal on both sides along x and @p axis before the rotation,
  /// so that the rotated lattice covers the whole box.
  template <int dim>
  std::vector<Tensor<1, dim>> rotated_lattice_points(LatticeType type, const Tensor<1, dim> &size, double a,
                                                     double angle, unsigned int axis);

  /// Where a body @p upper rests on a body @p lower (points in m) when they touch through
  /// a force of range @p d (m), zero beyond: the shift of @p upper, centre + o + z e_v
  /// (e_v the vertical axis), where z is the lowest height with every upper-lower distance
  /// >= d and the horizontal offset o, on a grid of 8 per horizontal axis over one spacing
  /// @p a (m), makes z lowest (@p highest = false: the upper body in the lower one's
  /// hollows) or highest (true: the lattices stacked, each contact point d above a point
  /// below). A pair at horizontal distance rho < d holds the upper point at least
  /// sqrt(d^2 - rho^2) above the lower one; only the facing layers (within 2 d of each
  /// body's extreme height) are compared. @p period > 0: x periodic with that period (m).
  template <int dim>
  Tensor<1, dim> rest_shift(const std::vector<Tensor<1, dim>> &lower, const std::vector<Tensor<1, dim>> &upper,
                            const Tensor<1, dim> &centre, double a, double d, double period, bool highest);

  /// Indices of the particles within @p tol (m) of the top (largest vertical
  /// coordinate; @p top = false: bottom) of @p points.
  template <int dim>
  std::vector<unsigned int> surface_layer(const std::vector<Tensor<1, dim>> &points, double tol,
                                          bool top = true);

  /// One-particle step: a copy of each top-layer particle with x > @p x_step,
  /// raised by @p a (m), is appended.
  template <int dim>
  void add_step(std::vector<Tensor<1, dim>> &points, double x_step, double a, double tol);

  /// Removes a fraction @p fraction (0..1) of the top-layer particles, chosen at
  /// random (seeded, reproducible).
  template <int dim>
  void random_holes(std::vector<Tensor<1, dim>> &points, double fraction, std::uint64_t seed,
                    double tol);

  /// Moves each top-layer particle vertically by a uniform random amount in
  /// [-dz/2, dz/2] (seeded).
  template <int dim>
  void random_heights(std::vector<Tensor<1, dim>> &points, double dz, std::uint64_t seed,
                      double tol);

  /// Self-affine heights of fractal dimension @p D_f by spectral synthesis added
  /// to the top layer: z(x) = sum_k c_k |k|^(-(H + d_s/2)) cos(k.x + phi_k), with
  /// surface dimension d_s = dim - 1, Hurst exponent H = dim - D_f (so
  /// 1 < D_f < 2 in 2D, 2 < D_f < 3 in 3D), k = 2 pi (p/L_x, q/L_y) for integer
  /// p, q up to the Nyquist number of the lattice (@p n_modes per axis),
  /// c_k standard normal and phi_k uniform (seeded); the result is scaled to the
  /// root-mean-square height @p rms (m) over the top layer. Periodic in x with
  /// period @p lengths[0] (and in y with lengths[1] in 3D).
  template <int dim>
  void fractal_heights(std::vector<Tensor<1, dim>> &points, double D_f, double rms,
                       const Tensor<1, dim> &lengths, unsigned int n_modes, std::uint64_t seed,
                       double tol);

  /// Appends @p points to @p state as particles of density @p rho0 (kg/m^3),
  /// mass rho0 * @p volume, smoothing length @p h, at rest, with the given
  /// material and body ids. Returns the index of the first new particle.
  template <int dim>
  unsigned int add_particles(ParticleState<dim> &state, const std::vector<Tensor<1, dim>> &points,
                             double rho0, double volume, double h, unsigned int material,
                             unsigned int body);
} // namespace tribo::sph
