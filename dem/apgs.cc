#include "dem/apgs.h"

#include "dem/scaled_operator.h"

#include <algorithm>
#include <cmath>

namespace tribo::dem
{
  SolveReport ApgsSolver::solve_problem(std::vector<Contact> &contacts, BodyState &state)
  {
    SolveReport                 report;
    const FrictionlessProblem   lcp(contacts, state, true);
    const Eigen::Index          n      = lcp.size();
    FrictionlessProblem::Scaled scaled = lcp.scaled();
    const Eigen::VectorXd      &inv_root = scaled.inv_root;
    const Eigen::VectorXd      &b        = scaled.b;
    ScaledOperator              op(scaled);

    // The natural map at y over its mean loaded impulse (one product).
    auto relative_map = [&](const Eigen::VectorXd &y) {
      ++report.iterations;
      op.set_vector(y);
      double worst = 0, loaded_sum = 0, loaded = 0;
      for (Eigen::Index j = 0; j < n; ++j)
        {
          worst = std::max(worst, std::abs(std::min(y[j], op.row_times(y, j) + b[j])) * inv_root[j]);
          if (y[j] > 0)
            {
              loaded_sum += y[j] * inv_root[j];
              ++loaded;
            }
        }
      return worst / (loaded > 0 ? loaded_sum / loaded : lcp.scale);
    };
    // One projected Gauss-Seidel sweep of v in place (unit diagonal: A'_jj + |U'_j|^2 = 1).
    auto sweep = [&](Eigen::VectorXd &v) {
      ++report.iterations;
      op.set_vector(v);
      for (Eigen::Index j = 0; j < n; ++j)
        {
          const double next = std::max(0.0, v[j] - (op.row_times(v, j) + b[j]));
          if (next != v[j])
            {
              op.add_to_low_rank(j, next - v[j]);
              v[j] = next;
            }
        }
    };

    Eigen::VectorXd y = scaled.y.cwiseMax(0.0), y_last(n), z = y, next(n);
    double          t = 1;
    while (relative_map(y) > prm.residual_target)
      {
        if (report.iterations >= prm.max_iterations)
          {
            report.converged = false;
            break;
          }
        for (unsigned int k = 0; k < check_interval; ++k)
          {
            next = z;
            sweep(next);
            double opposed = 0;
            for (Eigen::Index j = 0; j < n; ++j)
              opposed += (z[j] - next[j]) * (next[j] - y[j]);
            if (opposed > 0)
              t = 1;
            const double t_next = 0.5 * (1 + std::sqrt(1 + 4 * t * t));
            const double beta   = (t - 1) / t_next;
            y_last.swap(y);
            y.swap(next);
            z = y + beta * (y - y_last);
            t = t_next;
          }
      }
    lcp.apply(y.cwiseProduct(inv_root), contacts, state);
    return report;
  }
} // namespace tribo::dem
