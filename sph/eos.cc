#include "sph/eos.h"

#include <algorithm>
#include <cmath>

namespace tribo::sph
{
  TillotsonParameters TillotsonParameters::granite()
  {
    TillotsonParameters t;
    t.rho0  = 2680;
    t.A     = 18e9;
    t.B     = 18e9;
    t.a     = 0.5;
    t.b     = 1.3;
    t.alpha = 5;
    t.beta  = 5;
    t.E0    = 16e6;
    t.E_iv  = 3.5e6;
    t.E_cv  = 18e6;
    return t;
  }

  TillotsonParameters TillotsonParameters::basalt()
  {
    TillotsonParameters t;
    t.rho0  = 2700;
    t.A     = 26.7e9;
    t.B     = 26.7e9;
    t.a     = 0.5;
    t.b     = 1.5;
    t.alpha = 5;
    t.beta  = 5;
    t.E0    = 487e6;
    t.E_iv  = 4.72e6;
    t.E_cv  = 18.2e6;
    return t;
  }

  void Tillotson::compressed(double rho, double e, double &P, double &Pr, double &Pe) const
  {
    const double eta = rho / p.rho0, mu = eta - 1;
    const double omega = 1 + e / (p.E0 * eta * eta);
    const double domega_drho = -2 * e / (p.E0 * eta * eta * eta * p.rho0);
    const double domega_de   = 1 / (p.E0 * eta * eta);
    const double f = p.a + p.b / omega;
    P  = f * rho * e + p.A * mu + p.B * mu * mu;
    Pr = f * e - p.b / (omega * omega) * domega_drho * rho * e + (p.A + 2 * p.B * mu) / p.rho0;
    Pe = f * rho - p.b / (omega * omega) * domega_de * rho * e;
  }

  void Tillotson::expanded(double rho, double e, double &P, double &Pr, double &Pe) const
  {
    const double eta = rho / p.rho0, mu = eta - 1;
    const double omega = 1 + e / (p.E0 * eta * eta);
    const double domega_drho = -2 * e / (p.E0 * eta * eta * eta * p.rho0);
    const double domega_de   = 1 / (p.E0 * eta * eta);
    const double z = p.rho0 / rho - 1, dz = -p.rho0 / (rho * rho);
    const double eb = std::exp(-p.beta * z), ea = std::exp(-p.alpha * z * z);
    const double inner = p.b * rho * e / omega + p.A * mu * eb;
    const double dinner_drho = p.b * e / omega - p.b * rho * e / (omega * omega) * domega_drho +
                               p.A / p.rho0 * eb - p.A * mu * eb * p.beta * dz;
    const double dinner_de = p.b * rho / omega - p.b * rho * e / (omega * omega) * domega_de;
    P  = p.a * rho * e + inner * ea;
    Pr = p.a * e + dinner_drho * ea + inner * ea * (-2 * p.alpha * z * dz);
    Pe = p.a * rho + dinner_de * ea;
  }

  void Tillotson::pressure_and_derivatives(double rho, double e, double &P, double &Pr,
                                           double &Pe) const
  {
    if (rho >= p.rho0 || e <= p.E_iv)
      compressed(rho, e, P, Pr, Pe);
    else if (e >= p.E_cv)
      expanded(rho, e, P, Pr, Pe);
    else
      {
        double Pc, Pcr, Pce, Px, Pxr, Pxe;
        compressed(rho, e, Pc, Pcr, Pce);
        expanded(rho, e, Px, Pxr, Pxe);
        const double d = p.E_cv - p.E_iv;
        const double we = (e - p.E_iv) / d, wc = (p.E_cv - e) / d;
        P  = we * Px + wc * Pc;
        Pr = we * Pxr + wc * Pcr;
        Pe = we * Pxe + wc * Pce + (Px - Pc) / d;
      }
  }

  PressureState Tillotson::evaluate(double rho, double e) const
  {
    double P, Pr, Pe;
    pressure_and_derivatives(rho, e, P, Pr, Pe);
    const double floor = p.sound_speed_floor * std::sqrt(p.A / p.rho0);
    const double c2 = Pr + P / (rho * rho) * Pe;
    if (rho < p.expansion_cutoff * p.rho0 && e < p.E_cv)
      P = 0;
    return {P, std::max(floor, c2 > 0 ? std::sqrt(c2) : 0.0)};
  }

  PressureState Material::evaluate(double rho, double e) const
  {
    if (kind == EosKind::tillotson)
      return Tillotson(tillotson).evaluate(rho, e);
    return {bulk_modulus * (rho / rho0 - 1), std::sqrt(bulk_modulus / rho0)};
  }

  double Material::longitudinal_speed() const
  {
    return std::sqrt((bulk_modulus + 4 * shear_modulus / 3) / rho0);
  }

  Material Material::linear(double rho0, double K, double G)
  {
    Material m;
    m.name          = "linear";
    m.kind          = EosKind::linear;
    m.rho0          = rho0;
    m.bulk_modulus  = K;
    m.shear_modulus = G;
    return m;
  }

  Material Material::granite()
  {
    Material m;
    m.name          = "granite";
    m.kind          = EosKind::tillotson;
    m.tillotson     = TillotsonParameters::granite();
    m.rho0          = m.tillotson.rho0;
    m.bulk_modulus  = m.tillotson.A;
    m.shear_modulus = 9.72e9;
    return m;
  }

  Material Material::basalt()
  {
    Material m;
    m.name          = "basalt";
    m.kind          = EosKind::tillotson;
    m.tillotson     = TillotsonParameters::basalt();
    m.rho0          = m.tillotson.rho0;
    m.bulk_modulus  = m.tillotson.A;
    m.shear_modulus = 22.7e9;
    return m;
  }
} // namespace tribo::sph
