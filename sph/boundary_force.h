#pragma once
/// @file Radial forces between particles of two different bodies (block and
/// substrate), Maveyraud et al. (1999) eqs. (42)-(49).
///
/// Sign convention: value(r) > 0 is repulsive. For particles i, j of different
/// bodies at separation r_ij = x_i - x_j, the force on i is
/// F_i = s_ij f(|r_ij|) r_ij/|r_ij| and F_j = -F_i (momentum conserved), where the
/// scale s_ij = 1 for the spring law (f is a force, N, or N/m in 2D) and
/// s_ij = (m_i + m_j)/2 for the Monaghan and Lennard-Jones laws, which the paper
/// gives per unit mass (f in m/s^2).

#include <string>

namespace tribo::sph
{
  /// Which boundary law acts between bodies.
  enum class BoundaryLaw
  {
    none,         ///< bodies interact through nothing
    spring,       ///< f1(r) = -K (r - d) for r < d, else 0 (K in N/m, d in m)
    monaghan,     ///< f2: A (l/r)^s for r < l, D (r - b)^2 for l < r < b, else 0
    lennard_jones ///< f3: eps ((l/r)^m - (l/r)^n) for r < r_c, A3 (R-r)^2 + D3 (R-r) for r_c < r < R
  };

  /// A boundary law with its parameters, and the derived constants that make it
  /// continuous (paper's conditions).
  ///
  /// - spring (42): cut-off d (the paper takes d = h), stiffness K. A suggested K
  ///   is K ~ E h (the paper's eq. 25 estimate of a particle's stiffness).
  /// - Monaghan (43): amplitude A (m/s^2), exponent s, range b (paper: b = h).
  ///   Continuity of value and slope at r = l gives l = s b/(s + 2) and
  ///   D = A ((s + 2)/(2b))^2.
  /// - Lennard-Jones (44): eps (m/s^2), exponents m > n, zero l (paper: l = dp,
  ///   the lattice spacing) and range R (paper: R = 3 dp/2). The minimum is at
  ///   r_c = l (m/n)^(1/(m-n)) (eq. 45); continuity of value and slope at r_c
  ///   (eqs. 46, 47) gives
  ///   D3 = 2 eps/(R - r_c) [(n/m)^(m/(m-n)) - (n/m)^(n/(m-n))] and
  ///   A3 = -D3 / (2 (R - r_c)). Eq. (49) suggests
  ///   eps = (4/9) c_s^2/h (n/m)^(1/(m-n)) / (m - n), see lennard_jones_epsilon.
  class BoundaryForce
  {
  public:
    BoundaryForce() = default;
    /// f1 with stiffness @p K (N/m) and range @p d (m).
    static BoundaryForce spring(double K, double d);
    /// f2 with amplitude @p A (m/s^2), exponent @p s and range @p b (m).
    static BoundaryForce monaghan(double A, double s, double b);
    /// f3 with depth scale @p eps (m/s^2), exponents @p m > @p n, zero @p l (m), range @p R (m).
    static BoundaryForce lennard_jones(double eps, double m, double n, double l, double R);
    /// The paper's eq. (49) for eps, m/s^2 (c_s sound speed m/s, h m).
    static double lennard_jones_epsilon(double c_s, double h, double m, double n);

    /// f(r): force (spring) or force per unit mass (others), positive repulsive.
    double value(double r) const;
    /// Largest distance at which the law acts, m.
    double range() const;
    /// True if the law is given per unit mass (scale (m_i + m_j)/2).
    bool per_unit_mass() const { return law == BoundaryLaw::monaghan || law == BoundaryLaw::lennard_jones; }
    BoundaryLaw kind() const { return law; }
    /// Position r_c (f3) or l (f2) where the branches join, m.
    double junction() const { return law == BoundaryLaw::lennard_jones ? rc : l; }
    /// Short description with the parameters, for logs and errors.
    std::string describe() const;

  private:
    BoundaryLaw law = BoundaryLaw::none;
    double      K = 0, d = 0;                         // spring
    double      A = 0, s = 0, b = 0, l = 0, D = 0;    // Monaghan (l shared with LJ)
    double      eps = 0, m = 0, n = 0, R = 0, rc = 0; // Lennard-Jones
    double      A3 = 0, D3 = 0;
  };
} // namespace tribo::sph
