#include "mlp/interaction.h"

#include "core/errors.h"
#include "core/serialization.h"

#include <deal.II/base/parallel.h>

#include <cmath>
#include <string>

namespace tribo::mlp
{
  void InteractionParameters::validate() const
  {
    auto fail = [](const std::string &what) { throw InputError("MLP interaction: " + what); };
    if (!(r0 > 0))
      fail("r0 must be > 0 m, got " + to_text(r0));
    if (!(stiffness > 0))
      fail("stiffness k_c = U''(r0) must be > 0 Pa, got " + to_text(stiffness));
    if (!(width > 0))
      fail("Morse width a r0 must be > 0, got " + to_text(width));
    if (!(switch_start > 1 && cutoff > switch_start))
      fail("need 1 < switch start < cutoff (in units of r0), got switch start " +
           to_text(switch_start) + ", cutoff " + to_text(cutoff));
    if (n != 4 && n != 6)
      fail("symmetry order n must be 4 or 6, got " + std::to_string(n));
    if (!(f0 >= 0))
      fail("return force amplitude f0 must be >= 0 N/m, got " + to_text(f0));
    if (n == 6 && cutoff >= std::sqrt(3.0))
      fail("cutoff " + to_text(cutoff) + " r0 reaches the second neighbours of a hexagonal "
           "lattice (sqrt(3) r0)");
    if (n == 4 && cutoff >= std::sqrt(2.0))
      fail("cutoff " + to_text(cutoff) + " r0 reaches the diagonal neighbours of a square "
           "lattice (sqrt(2) r0), which sit on unstable axes of the n = 4 return force");
  }

  PairPotential::PairPotential(const InteractionParameters &p)
  {
    p.validate();
    r0  = p.r0;
    a   = p.width / p.r0;
    D   = p.stiffness / (2 * a * a);
    r_s = p.switch_start * p.r0;
    r_c = p.cutoff * p.r0;
  }

  double PairPotential::switch_value(double r, double &dsdr) const
  {
    if (r <= r_s)
      {
        dsdr = 0;
        return 1;
      }
    if (r >= r_c)
      {
        dsdr = 0;
        return 0;
      }
    const double w = r_c - r_s, x = (r - r_s) / w;
    dsdr = 6 * x * (x - 1) / w;
    return 1 - x * x * (3 - 2 * x);
  }

  double PairPotential::energy(double r) const
  {
    double       dsdr, e;
    const double S = switch_value(r, dsdr);
    return S == 0 ? 0 : morse_well(r, e) * S;
  }

  double PairPotential::derivative(double r) const
  {
    double       dsdr, e;
    const double S = switch_value(r, dsdr);
    if (S == 0)
      return 0;
    const double u = morse_well(r, e);
    return 2 * D * a * (1 - e) * e * S + u * dsdr;
  }

  Interaction::Interaction(const InteractionParameters &p) : prm(p), pot(p) {}

  namespace
  {
    /// cos(n phi) and sin(n phi) from the unit vector (c, s) = (cos phi, sin phi)
    /// by repeated complex multiplication (no trigonometric calls).
    inline void multiple_angle(double c, double s, unsigned int n, double &cn, double &sn)
    {
      cn = c;
      sn = s;
      for (unsigned int k = 1; k < n; ++k)
        {
          const double t = cn * c - sn * s;
          sn             = sn * c + cn * s;
          cn             = t;
        }
    }
  } // namespace

  Vec2 Interaction::central_force(const Vec2 &d) const
  {
    const double r = d.norm();
    if (!(r < pot.cutoff()) || r == 0)
      return Vec2::Zero();
    return (pot.derivative(r) / r) * d;
  }

  Vec2 Interaction::return_force(const Vec2 &d) const
  {
    const double r = d.norm();
    if (!(r < pot.cutoff()) || r == 0 || prm.f0 == 0)
      return Vec2::Zero();
    double       dsdr;
    const double S = pot.switch_value(r, dsdr);
    const double c = d.x() / r, s = d.y() / r;
    double       cn, sn;
    multiple_angle(c, s, prm.n, cn, sn);
    if (prm.form == ReturnForceForm::paper)
      return (prm.f0 * S * sn) * Vec2(-s, c);
    const double g      = prm.r0 / r;
    const double radial = prm.f0 * prm.r0 / prm.n * (1 - cn) * dsdr;
    return (prm.f0 * g * S * sn) * Vec2(-s, c) + radial * Vec2(c, s);
  }

  Vec2 Interaction::force(const Vec2 &d) const
  {
    // Fused central + return force (one sqrt, one exp): the hot loop.
    const double r2 = d.squaredNorm();
    const double rc = pot.cutoff();
    if (!(r2 < rc * rc) || r2 == 0)
      return Vec2::Zero();
    const double r = std::sqrt(r2);
    double       dsdr;
    const double S = pot.switch_value(r, dsdr);
    const double c = d.x() / r, s = d.y() / r;
    // Central: F_i = U'(r) d/r.
    const double a  = prm.width / prm.r0;
    const double D  = pot.depth();
    const double e  = std::exp(-a * (r - prm.r0));
    const double u  = D * ((1 - e) * (1 - e) - 1);
    double radial   = 2 * D * a * (1 - e) * e * S + u * dsdr;
    double tangent  = 0;
    if (prm.f0 != 0)
      {
        double cn, sn;
        multiple_angle(c, s, prm.n, cn, sn);
        if (prm.form == ReturnForceForm::paper)
          tangent = prm.f0 * S * sn;
        else
          {
            tangent = prm.f0 * (prm.r0 / r) * S * sn;
            radial += prm.f0 * prm.r0 / prm.n * (1 - cn) * dsdr;
          }
      }
    return Vec2(radial * c - tangent * s, radial * s + tangent * c);
  }

  double Interaction::energy(const Vec2 &d) const
  {
    const double r = d.norm();
    if (!(r < pot.cutoff()))
      return 0;
    double e = pot.energy(r);
    if (prm.form == ReturnForceForm::potential && prm.f0 != 0 && r > 0)
      {
        double       dsdr, cn, sn;
        const double S = pot.switch_value(r, dsdr);
        multiple_angle(d.x() / r, d.y() / r, prm.n, cn, sn);
        e += prm.f0 * prm.r0 / prm.n * (1 - cn) * S;
      }
    return e;
  }

  ForceField::ForceField(const InteractionParameters &p, double skin)
    : model(p), list(model.cutoff(), skin < 0 ? 0.3 * p.r0 : skin)
  {}

  void ForceField::compute(Particles &particles, const Box &box)
  {
    list.update(particles, box);
    const auto        &pairs   = list.pairs();
    const unsigned int n_pairs = static_cast<unsigned int>(pairs.size());
    const unsigned int n       = particles.size();
    pair_force.resize(n_pairs);
    const Vec2 *x = particles.position.data();

    auto pair_pass = [&](unsigned int begin, unsigned int end) {
      for (unsigned int p = begin; p < end; ++p)
        pair_force[p] = model.force(box.minimum_image(x[pairs[p].second] - x[pairs[p].first]));
    };
    auto gather_pass = [&](unsigned int begin, unsigned int end) {
      for (unsigned int i = begin; i < end; ++i)
        {
          Vec2 f = particles.external_force[i];
          for (auto it = list.incidence_begin(i); it != list.incidence_end(i); ++it)
            {
              if (it->sign > 0)
                f += pair_force[it->pair];
              else
                f -= pair_force[it->pair];
            }
          particles.force[i] = f;
        }
    };
    if (parallel)
      {
        dealii::parallel::apply_to_subranges(0u, n_pairs, pair_pass, 4096);
        dealii::parallel::apply_to_subranges(0u, n, gather_pass, 2048);
      }
    else
      {
        pair_pass(0, n_pairs);
        gather_pass(0, n);
      }
    pair_evaluations += n_pairs;
  }

  double ForceField::potential_energy(const Particles &particles, const Box &box)
  {
    list.update(particles, box);
    double e = 0;
    for (const auto &p : list.pairs())
      e += model.energy(
        box.minimum_image(particles.position[p.second] - particles.position[p.first]));
    return e;
  }

  Eigen::Matrix2d ForceField::virial_stress(const Particles &particles, const Box &box,
                                            double area)
  {
    list.update(particles, box);
    Eigen::Matrix2d s = Eigen::Matrix2d::Zero();
    for (const auto &p : list.pairs())
      {
        const Vec2 d =
          box.minimum_image(particles.position[p.second] - particles.position[p.first]);
        s += model.force(d) * d.transpose();
      }
    return s / area;
  }

  void ForceField::save(CheckpointOut &ar) const
  {
    list.save(ar);
    ar << pair_evaluations;
  }

  void ForceField::load(CheckpointIn &ar)
  {
    list.load(ar);
    ar >> pair_evaluations;
  }
} // namespace tribo::mlp
