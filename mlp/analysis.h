#pragma once
/// @file Analysis of MLP configurations (paper, section 5): two-point density
/// correlation and its Fourier transform, Gaussian-convolved density map, and
/// the normalised width delta_h(t), the return forces of eq. (24) and the coordination.

#include "mlp/particles.h"

#include <vector>

namespace tribo::mlp
{
  class ForceField; // mlp/interaction.h

  /// Values on a regular nx x ny grid; node (a, b) sits at
  /// (x0 + a dx, y0 + b dy) and is stored at values[b nx + a].
  struct Grid2D
  {
    unsigned int        nx = 0, ny = 0;
    double              x0 = 0, y0 = 0, dx = 0, dy = 0;
    std::vector<double> values;

    /// Value at node (a, b).
    double operator()(unsigned int a, unsigned int b) const { return values[b * nx + a]; }
  };

  /// Magnitude of the Fourier transform of the two-point density correlation,
  /// paper eqs. (19)-(21), i.e. the structure factor
  ///   S(q) = (1/N) |sum_k exp(-i q . x_k)|^2,
  /// on an n x n grid of wave vectors covering [-q_max, q_max]^2 (1/m); n odd
  /// puts q = 0 at the centre (S(0) = N). Bragg peaks of a hexagonal lattice of
  /// spacing c sit at |q| = 4 pi/(sqrt(3) c), six-fold; square: 2 pi/c, four-fold.
  Grid2D structure_factor(const Particles &particles, double q_max, unsigned int n);

  /// Two-point density correlation in real space: the density of pair
  /// separations x_j - x_i (i != j, nearest image in @p box) per particle, in
  /// 1/m^2, binned on an n x n grid covering [-half_width, half_width]^2 m.
  /// For an ideal lattice it shows the neighbour shells with the lattice's
  /// symmetry.
  Grid2D pair_correlation(const Particles &particles, const Box &box, double half_width,
                          unsigned int n);

  /// Gaussian-convolved density, paper eq. (22):
  ///   rho(x) = sum_k exp(-|x - x_k|^2 / lambda),
  /// dimensionless, on the nx x ny grid with nodes from @p lower to @p upper;
  /// @p lambda in m^2 (the kernel is cut at 6 sqrt(lambda)). Its integral over the
  /// plane is N pi lambda.
  Grid2D gaussian_density(const Particles &particles, const Vec2 &lower, const Vec2 &upper,
                          unsigned int nx, unsigned int ny, double lambda);

  /// Extent max(y) - min(y) of the particles (m) along @p axis (0 = x, 1 = y).
  double extent(const Particles &particles, unsigned int axis);

  /// Normalised width, paper eq. (23): delta_h = extent(y) / @p initial_extent.
  double normalised_width(const Particles &particles, double initial_extent);

  /// Per particle, from the pairs of the current neighbour list: @p net = |sum_j F_ret,ij|
  /// (the paper's eq. 24, N/m) and @p bond = mean over its bonds (r < r_c) of |F_ret,ij|
  /// (N/m; 0 for a particle without bonds). F_ret is Interaction::return_force, the
  /// force on i; in a homogeneously strained lattice the net value cancels, the bond
  /// mean measures the rotation of the bonds from the lattice axes.
  void return_force_magnitudes(const ForceField &field, const Particles &p,
                               const Box &box, std::vector<double> &net,
                               std::vector<double> &bond);

  /// Mean number of bonds (pairs closer than r_c) per particle, 2 n_bonds / N.
  double mean_coordination(const ForceField &field, const Particles &p, const Box &box);
} // namespace tribo::mlp
