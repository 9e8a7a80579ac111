#include "sph/kernel.h"

#include <cmath>

namespace tribo::sph
{
  template <int dim>
  double CubicSplineKernel<dim>::normalisation(double h)
  {
    if constexpr (dim == 2)
      return 10.0 / (7.0 * M_PI * h * h);
    else
      return 1.0 / (M_PI * h * h * h);
  }

  template <int dim>
  double CubicSplineKernel<dim>::value(double r, double h)
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
  double CubicSplineKernel<dim>::derivative(double r, double h)
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
  Tensor<1, dim> CubicSplineKernel<dim>::gradient(const Tensor<1, dim> &rij, double h)
  {
    const double r = rij.norm();
    if (r <= 0 || r >= 2 * h)
      return Tensor<1, dim>();
    return (derivative(r, h) / r) * rij;
  }

  template class CubicSplineKernel<2>;
  template class CubicSplineKernel<3>;
} // namespace tribo::sph
