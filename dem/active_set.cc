#include "dem/active_set.h"

#include "core/errors.h"
#include "dem/delassus.h"

#include <Eigen/CholmodSupport>

#include <algorithm>
#include <cmath>

namespace tribo::dem
{
  ActiveSetSolver::ActiveSetSolver(const SolverParameters &p)
    : prm(p)
  {}

  SolveReport ActiveSetSolver::solve(std::vector<Contact> &contacts, BodyState &state,
                                     const ContactLaw &law)
  {
    SolveReport report;
    const Eigen::Index n = static_cast<Eigen::Index>(contacts.size());
    if (n == 0)
      return report;
    if (law.friction > 0)
      throw RunError("the active-set method solves frictionless problems only (Coulomb friction "
                     "mu = " + std::to_string(law.friction) + ")");

    // The LCP 0 <= x _|_ w = A x + b >= 0 (file comment).
    Eigen::SparseMatrix<double> A = assemble_delassus(contacts, state, DelassusPart::normal);
    Eigen::VectorXd             gh(n), b(n), x(n), diag(n);
    for (Eigen::Index i = 0; i < n; ++i)
      {
        const Contact &c = contacts[i];
        gh[i]            = c.cohesion_impulse;
        b[i]             = c.u_free.x() + c.shift;
        x[i]             = std::max(0.0, c.r.x() + c.cohesion_impulse);
      }
    b -= A * gh;
    for (Eigen::Index i = 0; i < n; ++i)
      {
        A.coeffRef(i, i) += contacts[i].compliance;
        diag[i] = A.coeff(i, i);
      }

    // Scale of the impulses for the tests: the mean warm-started impulse of the loaded
    // contacts (or of |b_i| / A_ii without one).
    double       loaded_sum = 0;
    unsigned int loaded     = 0;
    for (Eigen::Index i = 0; i < n; ++i)
      if (x[i] > 0)
        {
          loaded_sum += x[i];
          ++loaded;
        }
    const double scale =
      loaded ? loaded_sum / loaded : std::max(1e-300, b.cwiseAbs().cwiseQuotient(diag).mean());
    const double tolerance = prm.feasibility_tolerance * scale;

    std::vector<char> active(n);
    Eigen::VectorXd   w = A * x + b;
    for (Eigen::Index i = 0; i < n; ++i)
      active[i] = x[i] - w[i] / diag[i] > 0;

    // The matrix factorised: A_SS + delta D_SS on the active rows and columns (D the
    // diagonal of A), the diagonal alone on the others (x_I = 0), on the pattern of A.
    Eigen::SparseMatrix<double> M = A;
    Eigen::CholmodDecomposition<Eigen::SparseMatrix<double>, Eigen::Lower> cholesky;
    cholesky.analyzePattern(M);
    const double    delta  = prm.regularization;
    Eigen::VectorXd centre = x, rhs(n), w_reg(n);
    unsigned int    best = n + 1, since_best = 0, solves = 0;
    bool            factorised = false;
    std::vector<Eigen::Index> infeasible;
    for (;;)
      {
        if (!factorised)
          {
            if (report.factorizations >= prm.max_factorizations)
              {
                // Leave the warm start in place for the caller's NLGS.
                report.converged  = false;

                return report;
              }
            for (Eigen::Index j = 0; j < n; ++j)
              for (Eigen::SparseMatrix<double>::InnerIterator a(A, j), m(M, j); a; ++a, ++m)
                {
                  const Eigen::Index i = a.row();
                  if (i == j)
                    m.valueRef() = active[j] ? a.value() * (1 + delta) : a.value();
                  else
                    m.valueRef() = active[i] && active[j] ? a.value() : 0.0;
                }
            cholesky.factorize(M);
            ++report.factorizations;
            if (cholesky.info() != Eigen::Success)
              throw RunError("the active-set method could not factorise the Delassus operator of "
                             "the loaded contacts (Solver/Regularization too small?)");
            factorised = true;
          }
        // The proximal subproblem: A_SS x_S + b_S + delta D_SS (x_S - centre_S) = 0.
        for (Eigen::Index i = 0; i < n; ++i)
          rhs[i] = active[i] ? -b[i] + delta * diag[i] * centre[i] : 0.0;
        x = cholesky.solve(rhs);
        ++solves;
        for (Eigen::Index i = 0; i < n; ++i)
          if (!active[i])
            x[i] = 0;
        w     = A * x + b;
        w_reg = w + delta * diag.cwiseProduct(x - centre);

        infeasible.clear();
        for (Eigen::Index i = 0; i < n; ++i)
          if (active[i] ? x[i] < -tolerance : w_reg[i] < -tolerance * diag[i])
            infeasible.push_back(i);
        if (!infeasible.empty())
          {
            // Block principal pivoting on the proximal subproblem.
            if (infeasible.size() < best)
              {
                best       = infeasible.size();
                since_best = 0;
              }
            else
              ++since_best;
            if (since_best < 3)
              for (const Eigen::Index i : infeasible)
                active[i] = !active[i];
            else
              active[infeasible.back()] = !active[infeasible.back()]; // Murty's rule
            factorised = false;
            continue;
          }
        // The subproblem is solved; is the problem itself? Natural map min(x, w / D).
        double worst = 0;
        for (Eigen::Index i = 0; i < n; ++i)
          worst = std::max(worst, std::abs(std::min(x[i], w[i] / diag[i])));
        if (worst <= tolerance)
          break;
        if (solves >= prm.max_proximal_steps)
          {
            report.converged  = false;

            return report;
          }
        centre = x; // the next proximal step, on the same factorisation
        best   = n + 1;
      }

    // Impulses (x >= 0: round-off projected) and the body velocities they produce.
    for (Eigen::Index i = 0; i < n; ++i)
      {
        Contact              &c = contacts[i];
        const Eigen::Vector2d r_new(std::max(0.0, x[i]) - gh[i], 0.0);
        const Eigen::Vector2d dr = r_new - c.r;
        if (dr.x() != 0 || dr.y() != 0)
          state.apply_impulse(c, dr);
        c.r = r_new;
      }

    report.converged  = true;
    return report;
  }
} // namespace tribo::dem
