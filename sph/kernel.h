#pragma once
/// @file Cubic-spline (M4) SPH kernel of Monaghan and Lattanzio (1985). Defined inline: the
/// force loop calls the gradient once per pair (out of line it was 28 % of an SPH body's time).

#include <deal.II/base/tensor.h>

#include <cmath>

namespace tribo::sph
{
  using dealii::Tensor;

  /// The M4 cubic spline with compact support 2h, q = r/h:
  ///
  ///   W(r, h) = sigma_d [1 - 3/2 q^2 + 3/4 q^3]   for 0 <= q < 1,
  ///           = sigma_d (2 - q)^3 / 4              for 1 <= q < 2,
  ///           = 0                                  for q >= 2,
  ///
  /// with sigma_2 = 10 / (7 pi h^2) (1/m^2) and sigma_3 = 1 / (pi h^3) (1/m^3), so
  /// that the integral of W over the plane (space) is 1. The gradient with respect
  /// to the position x_i of the first particle, r = x_i - x_j, is
  /// grad_i W = (dW/dr) r / |r|: it points from i towards j (dW/dr <= 0), i.e.
  /// along -r for a repulsive pressure force.
  template <int dim>
  class CubicSplineKernel
  {
  public:
    /// Normalisation sigma_d (1/m^dim) for smoothing length @p h (m).
    static double normalisation(double h);
    /// W(r, h), 1/m^dim; @p r >= 0 the distance, m.
    static double value(double r, double h);
    /// dW/dr (1/m^(dim+1)); <= 0 everywhere, 0 at r = 0 and r >= 2h.
    static double derivative(double r, double h);
    /// grad_i W for separation @p rij = x_i - x_j, 1/m^(dim+1).
    static Tensor<1, dim> gradient(const Tensor<1, dim> &rij, double h);
    /// The same from |rij|^2 (@p r2, m^2) and 1/h (@p inv_h, 1/m), for the force loop:
    /// grad_i W = (dW/dr / r) rij with dW/dr / r = sigma_d / h^2 (-3 + 9/4 q) for q < 1
    /// (no division) and -3/4 sigma_d (2 - q)^2 / (h r) for 1 <= q < 2.
    static Tensor<1, dim> gradient(const Tensor<1, dim> &rij, double r2, double inv_h);
    /// Support radius 2h, m.
    static double support(double h) { return 2 * h; }
  };

  template <int dim>
  inline double CubicSplineKernel<dim>::normalisation(double h)
  {
    if constexpr (dim == 2)
      return 10.0 / (7.0 * M_PI * h * h);
    else
      return 1.0 / (M_PI * h * h * h);
  }

  template <int dim>
  inline double CubicSplineKernel<dim>::value(double r, double h)
  {
    const double q = r / h;
    if (q >= 2)
      return 0;
    const double s = normalisation(h);
    if (q < 1)
      return s * (1 - 1.5 * q * q + 0.75 * q * q * q);
    const double t = 2 - q;
    return s * 0.25 * t * t * t;
  }

  template <int dim>
  inline double CubicSplineKernel<dim>::derivative(double r, double h)
  {
    const double q = r / h;
    if (q >= 2)
      return 0;
    const double s = normalisation(h) / h;
    if (q < 1)
      return s * (-3 * q + 2.25 * q * q);
    const double t = 2 - q;
    return -s * 0.75 * t * t;
  }

  template <int dim>
  inline Tensor<1, dim> CubicSplineKernel<dim>::gradient(const Tensor<1, dim> &rij, double h)
  {
    return gradient(rij, rij.norm_square(), 1 / h);
  }

  template <int dim>
  inline Tensor<1, dim> CubicSplineKernel<dim>::gradient(const Tensor<1, dim> &rij, double r2, double inv_h)
  {
    const double r = std::sqrt(r2);
    const double q = r * inv_h;
    if (r <= 0 || q >= 2)
      return Tensor<1, dim>();
    const double inv_h2 = inv_h * inv_h;
    double       s      = inv_h2 * inv_h2; // h^-4
    if constexpr (dim == 3)
      s *= inv_h;
    s *= normalisation(1.0); // sigma_d / h^2
    if (q < 1)
      return (s * (-3 + 2.25 * q)) * rij;
    const double t = 2 - q;
    return (-0.75 * s * t * t / q) * rij;
  }
} // namespace tribo::sph
