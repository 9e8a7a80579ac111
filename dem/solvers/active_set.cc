#include "dem/solvers/active_set.h"

#include "core/errors.h"
#include "core/parameter_file.h"
#include "dem/solvers/frictionless_problem.h"

#include <Eigen/CholmodSupport>

#include <algorithm>
#include <cmath>
#include <limits>

namespace tribo::dem
{
  void ActiveSetSolver::declare(dealii::ParameterHandler &prm)
  {
    prm.declare_entry("Regularization", "1e-8", dealii::Patterns::Double(),
                      "Active set: relative regularisation delta in [0, 1e-4] of the Newton matrix "
                      "W_FF + delta diag(W_FF) (redundant contacts make W_FF singular); it changes "
                      "the Newton step, not the solution.");
  }

  void ActiveSetSolver::parse(const ParameterFile &f, SolverParameters &p)
  {
    p.regularization = f.get_checked(p.section.entry("Regularization"),
                                     [](double v) { return v >= 0 && v <= 1e-4; }, "a regularisation in [0, 1e-4]");
  }

  SolveReport ActiveSetSolver::solve_problem(std::vector<Contact> &contacts, BodyState &state, const ContactLaw &)
  {
    SolveReport report;
    const Eigen::Index n = static_cast<Eigen::Index>(contacts.size());

    FrictionlessProblem   lcp(contacts, state);
    const Eigen::SparseMatrix<double> &A = lcp.A;
    const Eigen::VectorXd             &b = lcp.b;
    Eigen::VectorXd       x = lcp.x;
    const double          scale     = lcp.scale;

    // Projected Newton iterations (Bertsekas 1982) on f(x) = x.A x / 2 + b.x, x >= 0,
    // whose minimum is the LCP's solution; w = A x + b is f's gradient.
    Eigen::SparseMatrix<double> M = A;
    Eigen::CholmodDecomposition<Eigen::SparseMatrix<double>, Eigen::Lower> cholesky;
    cholesky.analyzePattern(M);
    const double      delta = prm.regularization;
    Eigen::VectorXd   w     = A * x + b, rhs(n), d(n), trial(n), w_trial(n);
    std::vector<char> free_dof(n);
    double            last_worst = std::numeric_limits<double>::infinity();
    for (;;)
      {
        const double worst = lcp.natural_map(x, w);
        if (worst <= prm.residual_target * lcp.mean_loaded(x))
          break;
        // Round-off floor: below 1e-8 of the mean impulse, an iteration that does not
        // halve the natural map ends the solve (the energy no longer tells the iterates
        // apart).
        if (worst <= 1e-8 * scale && worst >= 0.5 * last_worst)
          break;
        last_worst = worst;
        if (report.factorizations >= prm.max_factorizations)
          {
            report.converged = false;
            return report; // the warm start is untouched: the caller solves with NLGS
          }
        // Binding contacts: at (or within eps of) zero impulse with an opening gradient;
        // the others are free and take the Newton step of the reduced problem.
        const double eps = std::min(worst, scale);
        for (Eigen::Index i = 0; i < n; ++i)
          free_dof[i] = !(x[i] <= eps && w[i] > 0);
        for (Eigen::Index j = 0; j < n; ++j)
          for (Eigen::SparseMatrix<double>::InnerIterator a(A, j), m(M, j); a; ++a, ++m)
            {
              const Eigen::Index i = a.row();
              if (i == j)
                m.valueRef() = free_dof[j] ? a.value() * (1 + delta) : a.value();
              else
                m.valueRef() = free_dof[i] && free_dof[j] ? a.value() : 0.0;
            }
        cholesky.factorize(M);
        ++report.factorizations;
        if (cholesky.info() != Eigen::Success)
          throw RunError("the active-set method could not factorise the Delassus operator of "
                         "the loaded contacts (" + prm.section.entry("Regularization") + " too small?)");
        for (Eigen::Index i = 0; i < n; ++i)
          rhs[i] = -w[i];
        d = cholesky.solve(rhs); // free: -(A_FF + delta D)^-1 w_F; binding: -w_B / D_B
        // Armijo search along the projection arc x(alpha) = max(0, x + alpha d); the full
        // step is also taken when it halves the natural map (near the solution the energy's
        // round-off hides the decrease).
        const double f0    = lcp.energy(x, w);
        double       alpha = 1;
        for (int k = 0; k < 30; ++k, alpha *= 0.5)
          {
            trial   = (x + alpha * d).cwiseMax(0.0);
            w_trial = A * trial + b;
            if (lcp.energy(trial, w_trial) <= f0 + 1e-4 * w.dot(trial - x) ||
                (k == 0 && lcp.natural_map(trial, w_trial) <= 0.5 * worst))
              break;
          }
        x = trial;
        w = w_trial;
      }
    lcp.apply(x, contacts, state);
    report.converged = true;
    return report;
  }
} // namespace tribo::dem
