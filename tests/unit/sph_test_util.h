#pragma once
/// @file Helpers shared by the SPH unit tests.

#include <deal.II/base/tensor.h>

namespace tribo::sph::testing
{
  /// The vector (x, y) in 2D, (x, y, z) in 3D.
  template <int dim>
  dealii::Tensor<1, dim> vec(double x, double y, double z = 0)
  {
    dealii::Tensor<1, dim> t;
    t[0] = x;
    t[1] = y;
    if constexpr (dim == 3)
      t[2] = z;
    return t;
  }
} // namespace tribo::sph::testing
