#include "dem/solvers/global_solver.h"

#include <algorithm>

namespace tribo::dem
{
  namespace
  {
    /// NLGS controls that make exactly @p p.predictor_sweeps sweeps (at least one).
    SolverParameters predictor_controls(const SolverParameters &p)
    {
      SolverParameters q = p;
      q.max_iterations   = std::max(1U, p.predictor_sweeps);
      q.check_interval   = q.max_iterations;
      q.tolerance        = 1e-300; // never stops early
      return q;
    }
  } // namespace

  GlobalSolver::GlobalSolver(const SolverParameters &p)
    : ContactSolver(p)
    , nlgs(p)
    , predictor(predictor_controls(p))
  {}

  SolveReport GlobalSolver::solve(std::vector<Contact> &contacts, BodyState &state, const ContactLaw &law,
                                  double theta_h)
  {
    if (contacts.empty())
      return {};
    if (law.friction > 0 && !solves_friction())
      return nlgs.solve(contacts, state, law, theta_h);
    unsigned int sweeps = 0;
    if (prm.predictor_sweeps > 0)
      sweeps = predictor.solve(contacts, state, law, theta_h).iterations;
    step_theta_h       = theta_h;
    SolveReport report = solve_problem(contacts, state, law);
    if (!report.converged && falls_back_to_nlgs())
      {
        // Not found within its budget: NLGS from the impulses the method left.
        const unsigned int factorizations = report.factorizations;
        report                = nlgs.solve(contacts, state, law, theta_h);
        report.factorizations = factorizations;
        report.fell_back      = true;
      }
    report.iterations += sweeps;
    return report;
  }
} // namespace tribo::dem
