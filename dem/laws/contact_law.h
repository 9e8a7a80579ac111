#pragma once
/// @file Contact laws of the NSCD engine and their closed-form local solves.
///
/// Sign conventions, for a contact between discs 0 and 1:
/// - the normal n points from disc 0 to disc 1, the tangent is t = (-n_y, n_x);
/// - the gap g = |x_1 - x_0| - R_0 - R_1 (m) is negative for an overlap;
/// - the local velocity u = (u_n, u_t) is the velocity of disc 1 relative to
///   disc 0 at the contact point, u_n > 0 when the discs separate;
/// - the impulse r = (r_n, r_t) = h F (N s/m) acts on disc 1 and -r on disc 0;
///   r_n > 0 pushes the discs apart (compression), r_n < 0 pulls (cohesion).
///
/// Both laws act on the gap at the end of the step predicted from the
/// Moreau-Jean position update, g_end = g + theta h u_n, where g is the gap at
/// the predicted configuration q + (1 - theta) h v_begin. Cohesion gamma (N/m)
/// acts while g <= d_w: the laws are written on the shifted impulse
/// r~_n = r_n + gamma h >= 0 (so r_n >= -gamma h, Cao et al. 2011 eq. 7).
/// - IQS (inelastic quasi-shock): 0 <= r~_n  _|_  u_n + max(0, g)/(theta h) >= 0:
///   a closing gap is closed exactly at the end of the step and an existing
///   overlap is frozen (never pushed out). Cao et al. eq. (7). With an overlap
///   recovery beta > 0 the shift for g < 0 is beta g/(theta h): a fraction beta
///   of the overlap is pushed out per step.
/// - ELAS (elastic): F~_n = max(0, -k g_end), i.e. r~_n = h k max(0, -(g + theta h u_n)),
///   solved in closed form as a Signorini problem with the shift g/(theta h)
///   and the augmented diagonal W_nn + 1/(theta k h^2). Cao et al. eq. (8)
///   (written there with the opposite sign for gamma).
/// - Optional Coulomb friction mu: |r_t| <= mu r~_n, acting on the shifted impulse.

#include "core/errors.h"
#include "core/parameter_section.h"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

namespace tribo::dem
{
  /// The contact law shared by all contacts of a scene.
  struct ContactLaw
  {
    enum class Type
    {
      iqs,
      elas
    };
    Type   type            = Type::iqs;
    double cohesion        = 0; ///< gamma, N/m (force per unit depth)
    double cohesion_range  = 0; ///< d_w, m
    double stiffness       = 0; ///< k, N/m^2 (force per unit depth per metre of overlap), ELAS only
    double friction        = 0; ///< Coulomb coefficient mu, dimensionless
    /// IQS only: fraction beta in [0, 1] of an existing overlap pushed out per step
    /// (shift beta g/(theta h) for g < 0). 0 freezes overlaps (the paper's IQS);
    /// beta > 0 stops NLGS errors from accumulating into overlaps.
    double overlap_recovery = 0;
    /// Pairs closer than this gap enter the contact list, m; 0: the run's choice (a tenth
    /// of the smallest radius). Read with the law (its entry is in the law's subsection);
    /// the law itself does not use it: MoreauJean takes the distance the run settles on.
    double detection_distance = 0;
    /// The case subsection the law was read from: its messages name entries through it.
    ParameterSection section;

    /// Declare the law's entries, and Detection distance, in the current subsection of
    /// @p prm (the caller enters and leaves it).
    static void declare(dealii::ParameterHandler &prm);
    /// The law of subsection @p section of @p file, checked; InputError names the file,
    /// the line and the entry.
    static ContactLaw parse(const ParameterFile &file, const std::string &section);

    /// The terms of one contact's local problem that depend on its gap.
    struct Terms
    {
      double cohesion_impulse; ///< gamma h if g <= d_w, else 0 (N s/m)
      double shift;            ///< velocity shift b (m/s): max(0,g)/(theta h) (IQS), g/(theta h) (ELAS)
      double compliance;       ///< added to W_nn: 0 (IQS), 1/(theta k h^2) (ELAS), s m/kg
    };

    /// Terms of a contact with gap @p g (m) for step @p h (s) and @p theta.
    Terms terms(double g, double h, double theta) const
    {
      Terms t;
      t.cohesion_impulse = (cohesion > 0 && g <= cohesion_range) ? cohesion * h : 0;
      if (type == Type::iqs)
        {
          t.shift      = (g > 0 ? g : overlap_recovery * g) / (theta * h);
          t.compliance = 0;
        }
      else
        {
          t.shift      = g / (theta * h);
          t.compliance = 1 / (theta * stiffness * h * h);
        }
      return t;
    }

    /// Closed-form local solve. @p W is the contact's own 2x2 Delassus block
    /// (m/s per N s/m), @p u_other the local velocity produced by
    /// the free motion and every other impulse (u = W r + u_other). Returns r.
    /// With friction the 2x2 problem is solved exactly by enumeration
    /// (solve_coulomb()); throws RunError if no case satisfies the law.
    Eigen::Vector2d solve(const Eigen::Matrix2d &W, const Eigen::Vector2d &u_other,
                          const Terms &t) const
    {
      const double gh = t.cohesion_impulse;
      // Shifted problem: u = W~ r~ + q, with q = u_other - W (gh, 0) + (b, 0) and W~ the
      // block with the law's compliance added to W_nn.
      const double qn  = u_other.x() - W(0, 0) * gh + t.shift;
      const double qt  = u_other.y() - W(1, 0) * gh;
      const double Wnn = W(0, 0) + t.compliance;
      Eigen::Vector2d r(0, 0);
      if (friction <= 0)
        r.x() = qn < 0 ? -qn / Wnn : 0;
      else if (qn < 0) // closing: the no-contact case (r~ = 0, u_n = q_n) fails the law
        r = solve_coulomb(Wnn, W(0, 1), W(1, 0), W(1, 1), qn, qt);
      r.x() -= gh;
      return r;
    }

    /// The frictional local problem u = W~ r~ + q with q_n < 0 (no contact would
    /// interpenetrate), 0 <= r~_n _|_ u_n >= 0, |r~_t| <= mu r~_n, u_t = 0 if
    /// |r~_t| < mu r~_n, else r~_t = -mu r~_n sign(u_t). Enumerates the cases in the
    /// order stick (u = 0), slide with s = sign of the stick trial's r~_t, slide with -s
    /// (u_n = 0, r~_t = s mu r~_n, r~_n = -q_n / (W~_nn + s mu W~_nt), valid if r~_n >= 0
    /// and s u_t <= 0), and returns the first that satisfies the law (a stick accepted within
    /// round-off of the cone's edge is put on the edge: the returned impulse is in the cone). A coupled block
    /// (W_nt != 0: clumps, half-discs) can make the stick trial's sign wrong, and its
    /// sliding denominator vanish or turn negative; the enumeration handles both.
    /// Throws RunError, with the block and q, if no case satisfies the law.
    Eigen::Vector2d solve_coulomb(double Wnn, double Wnt, double Wtn, double Wtt, double qn,
                                  double qt) const
    {
      constexpr double tol = 1e-10; // relative, for round-off at the case boundaries
      const double     det = Wnn * Wtt - Wnt * Wtn;
      double           s   = 1;
      if (det > 0)
        {
          const double rn = (-qn * Wtt + qt * Wnt) / det;
          const double rt = (-qt * Wnn + qn * Wtn) / det;
          if (rn >= 0 && std::abs(rt) <= friction * rn * (1 + tol))
            return {rn, std::clamp(rt, -friction * rn, friction * rn)}; // on the cone within round-off
          s = rt >= 0 ? 1.0 : -1.0;
        }
      for (const double sign : {s, -s})
        {
          const double denom = Wnn + sign * friction * Wnt;
          if (!(denom > 0))
            continue; // r~_n = -q_n / denom would be negative or unbounded
          const double rn = -qn / denom, rt = sign * friction * rn;
          const double ut = Wtn * rn + Wtt * rt + qt;
          if (sign * ut <= tol * (std::abs(Wtn * rn) + std::abs(Wtt * rt) + std::abs(qt)))
            return {rn, rt};
        }
      std::ostringstream os;
      os << "the frictional local problem has no solution (mu = " << friction << ", W~ = [" << Wnn
         << ", " << Wnt << "; " << Wtn << ", " << Wtt << "], q = (" << qn << ", " << qt
         << ")): the contact's Delassus block is not positive definite";
      throw RunError(os.str());
    }
  };
} // namespace tribo::dem
