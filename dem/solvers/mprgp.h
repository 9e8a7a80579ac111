#pragma once
/// @file MPRGP, the modified proportioning with reduced gradient projections of Dostál
/// and Schöberl (2005), on the frictionless contact problem (dem/solvers/frictionless_problem.h):
/// a conjugate-gradient method for the bound-constrained quadratic problem
///     min f(x) = x.A x / 2 + b.x  over x >= 0,
/// that needs no ordering of the contacts, only products with the sparse Delassus
/// operator A, which run on several cores without bands (SolverParameters::threads).
///
/// Preconditioning by the diagonal D of A, as a change of variables y = D^(1/2) x:
/// the problem in y has A' = D^(-1/2) A D^(-1/2) (unit diagonal), b' = D^(-1/2) b and the
/// same bounds y >= 0; the gradient is g = A' y + b' = D^(-1/2) w. The walls (bodies with
/// more than LowRankBodies::contact_limit contacts, dem/linalg/delassus.h) are kept out of the
/// sparse matrix as low-rank columns, A' = A'_sparse + U'U'^T: a product then costs
/// O(nnz(A'_sparse) + n k) (k: the walls' free dofs) instead of a dense block per wall.
/// With F = {i : y_i > 0} (free) and the others active, the free gradient phi_i = g_i on
/// F, the chopped gradient beta_i = min(g_i, 0) off F, and the reduced free gradient
/// phi~_i = min(y_i / alpha, g_i) on F, each iteration is one of
/// - a conjugate-gradient step along p (p = phi after any other step, then
///   p <- phi - (phi.A'p / p.A'p) p), when ||beta||^2 <= Gamma^2 phi~.phi (proportional
///   iterate) and the CG step length g.p / p.A'p keeps y >= 0;
/// - an expansion step when it does not: to the bound along p, then the projected
///   gradient step y <- max(0, y - alpha phi(y)) with fixed length alpha = 1.9 / ||A'||
///   (||A'|| bounded by the largest absolute row sum of its sparse part plus ||U'||_F^2);
/// - a proportioning step along beta (exact line search) when the iterate is not
///   proportional: contacts pushed closed by the others leave the active set.
/// Gamma = 1. f decreases at every step (Dostál 2009, "Optimal quadratic programming
/// algorithms", ch. 9, which proves R-linear convergence for A positive definite).
///
/// It stops when the natural map max_i |min(x_i, w_i / A_ii)| = max_i |min(y_i, g_i)| /
/// sqrt(D_i) is at most SolverParameters::residual_target times the iterate's mean loaded
/// impulse (the law residual's measure, dem/laws/law_residual.h), or after SolverParameters::max_iterations products with A' (each
/// about the cost of one NLGS sweep); it then keeps its last iterate, which satisfies
/// x >= 0, and reports not converged.

#include "dem/solvers/global_solver.h"

namespace tribo::dem
{
  class MprgpSolver : public GlobalSolver
  {
  public:
    using GlobalSolver::GlobalSolver;

  protected:
    /// The report's iterations are the products with the Delassus operator.
    SolveReport solve_problem(std::vector<Contact> &contacts, BodyState &state, const ContactLaw &) override;
  };
} // namespace tribo::dem
