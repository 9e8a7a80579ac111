#pragma once
/// @file The active-set (projected Newton) method for the frictionless contact problem,
/// on the sparse Delassus operator (dem/linalg/delassus.h).
///
/// With x = r~ = r_n + gamma h the shifted normal impulses (N s/m) and
///     w = A x + b,  A = W_nn + C,  b = u_free,n + shift - W_nn (gamma h)
/// the law's normal velocities (m/s; C the ELAS compliances, 0 for IQS; shift the law's
/// gap term, dem/laws/contact_law.h), both laws are the linear complementarity problem
///     0 <= x  _|_  w >= 0,
/// i.e. the minimum of f(x) = x.A x / 2 + b.x over x >= 0 (A symmetric positive
/// semidefinite; w is f's gradient). Bertsekas' projected Newton method (1982):
/// - binding contacts B: x_i <= eps and w_i > 0 (eps: the current natural map); free F:
///   the others;
/// - direction d_F = -(A_FF + delta D_FF)^-1 w_F, d_B = -w_B / D_B (D the diagonal of A,
///   delta = SolverParameters::regularization against the singular A_FF of redundant,
///   hyperstatic contacts: it changes the direction, not the solution);
/// - Armijo search on f along x(alpha) = max(0, x + alpha d) (the full step is also taken
///   when it halves the natural map: near the solution f's round-off hides the decrease);
/// - stop when max_i |min(x_i, w_i / D_i)| <= tau x_mean (tau =
///   SolverParameters::residual_target, x_mean the iterate's mean loaded impulse), or
///   <= 1e-8 of the warm start's once an iteration no longer halves it (round-off).
/// Cost per step: one assembly, one CHOLMOD symbolic analysis on the pattern of all
/// detected contacts (the binding ones are decoupled in the values, so the pattern holds
/// within the step), one numeric factorisation per iteration, sparse products in the
/// line search. docs/laws.md gives the derivation and the measured behaviour.

#include "dem/solvers/global_solver.h"

namespace tribo::dem
{
  class ActiveSetSolver : public GlobalSolver
  {
  public:
    using GlobalSolver::GlobalSolver;
    /// Its own entry, Regularization (SolverParameters::regularization), declared in the
    /// current subsection and read into @p prm.
    static void declare(dealii::ParameterHandler &prm);
    static void parse(const ParameterFile &file, SolverParameters &prm);

  protected:
    /// The report counts factorizations; if it is not converged within
    /// SolverParameters::max_factorizations, the contacts and the state are left as they
    /// came (GlobalSolver then solves the step with NLGS).
    SolveReport solve_problem(std::vector<Contact> &contacts, BodyState &state, const ContactLaw &) override;
    bool        falls_back_to_nlgs() const override { return true; }
  };
} // namespace tribo::dem
