#include "mlp/linear_theory.h"

#include "core/errors.h"

#include <algorithm>
#include <cmath>

namespace tribo::mlp
{
  HexagonalElasticity hexagonal_elasticity(double k1, double k2, double c, double mass)
  {
    const double        s3 = std::sqrt(3.0);
    HexagonalElasticity h;
    h.k1                   = k1;
    h.k2                   = k2;
    h.area                 = area_per_particle(LatticeType::hexagonal, c);
    h.density              = mass / h.area;
    h.lambda               = 0.25 * s3 * k2;
    h.mu                   = s3 * (0.5 * k1 + 0.25 * k2);
    h.rotation_modulus     = s3 * k1;
    h.simple_shear_modulus = h.mu + 0.5 * h.rotation_modulus;
    h.mu_navier            = s3 * (k1 + 0.25 * k2);
    h.lambda_navier        = s3 * (0.25 * k2 - k1);
    h.bulk_modulus         = h.lambda + h.mu;
    h.youngs_modulus       = 4 * h.mu * (h.lambda + h.mu) / (h.lambda + 2 * h.mu);
    h.poisson_ratio        = h.lambda / (h.lambda + 2 * h.mu);
    h.longitudinal_speed   = std::sqrt((h.lambda + 2 * h.mu) / h.density);
    h.transverse_speed     = std::sqrt(h.mu_navier / h.density);
    return h;
  }

  SquareElasticity square_elasticity(double k_c, double k_t)
  {
    SquareElasticity s;
    s.c11                  = k_c;
    s.c12                  = 0;
    s.c66                  = 0.5 * k_t;
    s.simple_shear_modulus = k_t;
    return s;
  }

  HexagonalModel hexagonal_model_for(double youngs_modulus, double poisson_ratio, double r0,
                                     MappingTarget target)
  {
    if (!(youngs_modulus > 0))
      throw InputError("MLP mapping: Young's modulus must be > 0 Pa, got " +
                       to_text(youngs_modulus));
    if (!(r0 > 0))
      throw InputError("MLP mapping: r0 must be > 0 m, got " + to_text(r0));
    if (!(poisson_ratio > -1 && poisson_ratio <= 1.0 / 3.0 + 1e-12))
      throw InputError("MLP mapping: a hexagonal MLP lattice reaches 2D Poisson ratios in "
                       "(-1, 1/3] only (return forces lower it from 1/3), got " +
                       to_text(poisson_ratio));
    const double E = youngs_modulus, nu = std::min(poisson_ratio, 1.0 / 3.0);
    const double lambda = E * nu / (1 - nu * nu), mu = E / (2 * (1 + nu));
    const double s3     = std::sqrt(3.0);
    double       k_c, k_t;
    if (target == MappingTarget::pure_strain)
      {
        k_c = 2 / s3 * (lambda + mu);
        k_t = 2 / s3 * (mu - lambda);
      }
    else
      {
        const double k2 = 2 / s3 * (lambda + mu);
        k_t             = mu / s3 - 0.25 * k2;
        k_c             = k_t + k2;
      }
    HexagonalModel m;
    m.stiffness = k_c;
    m.f0        = std::max(0.0, k_t) * r0 / 6;
    return m;
  }

  double max_angular_frequency(LatticeType type, double k_c, double k_t, double mass)
  {
    const auto   e = lattice_directions(type);
    const int    n = 129;
    const double q_max = 2 * M_PI; // in units of 1/c: covers both Brillouin zones
    double       w2_max = 0;
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b)
        {
          const double qx = -q_max + 2 * q_max * a / (n - 1);
          const double qy = -q_max + 2 * q_max * b / (n - 1);
          double       dxx = 0, dxy = 0, dyy = 0;
          for (const Vec2 &u : e)
            {
              const double w = 1 - std::cos(qx * u.x() + qy * u.y());
              // K = k_c u u^T + k_t u_perp u_perp^T, u_perp = (-u_y, u_x).
              dxx += w * (k_c * u.x() * u.x() + k_t * u.y() * u.y());
              dyy += w * (k_c * u.y() * u.y() + k_t * u.x() * u.x());
              dxy += w * (k_c - k_t) * u.x() * u.y();
            }
          const double tr = 0.5 * (dxx + dyy);
          const double l  = tr + std::sqrt(0.25 * (dxx - dyy) * (dxx - dyy) + dxy * dxy);
          w2_max          = std::max(w2_max, l);
        }
    return std::sqrt(w2_max / mass);
  }
} // namespace tribo::mlp
