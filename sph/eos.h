#pragma once
/// @file Equations of state P(rho, e) and the elastic material of a particle.
///
/// Units: density kg/m^3, specific internal energy e in J/kg, pressure and moduli
/// in Pa, sound speed in m/s. Pressure is positive in compression; the Cauchy
/// stress is sigma = -P I + S.

#include <string>

namespace tribo::sph
{
  /// Pressure and sound speed of a state.
  struct PressureState
  {
    double pressure;    ///< P, Pa (positive in compression)
    double sound_speed; ///< c, m/s (already floored)
  };

  /// Parameters of the Tillotson (1962) equation of state, as in Benz and Asphaug
  /// (1994); see Tillotson::evaluate for the formulas.
  struct TillotsonParameters
  {
    double rho0;  ///< reference density, kg/m^3
    double A;     ///< bulk-modulus-like coefficient, Pa
    double B;     ///< quadratic coefficient, Pa
    double a;     ///< dimensionless
    double b;     ///< dimensionless
    double alpha; ///< dimensionless
    double beta;  ///< dimensionless
    double E0;    ///< J/kg
    double E_iv;  ///< energy of incipient vaporisation, J/kg
    double E_cv;  ///< energy of complete vaporisation, J/kg
    /// Expansion cut-off: P = 0 when rho/rho0 < this ratio and e < E_cv (no
    /// spurious tension in strongly expanded cold material). 0 disables it.
    double expansion_cutoff = 0.9;
    /// Sound-speed floor as a fraction of sqrt(A/rho0).
    double sound_speed_floor = 1.0;

    /// Granite (rho0 = 2680, A = B = 18 GPa, a = 0.5, b = 1.3, alpha = beta = 5,
    /// E0 = 16 MJ/kg, E_iv = 3.5 MJ/kg, E_cv = 18 MJ/kg).
    static TillotsonParameters granite();
    /// Basalt (rho0 = 2700, A = B = 26.7 GPa, a = 0.5, b = 1.5, alpha = beta = 5,
    /// E0 = 487 MJ/kg, E_iv = 4.72 MJ/kg, E_cv = 18.2 MJ/kg).
    static TillotsonParameters basalt();
  };

  /// Tillotson equation of state. With eta = rho/rho0, mu = eta - 1,
  /// omega = 1 + e/(E0 eta^2), z = rho0/rho - 1:
  ///
  /// - compressed or cold (rho >= rho0, or e <= E_iv):
  ///   P_c = (a + b/omega) rho e + A mu + B mu^2;
  /// - expanded and hot (rho < rho0 and e >= E_cv):
  ///   P_e = a rho e + [b rho e/omega + A mu exp(-beta z)] exp(-alpha z^2);
  /// - in between (rho < rho0, E_iv < e < E_cv):
  ///   P = [(e - E_iv) P_e + (E_cv - e) P_c] / (E_cv - E_iv);
  /// - cut-off: P = 0 when rho/rho0 < expansion_cutoff and e < E_cv.
  ///
  /// Sound speed c^2 = dP/drho|_e + (P/rho^2) dP/de|_rho (analytic derivatives of
  /// the active branch), floored at sound_speed_floor * sqrt(A/rho0).
  class Tillotson
  {
  public:
    explicit Tillotson(const TillotsonParameters &p) : p(p) {}
    /// P and c at density @p rho and specific internal energy @p e.
    PressureState evaluate(double rho, double e) const;
    /// P, dP/drho and dP/de without cut-off or floor (for tests).
    void pressure_and_derivatives(double rho, double e, double &P, double &dP_drho,
                                  double &dP_de) const;
    const TillotsonParameters &parameters() const { return p; }

  private:
    void compressed(double rho, double e, double &P, double &Pr, double &Pe) const;
    void expanded(double rho, double e, double &P, double &Pr, double &Pe) const;
    TillotsonParameters p;
  };

  /// Which equation of state a Material uses.
  enum class EosKind
  {
    linear,   ///< P = K (rho/rho0 - 1), c = sqrt(K/rho0)
    tillotson ///< Tillotson
  };

  /// An elastic solid: equation of state plus shear modulus G (Hooke's law for
  /// the deviatoric stress, see Solver).
  struct Material
  {
    std::string         name;
    EosKind             kind = EosKind::linear;
    double              rho0 = 0;          ///< reference density, kg/m^3
    double              bulk_modulus = 0;  ///< K of the linear EOS (A for Tillotson), Pa
    double              shear_modulus = 0; ///< G, Pa
    TillotsonParameters tillotson{};

    /// P and c at (rho, e). For the linear EOS, P = K (rho/rho0 - 1) and
    /// c = sqrt(K/rho0) (independent of e).
    PressureState evaluate(double rho, double e) const;
    /// Longitudinal (P-wave) speed of the small-strain solid,
    /// c_P = sqrt((K + 4G/3)/rho0), m/s; used for the CFL step.
    double longitudinal_speed() const;

    /// Linear-EOS solid with bulk modulus @p K and shear modulus @p G.
    static Material linear(double rho0, double K, double G);
    /// Granite, Tillotson, G = 9.72 GPa. The published K = 50 GPa, G = 27 GPa do
    /// not match A = 18 GPa (the small-strain bulk modulus of Tillotson is A);
    /// we keep K = A and the published Poisson ratio nu = 0.271, which gives
    /// G = A * 27/50 = 9.72 GPa (E = 24.7 GPa).
    static Material granite();
    /// Basalt, Tillotson, G = 22.7 GPa (K = A = 26.7 GPa, nu ~ 0.17).
    static Material basalt();
  };
} // namespace tribo::sph
