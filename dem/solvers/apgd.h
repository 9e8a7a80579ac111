#pragma once
/// @file APGD, the accelerated projected gradient method (Nesterov's momentum with the
/// projection of FISTA, Beck and Teboulle 2009, and the adaptive restart of O'Donoghue and
/// Candès 2015), on the frictionless contact problem (dem/solvers/frictionless_problem.h):
///     min f(x) = x.A x / 2 + b.x  over x >= 0.
///
/// It works in the diagonally scaled variables of MPRGP (dem/solvers/mprgp.h): y = D^(1/2) x,
/// A' = D^(-1/2) A D^(-1/2) (unit diagonal, the walls as the low-rank columns U', so
/// A' + U'U'^T), b' = D^(-1/2) b, gradient g = A'y + b'. From the warm start y_0 = z_0,
/// t_0 = 1, each iteration is one product with the operator:
///     y_{k+1} = max(0, z_k - g(z_k) / L),
///     t_{k+1} = (1 + sqrt(1 + 4 t_k^2)) / 2,
///     z_{k+1} = y_{k+1} + (t_k - 1) / t_{k+1} (y_{k+1} - y_k),
/// with A'z_{k+1} formed from A'y_{k+1} and A'y_k (no second product). L bounds the largest
/// eigenvalue of A' + U'U'^T: 1.1 times ten power iterations, never above the absolute
/// column-sum bound. Restart: when f(y_{k+1}) > f(y_k), y_{k+1} is dropped and the momentum
/// reset (z = y_k, t = 1), so f never increases; a plain projected-gradient step that still
/// increases f means L was too small, and L doubles.
///
/// Unlike MPRGP it never stops at a bound: every iteration projects, so contacts open and
/// close in bulk, and its iterations follow the square root of the operator's condition
/// number (MPRGP's expansion steps degenerate into fixed-step gradient steps in steady
/// shear, docs/performance.md). The products and sums run over fixed chunks of the
/// contacts (dem/linalg/scaled_operator.h): the same bits on any number of threads.
///
/// It stops when the natural map max_i |min(x_i, w_i / A_ii)| = max_i |min(y_i, g_i)| /
/// sqrt(D_i) (the law residual's measure, dem/laws/law_residual.h, at the iterate y_k, known
/// every iteration) is at most SolverParameters::residual_target times the iterate's mean
/// loaded impulse, or after SolverParameters::max_iterations products with the operator
/// (the power iterations counted); it then keeps its last iterate, x >= 0, and reports not
/// converged.

#include "dem/solvers/global_solver.h"

namespace tribo::dem
{
  class ApgdSolver : public GlobalSolver
  {
  public:
    using GlobalSolver::GlobalSolver;

  protected:
    /// The report's iterations are the products with the Delassus operator.
    SolveReport solve_problem(std::vector<Contact> &contacts, BodyState &state, const ContactLaw &) override;
  };
} // namespace tribo::dem
