#pragma once
/// @file The contact problem of a step as the Gauss-Seidel sweeps of APGS (dem/solvers/apgs.h) see it:
/// scaled variables, one row per contact without friction, two with Coulomb friction.
///
/// Frictionless (width 1): the scaled problem of dem/solvers/frictionless_problem.h, y = D^(1/2) r~,
/// the operator A' + U'U'^T with a unit diagonal.
///
/// Coulomb friction mu (width 2): contact i has rows 2i (normal) and 2i + 1 (tangent) of the
/// full Delassus operator (dem/linalg/delassus.h), x = (r~_n, r_t) = (r_n + gamma h, r_t) (N s/m),
///     u~ = (W + C) x + b,  b = u_free + (shift, 0) - W (gamma h, 0)      (m/s),
/// with C the ELAS compliance on the normal rows (dem/laws/contact_law.h). Both components of a
/// contact share one scale s_i = (W_nn,i + C_i)^(-1/2): y = x / s_i, A' = S (W + C) S,
/// b' = S b, so that the normal diagonal is 1 and the cone |y_t| <= mu y_n is the law's own.
/// The law of each contact (0 <= y_n _|_ u~_n >= 0, |y_t| <= mu y_n, u_t = 0 while
/// |y_t| < mu y_n, else y_t = -mu y_n sign(u_t)) is solved locally in closed form by
/// ContactLaw::solve_coulomb() against the contact's own 2x2 block of A' + U'U'^T (own_block).

#include "dem/solvers/frictionless_problem.h"

#include <Eigen/Core>

#include <vector>

namespace tribo::dem
{
  struct SweepProblem
  {
    /// The problem of @p contacts against @p state (which holds the contacts' warm-start
    /// impulses c.r), the walls kept as low-rank columns. Width 2 when @p law has friction.
    SweepProblem(const std::vector<Contact> &contacts, const BodyState &state, const ContactLaw &law);

    unsigned int width;    ///< rows per contact: 1 (frictionless) or 2 (Coulomb)
    double       friction; ///< mu, 0 without friction
    /// Operator A' + U'U'^T, b', the warm start y and inv_root = s (per row: a contact's
    /// rows share their scale).
    FrictionlessProblem::Scaled scaled;
    /// Width 2: each contact's own 2x2 block of A' + U'U'^T (normal, tangent).
    std::vector<Eigen::Matrix2d> own_block;
    /// The warm start's mean loaded impulse r~_n (N s/m), or without one the mean
    /// |b_n| / (W_nn + C): the scale of relative tests when nothing is loaded.
    double scale = 0;

    Eigen::Index n_contacts() const { return Eigen::Index(cohesion.size()); }
    /// Write the impulses of @p y (scaled) into @p contacts, r_n = max(0, x_n) - gamma h,
    /// r_t = x_t (0 without friction), and apply the change to @p state's velocities.
    void apply(const Eigen::VectorXd &y, std::vector<Contact> &contacts, BodyState &state) const;

  private:
    Eigen::VectorXd cohesion; ///< gamma h per contact, N s/m
  };
} // namespace tribo::dem
