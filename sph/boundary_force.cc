#include "sph/boundary_force.h"

#include "core/errors.h"

#include <cmath>

namespace tribo::sph
{
  BoundaryForce BoundaryForce::spring(double K, double d)
  {
    if (!(K > 0 && d > 0))
      throw InputError("SPH spring boundary force: stiffness and range must be positive");
    BoundaryForce f;
    f.law = BoundaryLaw::spring;
    f.K   = K;
    f.d   = d;
    return f;
  }

  BoundaryForce BoundaryForce::monaghan(double A, double s, double b)
  {
    if (!(A > 0 && s > 0 && b > 0))
      throw InputError("SPH Monaghan boundary force: A, s and b must be positive");
    BoundaryForce f;
    f.law = BoundaryLaw::monaghan;
    f.A   = A;
    f.s   = s;
    f.b   = b;
    f.l   = s * b / (s + 2);
    f.D   = A * std::pow((s + 2) / (2 * b), 2);
    return f;
  }

  BoundaryForce BoundaryForce::lennard_jones(double eps, double m, double n, double l, double R)
  {
    if (!(eps > 0 && m > n && n > 0 && l > 0))
      throw InputError("SPH Lennard-Jones boundary force: need eps > 0, m > n > 0, l > 0");
    BoundaryForce f;
    f.law = BoundaryLaw::lennard_jones;
    f.eps = eps;
    f.m   = m;
    f.n   = n;
    f.l   = l;
    f.R   = R;
    f.rc  = l * std::pow(m / n, 1 / (m - n));
    if (!(R > f.rc))
      throw InputError("SPH Lennard-Jones boundary force: range R = " + to_text(R) +
                       " m must exceed the minimum r_c = " + to_text(f.rc) + " m");
    const double q = n / m;
    f.D3 = 2 * eps / (R - f.rc) * (std::pow(q, m / (m - n)) - std::pow(q, n / (m - n)));
    f.A3 = -f.D3 / (2 * (R - f.rc));
    return f;
  }

  double BoundaryForce::lennard_jones_epsilon(double c_s, double h, double m, double n)
  {
    return 4.0 / 9.0 * c_s * c_s / h * std::pow(n / m, 1 / (m - n)) / (m - n);
  }

  double BoundaryForce::value(double r) const
  {
    switch (law)
      {
        case BoundaryLaw::spring:
          return r < d ? -K * (r - d) : 0;
        case BoundaryLaw::monaghan:
          if (r < l)
            return A * std::pow(l / r, s);
          return r < b ? D * (r - b) * (r - b) : 0;
        case BoundaryLaw::lennard_jones:
          if (r < rc)
            return eps * (std::pow(l / r, m) - std::pow(l / r, n));
          return r < R ? A3 * (R - r) * (R - r) + D3 * (R - r) : 0;
        default:
          return 0;
      }
  }

  double BoundaryForce::range() const
  {
    switch (law)
      {
        case BoundaryLaw::spring:
          return d;
        case BoundaryLaw::monaghan:
          return b;
        case BoundaryLaw::lennard_jones:
          return R;
        default:
          return 0;
      }
  }

  std::string BoundaryForce::describe() const
  {
    switch (law)
      {
        case BoundaryLaw::spring:
          return "spring f1 (K = " + to_text(K) + " N/m, d = " + to_text(d) + " m)";
        case BoundaryLaw::monaghan:
          return "Monaghan f2 (A = " + to_text(A) + " m/s^2, s = " + to_text(s) +
                 ", b = " + to_text(b) + " m)";
        case BoundaryLaw::lennard_jones:
          return "Lennard-Jones f3 (eps = " + to_text(eps) + " m/s^2, m = " + to_text(m) +
                 ", n = " + to_text(n) + ", l = " + to_text(l) + " m, R = " + to_text(R) + " m)";
        default:
          return "none";
      }
  }
} // namespace tribo::sph
