#pragma once
/// @file Linear theory of the MLP lattice (Popov and Filippov 2006, section 2)
/// and the mapping between the model's parameters and 2D elastic constants.
///
/// Linearising the interaction about the ideal lattice (spacing c = r0) gives
/// for each bond the paper's eq. (2): the force on i from j is
///   F_i = k1 (u_j - u_i) + k2 e (e . (u_j - u_i)),
/// with e the reference bond direction (fixed in the lab), k1 = k_t = n f0 / r0
/// (the return force: sin(n dphi) ~ n dphi, dphi = e_perp . (u_j - u_i)/r0) and
/// k1 + k2 = k_c = U''(r0). In the moving lattice the "reference bond vector"
/// is the lattice axis nearest to the current bond: the return force measures
/// the bond's angle from it, the potential its length from r0.
///
/// All moduli are 2D (per unit depth): stress in N/m per m of depth = Pa. With
/// the displacement gradient G_ab = du_a/dx_b, strain eps = (G + G^T)/2 and
/// rotation omega = (G - G^T)/2, the virial stress of a homogeneously deformed
/// hexagonal lattice is exactly
///   sigma = lambda tr(eps) I + 2 mu eps + C omega,
///   lambda = (sqrt(3)/4) k2,  mu = sqrt(3) (k1/2 + k2/4),  C = sqrt(3) k1,
/// using the true area per particle (sqrt(3)/2) c^2. The term C omega is the
/// resistance of the lab-fixed return forces to a rigid rotation of the bonds:
/// pure shear (omega = 0) measures mu, simple shear u_x = gamma y measures
/// sigma_xy / gamma = mu + C/2. Its divergence, (C/2)(Laplace u - grad div u),
/// adds to the bulk equation of motion, which becomes the paper's eq. (10)
/// with mu_N = mu + C/2 = sqrt(3)(k1 + k2/4), lambda_N + mu_N = (sqrt(3)/2) k2,
/// the paper's eq. (11) times 2: the paper divides by sqrt(3) c^2, twice the
/// true area per particle (settled by measurement in test_mlp.cc).
#include "mlp/particles.h"

namespace tribo::mlp
{
  /// Elastic constants of the linearised hexagonal lattice (2D; Pa, kg/m^3, m/s).
  struct HexagonalElasticity
  {
    double k1 = 0, k2 = 0; ///< eq. (2) constants, N/m^2
    double area    = 0;    ///< area per particle (sqrt(3)/2) c^2, m^2
    double density = 0;    ///< rho = m / area, kg/m^3 (per unit depth: kg/m / m^2)
    double lambda  = 0;    ///< pure-strain Lame constant (sqrt(3)/4) k2, Pa
    double mu      = 0;    ///< pure-shear modulus sqrt(3)(k1/2 + k2/4), Pa
    double rotation_modulus = 0; ///< C = sqrt(3) k1: sigma += C omega, Pa
    double simple_shear_modulus = 0; ///< sigma_xy/gamma in simple shear = mu + C/2, Pa
    double lambda_navier = 0; ///< lambda_N = sqrt(3)(k2/4 - k1), bulk equation, Pa
    double mu_navier     = 0; ///< mu_N = sqrt(3)(k1 + k2/4) = simple_shear_modulus, Pa
    double bulk_modulus  = 0; ///< K = lambda + mu = (sqrt(3)/2)(k1 + k2) = sqrt(3) k_c / 2, Pa
    double youngs_modulus = 0; ///< 2D E = 4 mu (lambda + mu)/(lambda + 2 mu), Pa
    double poisson_ratio  = 0; ///< 2D nu = lambda/(lambda + 2 mu) = k2/(4 k1 + 3 k2)
    double longitudinal_speed = 0; ///< c_L = sqrt((lambda + 2 mu)/rho), m/s
    double transverse_speed   = 0; ///< c_T = sqrt(mu_N/rho) (not sqrt(mu/rho)), m/s
  };

  /// Linear theory of a hexagonal lattice with eq. (2) constants @p k1, @p k2
  /// (N/m^2), spacing @p c (m) and particle mass @p mass (kg/m).
  HexagonalElasticity hexagonal_elasticity(double k1, double k2, double c, double mass);

  /// Elastic constants of the linearised square lattice (n = 4), Pa. Cubic
  /// symmetry: C11 = k_c, C12 = 0 (nu = 0 along the axes), pure shear
  /// C66 = k_t/2, simple shear sigma_xy/gamma = k_t. Isotropic only if
  /// C11 - C12 = 2 C66, i.e. k_t = k_c.
  struct SquareElasticity
  {
    double c11 = 0, c12 = 0, c66 = 0, simple_shear_modulus = 0;
  };

  /// Linear theory of a square lattice with bond stiffnesses @p k_c, @p k_t.
  SquareElasticity square_elasticity(double k_c, double k_t);

  /// Which moduli the mapping from (E, nu) targets.
  enum class MappingTarget
  {
    /// The pure-strain moduli (lambda, mu): static response to rotation-free
    /// deformation, e.g. a periodic patch under uniaxial stress (default).
    pure_strain,
    /// The paper's bulk (Navier) moduli (lambda_N, mu_N) of eq. (11), corrected
    /// for the area per particle: c_L and c_T follow from them.
    navier
  };

  /// k_c = U''(r0) (Pa) and f0 (N/m) of a hexagonal MLP lattice.
  struct HexagonalModel
  {
    double stiffness = 0; ///< k_c, N/m^2
    double f0        = 0; ///< return force amplitude, N/m
  };

  /// Model parameters for 2D target moduli @p youngs_modulus (Pa) and
  /// @p poisson_ratio at spacing @p r0 (m). For plane strain of a 3D material
  /// pass E/(1 - nu^2) and nu/(1 - nu). With lambda = E nu/(1 - nu^2),
  /// mu = E/(2(1 + nu)):
  ///   pure_strain: k_c = (2/sqrt(3))(lambda + mu), k_t = (2/sqrt(3))(mu - lambda);
  ///   navier:      k2 = (2/sqrt(3))(lambda + mu), k1 = mu/sqrt(3) - k2/4;
  /// and f0 = k_t r0 / 6. Return forces can only lower nu (f0 >= 0), so
  /// -1 < nu <= 1/3 is required; InputError otherwise.
  HexagonalModel hexagonal_model_for(double youngs_modulus, double poisson_ratio, double r0,
                                     MappingTarget target = MappingTarget::pure_strain);

  /// Largest angular frequency (rad/s) of the ideal lattice with bonds of
  /// stiffness @p k_c along and @p k_t across (N/m^2) and particle mass @p mass
  /// (kg/m): the maximum over the Brillouin zone of the dynamical matrix
  /// D(q) = (1/m) sum_alpha K_alpha (1 - cos(q . c e_alpha)),
  /// K_alpha = k_c e e^T + k_t e_perp e_perp^T (sampled on a 129 x 129 q-grid).
  /// Hexagonal with k_t = 0: omega_max^2 = 6 k_c / m (M point).
  double max_angular_frequency(LatticeType type, double k_c, double k_t, double mass);
} // namespace tribo::mlp
