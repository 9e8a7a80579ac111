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

#include "dem/laws/contact_law.h"
#include "dem/linalg/scaled_operator.h"
#include "dem/solvers/frictionless_problem.h"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace tribo::dem
{
  struct SweepProblem
  {
    /// The problem of @p contacts against @p state (which holds the contacts' warm-start
    /// impulses c.r), the walls kept as low-rank columns. Width 2 when @p law has friction.
    /// The operator is assembled on @p threads threads (the same bits on any number).
    SweepProblem(const std::vector<Contact> &contacts, const BodyState &state, const ContactLaw &law,
                 unsigned int threads = 1);

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
    /// Contact @p j's local solve in @p v (rows set in @p op, an operator of this problem's
    /// scaled form; @p b its b', or one that other ranks' impulses have moved,
    /// dem/parallel/distributed_apgs.h), the low-rank product kept current and, with @p also,
    /// the same changes added to it: without friction v_j = max(0, v_j - g_j) (unit
    /// diagonal); with friction the exact 2x2 Coulomb solve against the contact's own block B,
    /// u = B v_j + q (ContactLaw::solve_coulomb; v_j = 0 if q_n >= 0). With @p omega != 1 the
    /// relaxed solve, v_j <- omega v_law + (1 - omega) v_j.
    void relax(ScaledOperator &op, const ContactLaw &law, const Eigen::VectorXd &b, Eigen::VectorXd &v,
               Eigen::Index j, Eigen::VectorXd *also, double omega = 1) const
    {
      // Relaxed from an extrapolated (momentum) start, a normal impulse may fall below 0: it
      // is kept at 0, where impulse() puts it too.
      const auto set = [&](Eigen::Index k, double law_value) {
        double next = law_value;
        if (omega != 1)
          next = k == width * j ? std::max(0.0, omega * law_value + (1 - omega) * v[k])
                                : omega * law_value + (1 - omega) * v[k];
        if (next != v[k])
          {
            op.add_to_low_rank(k, next - v[k]);
            if (also)
              (*also)[k] += next - v[k];
            v[k] = next;
          }
      };
      if (width == 1)
        return set(j, std::max(0.0, v[j] - (op.row_times(v, j) + b[j])));
      const Eigen::Index     k   = 2 * j;
      const Eigen::Matrix2d &B   = own_block[j];
      const double           q_n = op.row_times(v, k) + b[k] - B(0, 0) * v[k] - B(0, 1) * v[k + 1];
      const double           q_t = op.row_times(v, k + 1) + b[k + 1] - B(1, 0) * v[k] - B(1, 1) * v[k + 1];
      const Eigen::Vector2d  next = q_n < 0 ? law.solve_coulomb(B(0, 0), B(0, 1), B(1, 0), B(1, 1), q_n, q_t)
                                            : Eigen::Vector2d::Zero();
      set(k, next[0]);
      set(k + 1, next[1]);
    }

    /// Contact @p j's natural map in N s/m at @p y (rows set in @p op, b' given as @p b) with
    /// @p g_n its normal row of A'y + b': without friction |min(y_j, g_j)| / sqrt(D_j); with
    /// friction the norm of (phi_n, phi_t) of dem/laws/law_residual.h in the scaled variables
    /// (unit normal diagonal, tangent diagonal A'_tt), times the contact's scale.
    double contact_map(const ScaledOperator &op, const Eigen::VectorXd &b, const Eigen::VectorXd &y,
                       Eigen::Index j, double g_n) const
    {
      if (width == 1)
        return std::abs(std::min(y[j], g_n)) * scaled.inv_root[j];
      const Eigen::Index k     = 2 * j;
      const double       g_t   = op.row_times(y, k + 1) + b[k + 1];
      const double       r_law = std::max(0.0, y[k] - g_n);
      const double       bound = friction * r_law;
      const double       phi_n = y[k] - r_law;
      const double       phi_t = y[k + 1] - std::clamp(y[k + 1] - g_t / own_block[j](1, 1), -bound, bound);
      return std::sqrt(phi_n * phi_n + phi_t * phi_t) * scaled.inv_root[k];
    }

    /// Contact @p i's impulse (r_n, r_t) at @p y (scaled), r_n = max(0, x_n) - gamma h,
    /// r_t = x_t (0 without friction), N s/m.
    /// The polish's neighbourhood: @p local (contacts, each marked in @p marked) grown by the
    /// contacts up to @p rings rings away in A' (ring 1: the rows of their columns) while it
    /// holds at most @p most contacts; the marks are cleared again.
    void add_rings(std::vector<Eigen::Index> &local, std::vector<char> &marked, unsigned int rings, double most) const
    {
      std::size_t last_ring = 0; // local[last_ring, ...) is the outermost ring so far
      for (unsigned int ring = 0; ring < rings && double(local.size()) <= most; ++ring)
        {
          const std::size_t inner = local.size();
          for (std::size_t q = std::exchange(last_ring, inner); q < inner; ++q)
            for (Eigen::Index k = width * local[q]; k < width * local[q] + width; ++k)
              for (Eigen::SparseMatrix<double>::InnerIterator a(scaled.A, k); a; ++a)
                if (!marked[a.row() / width])
                  {
                    marked[a.row() / width] = 1;
                    local.push_back(a.row() / width);
                  }
        }
      for (const Eigen::Index j : local)
        marked[j] = 0;
    }
    Eigen::Vector2d impulse(const Eigen::VectorXd &y, Eigen::Index i) const
    {
      const Eigen::Index k = width * i;
      return {std::max(0.0, y[k] * scaled.inv_root[k]) - cohesion[i], width == 2 ? y[k + 1] * scaled.inv_root[k + 1] : 0.0};
    }
    /// Write the impulses of @p y (scaled) into @p contacts, r_n = max(0, x_n) - gamma h,
    /// r_t = x_t (0 without friction), and apply the change to @p state's velocities.
    void apply(const Eigen::VectorXd &y, std::vector<Contact> &contacts, BodyState &state) const;

  private:
    Eigen::VectorXd cohesion; ///< gamma h per contact, N s/m
  };
} // namespace tribo::dem
