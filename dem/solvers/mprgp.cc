#include "dem/solvers/mprgp.h"

#include "dem/linalg/scaled_operator.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace tribo::dem
{
  namespace
  {
    using Index = Eigen::Index;

    /// Reductions of a product pass: p.A'p, g.p and the largest feasible step along -p.
    struct ProductSums
    {
      double pAp = 0, gp = 0, to_bound = std::numeric_limits<double>::infinity();
      void   merge(const ProductSums &o)
      {
        pAp += o.pAp;
        gp += o.gp;
        to_bound = std::min(to_bound, o.to_bound);
      }
    };

    /// Reductions of a split pass (file comment of mprgp.h): the natural map, ||beta||^2,
    /// phi~.phi and phi.A'p, the sum and count of the loaded impulses x_j > 0, and the largest
    /// closing velocity max(0, -u~_n) (m/s).
    struct SplitSums
    {
      double worst = 0, beta2 = 0, proportional = 0, phi_Ap = 0, loaded_sum = 0, loaded = 0, closing = 0;
      /// The natural map over the mean loaded impulse (over @p fallback without one).
      double relative(double fallback) const
      {
        return worst / (loaded > 0 ? loaded_sum / loaded : fallback);
      }
      void merge(const SplitSums &o)
      {
        loaded_sum += o.loaded_sum;
        loaded += o.loaded;
        worst   = std::max(worst, o.worst);
        closing = std::max(closing, o.closing);
        beta2 += o.beta2;
        proportional += o.proportional;
        phi_Ap += o.phi_Ap;
      }
    };
  } // namespace

  SolveReport MprgpSolver::solve_problem(std::vector<Contact> &contacts, BodyState &state, const ContactLaw &law)
  {
    SolveReport report;
    // The walls (bodies with many contacts) as low-rank terms: A' + U'U'^T, so that a
    // product costs O(nnz(A') + n k) instead of the walls' dense blocks.
    const FrictionlessProblem lcp(contacts, state, true, prm.threads);
    const Index               n = lcp.size();
    // The scaled problem (file comment).
    FrictionlessProblem::Scaled       scaled   = lcp.scaled();
    const Eigen::VectorXd            &inv_root = scaled.inv_root;
    const Eigen::VectorXd            &b        = scaled.b;
    Eigen::VectorXd                  &y        = scaled.y;
    ScaledOperator     op(scaled);
    const double       alpha   = 1.9 / op.norm_bound();
    const double       gamma2  = 1.0; // Gamma^2
    const unsigned int threads = prm.threads;
    auto set_low_rank_product = [&](const Eigen::VectorXd &v) { op.set_vector(v); };
    auto times                = [&](const Eigen::VectorXd &v, Index j) { return op.row_times(v, j); };

    Eigen::VectorXd g(n), p(n), Ap(n), phi(n), beta(n);
    // phi_j, beta_j and the split sums of entry j; with @p Ap_known, also phi.A'p.
    auto split_entry = [&](Index j, SplitSums &s, bool with_Ap) {
      s.worst   = std::max(s.worst, std::abs(std::min(y[j], g[j])) * inv_root[j]);
      s.closing = std::max(s.closing, -g[j] / inv_root[j]); // u~_n = g sqrt(D)
      if (y[j] > 0)
        {
          phi[j]  = g[j];
          beta[j] = 0;
          s.proportional += std::min(y[j] / alpha, g[j]) * g[j];
          if (with_Ap)
            s.phi_Ap += phi[j] * Ap[j];
          s.loaded_sum += y[j] * inv_root[j];
          s.loaded += 1;
        }
      else
        {
          phi[j]  = 0;
          beta[j] = std::min(g[j], 0.0);
          s.beta2 += beta[j] * beta[j];
        }
    };
    // g = A'y + b, then the split; p = phi.
    auto gradient_and_split = [&]() {
      ++report.iterations;
      set_low_rank_product(y);
      return over_chunks<SplitSums>(n, threads, [&](Index first, Index last) {
        SplitSums s;
        for (Index j = first; j < last; ++j)
          {
            g[j] = times(y, j) + b[j];
            split_entry(j, s, false);
            p[j] = phi[j];
          }
        return s;
      });
    };
    // Ap = A' d and the product sums along d.
    auto product = [&](const Eigen::VectorXd &d) {
      ++report.iterations;
      set_low_rank_product(d);
      return over_chunks<ProductSums>(n, threads, [&](Index first, Index last) {
        ProductSums s;
        for (Index j = first; j < last; ++j)
          {
            Ap[j] = times(d, j);
            s.pAp += d[j] * Ap[j];
            s.gp += g[j] * d[j];
            if (d[j] > 0)
              s.to_bound = std::min(s.to_bound, y[j] / d[j]);
          }
        return s;
      });
    };
    // y -= step d, g -= step A'd, then the split (with phi.A'p when @p cg).
    auto move = [&](const Eigen::VectorXd &d, double step, bool cg) {
      return over_chunks<SplitSums>(n, threads, [&](Index first, Index last) {
        SplitSums s;
        for (Index j = first; j < last; ++j)
          {
            y[j] -= step * d[j];
            g[j] -= step * Ap[j];
            split_entry(j, s, cg);
          }
        return s;
      });
    };
    auto set_p = [&](double coeff) { // p = phi - coeff p
      over_chunks<SplitSums>(n, threads, [&](Index first, Index last) {
        for (Index j = first; j < last; ++j)
          p[j] = phi[j] - coeff * p[j];
        return SplitSums{};
      });
    };

    SplitSums split = gradient_and_split();
    // With IQS the solve also aims at the gap target, which a converged step must meet: its
    // largest gap violation theta h max(0, -u~_n).
    const double gap_target = law.type == ContactLaw::Type::iqs ? prm.gap_target : 0.0;
    while (split.relative(lcp.scale) > prm.residual_target ||
           (gap_target > 0 && step_theta_h * split.closing > gap_target))
      {
        if (report.iterations >= prm.max_iterations)
          {
            report.converged = false;
            break;
          }
        if (split.beta2 <= gamma2 * split.proportional)
          {
            const ProductSums along = product(p);
            // Along a direction of zero curvature (A' is singular for redundant contacts)
            // f is linear: the step goes to the bound.
            const double step = along.pAp > 0 ? along.gp / along.pAp
                                              : std::numeric_limits<double>::infinity();
            if (std::isinf(step) && std::isinf(along.to_bound))
              {
                report.converged = false; // f unbounded below along -p: cannot happen
                break;                    // with a mobile body at every contact
              }
            if (step <= along.to_bound)
              {
                // Conjugate-gradient step.
                split = move(p, step, true);
                set_p(split.phi_Ap / along.pAp);
              }
            else
              {
                // Expansion step: to the bound along p, then the fixed-length projected
                // gradient step on the free gradient there.
                move(p, along.to_bound, false);
                over_chunks<SplitSums>(n, threads, [&](Index first, Index last) {
                  for (Index j = first; j < last; ++j)
                    if (y[j] > 0)
                      y[j] = std::max(0.0, y[j] - alpha * g[j]);
                  return SplitSums{};
                });
                split = gradient_and_split();
              }
          }
        else
          {
            // Proportioning step along the chopped gradient, exact line search.
            const ProductSums along = product(beta);
            split = move(beta, split.beta2 / along.pAp, false);
            p     = phi;
          }
      }
    // A CG step that reached a bound may leave y_j a round-off below 0: apply() projects.
    lcp.apply(y.cwiseProduct(inv_root), contacts, state);
    return report;
  }
} // namespace tribo::dem
