#include "dem/mprgp.h"

#include "core/errors.h"
#include "dem/frictionless_problem.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace tribo::dem
{
  MprgpSolver::MprgpSolver(const SolverParameters &p)
    : prm(p)
  {}

  SolveReport MprgpSolver::solve(std::vector<Contact> &contacts, BodyState &state,
                                 const ContactLaw &law)
  {
    SolveReport report;
    if (contacts.empty())
      return report;
    if (law.friction > 0)
      throw RunError("MPRGP solves frictionless problems only (Coulomb friction mu = " +
                     std::to_string(law.friction) + ")");

    const FrictionlessProblem lcp(contacts, state);
    const Eigen::Index        n = lcp.size();
    // The scaled problem (file comment): A' = S A S, b' = S b, y = x / s, S = D^(-1/2).
    const Eigen::VectorXd inv_root = lcp.diagonal.cwiseSqrt().cwiseInverse(); // S
    Eigen::SparseMatrix<double> A = lcp.A;
    for (Eigen::Index j = 0; j < n; ++j)
      for (Eigen::SparseMatrix<double>::InnerIterator a(A, j); a; ++a)
        a.valueRef() *= inv_root[a.row()] * inv_root[j];
    const Eigen::VectorXd b = lcp.b.cwiseProduct(inv_root);
    double                norm_bound = 0; // ||A'|| <= max absolute row (= column) sum
    for (Eigen::Index j = 0; j < n; ++j)
      {
        double sum = 0;
        for (Eigen::SparseMatrix<double>::InnerIterator a(A, j); a; ++a)
          sum += std::abs(a.value());
        norm_bound = std::max(norm_bound, sum);
      }
    const double alpha     = 1.9 / norm_bound;
    const double tolerance = prm.residual_target * lcp.scale;
    const double gamma2    = 1.0; // Gamma^2

    Eigen::VectorXd y = lcp.x.cwiseQuotient(inv_root), g(n), p(n), Ap(n), phi(n), beta(n);
    auto product = [&](const Eigen::VectorXd &in, Eigen::VectorXd &out) {
      symmetric_product(A, in, out, prm.threads);
      ++report.iterations;
    };
    // phi, beta and the proportionality test's two sides; returns the natural map
    // max |min(y_i, g_i)| / sqrt(D_i) (N s/m).
    double beta2 = 0, proportional = 0;
    auto   split = [&]() {
      double worst = 0;
      beta2 = proportional = 0;
      for (Eigen::Index i = 0; i < n; ++i)
        {
          worst = std::max(worst, std::abs(std::min(y[i], g[i])) * inv_root[i]);
          if (y[i] > 0)
            {
              phi[i]  = g[i];
              beta[i] = 0;
              proportional += std::min(y[i] / alpha, g[i]) * g[i];
            }
          else
            {
              phi[i]  = 0;
              beta[i] = std::min(g[i], 0.0);
              beta2 += beta[i] * beta[i];
            }
        }
      return worst;
    };

    product(y, g);
    g += b;
    double worst = split();
    p            = phi;
    while (worst > tolerance)
      {
        if (report.iterations >= prm.max_iterations)
          {
            report.converged = false;
            break;
          }
        if (beta2 <= gamma2 * proportional)
          {
            product(p, Ap);
            const double pAp = p.dot(Ap);
            if (!(pAp > 0))
              {
                // p = 0 on a proportional iterate: the free part is solved; nothing
                // more to gain along it (round-off), so take the gradient step.
                p = phi;
                if (p.squaredNorm() == 0)
                  break;
                continue;
              }
            const double step = g.dot(p) / pAp;
            double       to_bound = std::numeric_limits<double>::infinity();
            for (Eigen::Index i = 0; i < n; ++i)
              if (p[i] > 0)
                to_bound = std::min(to_bound, y[i] / p[i]);
            if (step <= to_bound)
              {
                // Conjugate-gradient step.
                y -= step * p;
                g -= step * Ap;
                worst              = split();
                const double coeff = phi.dot(Ap) / pAp;
                p                  = phi - coeff * p;
              }
            else
              {
                // Expansion step: to the bound, then a fixed-length projected gradient step.
                y -= to_bound * p;
                g -= to_bound * Ap;
                for (Eigen::Index i = 0; i < n; ++i)
                  {
                    const double free_gradient = y[i] > 0 ? g[i] : 0.0;
                    y[i] = std::max(0.0, y[i] - alpha * free_gradient);
                  }
                product(y, g);
                g += b;
                worst = split();
                p     = phi;
              }
          }
        else
          {
            // Proportioning step along the chopped gradient, exact line search.
            product(beta, Ap);
            const double step = beta2 / beta.dot(Ap);
            y -= step * beta;
            g -= step * Ap;
            worst = split();
            p     = phi;
          }
      }
    // Round-off may leave y_i a little below 0 after a CG step that reached a bound:
    // apply() projects.
    const Eigen::VectorXd x = y.cwiseProduct(inv_root);
    lcp.apply(x, contacts, state);
    return report;
  }
} // namespace tribo::dem
