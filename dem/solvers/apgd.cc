#include "dem/solvers/apgd.h"

#include "dem/linalg/scaled_operator.h"

#include <algorithm>
#include <cmath>

namespace tribo::dem
{
  namespace
  {
    using Index = Eigen::Index;

    /// Reductions of a product pass at a point v: v.A'v, b'.v, the natural map, the sum and
    /// count of the loaded impulses x_j > 0, |A'v|^2 (for the power iterations) and the
    /// largest closing velocity max(0, -u~_n) (m/s).
    struct PointSums
    {
      double vAv = 0, bv = 0, worst = 0, loaded_sum = 0, loaded = 0, norm2 = 0, closing = 0;
      void   merge(const PointSums &o)
      {
        vAv += o.vAv;
        bv += o.bv;
        worst   = std::max(worst, o.worst);
        closing = std::max(closing, o.closing);
        loaded_sum += o.loaded_sum;
        loaded += o.loaded;
        norm2 += o.norm2;
      }
      /// f(v) = v.A'v / 2 + b'.v
      double energy() const { return 0.5 * vAv + bv; }
      /// The natural map over the mean loaded impulse (over @p fallback without one).
      double relative(double fallback) const
      {
        return worst / (loaded > 0 ? loaded_sum / loaded : fallback);
      }
    };

    /// Iterations of the power method from a fixed start: an estimate (from below)
    /// of the largest eigenvalue of the operator.
    constexpr int power_iterations = 10;
    /// The estimate's safety factor.
    constexpr double power_margin = 1.1;
  } // namespace

  SolveReport ApgdSolver::solve_problem(std::vector<Contact> &contacts, BodyState &state, const ContactLaw &law)
  {
    SolveReport report;
    const FrictionlessProblem   lcp(contacts, state, true, prm.threads);
    const Index                 n = lcp.size();
    FrictionlessProblem::Scaled scaled = lcp.scaled();
    const Eigen::VectorXd      &inv_root = scaled.inv_root;
    const Eigen::VectorXd      &b        = scaled.b;
    Eigen::VectorXd            &y        = scaled.y;
    ScaledOperator              op(scaled);
    const unsigned int          threads = prm.threads;

    // out = (A' + U'U'^T) v and the sums at v.
    auto product = [&](const Eigen::VectorXd &v, Eigen::VectorXd &out) {
      ++report.iterations;
      op.set_vector(v);
      return over_chunks<PointSums>(n, threads, [&](Index first, Index last) {
        PointSums s;
        for (Index j = first; j < last; ++j)
          {
            out[j] = op.row_times(v, j);
            s.vAv += v[j] * out[j];
            s.bv += b[j] * v[j];
            s.worst   = std::max(s.worst, std::abs(std::min(v[j], out[j] + b[j])) * inv_root[j]);
            s.closing = std::max(s.closing, -(out[j] + b[j]) / inv_root[j]); // u~_n = g' sqrt(D)
            if (v[j] > 0)
              {
                s.loaded_sum += v[j] * inv_root[j];
                s.loaded += 1;
              }
            s.norm2 += out[j] * out[j];
          }
        return s;
      });
    };

    // L: the power method, bounded by the column-sum bound.
    Eigen::VectorXd trial = Eigen::VectorXd::Constant(n, 1.0 / std::sqrt(double(n))), A_trial(n);
    double          L     = 0;
    for (int k = 0; k < power_iterations; ++k)
      {
        L = std::sqrt(product(trial, A_trial).norm2);
        if (!(L > 0))
          break;
        trial = A_trial / L;
      }
    L = std::min(power_margin * L, op.norm_bound());
    if (!(L > 0))
      L = op.norm_bound();

    y = y.cwiseMax(0.0);
    Eigen::VectorXd Ay(n);
    PointSums       at_y = product(y, Ay);
    Eigen::VectorXd z = y, Az = Ay;
    double          t          = 1;
    bool            restarted  = true; // z == y
    // f changes below this are round-off, not an increase.
    auto increased = [](double f_new, double f_old) {
      return f_new - f_old > 1e-13 * (std::abs(f_new) + std::abs(f_old));
    };
    // With IQS the solve also aims at the gap target, which a converged step must meet: its
    // largest gap violation theta h max(0, -u~_n).
    const double gap_target = law.type == ContactLaw::Type::iqs ? prm.gap_target : 0.0;
    const auto   open = [&](const PointSums &at) {
      return at.relative(lcp.scale) > prm.residual_target || (gap_target > 0 && step_theta_h * at.closing > gap_target);
    };
    while (open(at_y))
      {
        if (report.iterations >= prm.max_iterations)
          {
            report.converged = false;
            break;
          }
        over_chunks<NoSums>(n, threads, [&](Index first, Index last) {
          for (Index j = first; j < last; ++j)
            trial[j] = std::max(0.0, z[j] - (Az[j] + b[j]) / L);
          return NoSums{};
        });
        const PointSums at_trial = product(trial, A_trial);
        if (increased(at_trial.energy(), at_y.energy()))
          {
            // A projected gradient step from y itself that raises f: L was too small.
            if (restarted)
              L *= 2;
            z         = y;
            Az        = Ay;
            t         = 1;
            restarted = true;
            continue;
          }
        const double t_next = 0.5 * (1 + std::sqrt(1 + 4 * t * t));
        const double beta   = (t - 1) / t_next;
        over_chunks<NoSums>(n, threads, [&](Index first, Index last) {
          for (Index j = first; j < last; ++j)
            {
              z[j]  = trial[j] + beta * (trial[j] - y[j]);
              Az[j] = A_trial[j] + beta * (A_trial[j] - Ay[j]);
            }
          return NoSums{};
        });
        y.swap(trial);
        Ay.swap(A_trial);
        at_y      = at_trial;
        t         = t_next;
        restarted = false;
      }
    lcp.apply(y.cwiseProduct(inv_root), contacts, state);
    return report;
  }
} // namespace tribo::dem
