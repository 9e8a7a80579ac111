#pragma once
/// @file A primal-dual interior-point method (Mehrotra's predictor-corrector) for the
/// frictionless contact problem (dem/solvers/frictionless_problem.h), on the sparse Delassus
/// operator factorised by CHOLMOD.
///
/// In the diagonally scaled variables of dem/solvers/mprgp.h (y = D^(1/2) x, A' = D^(-1/2) A
/// D^(-1/2), b' = D^(-1/2) b), the problem 0 <= y _|_ s = A'y + b' >= 0 is followed along
/// its central path y_i s_i = mu > 0, mu -> 0. With the residual r = A'y + b' - s, each
/// iteration solves twice with one factorisation of
///     K = A' + Y^-1 S        (symmetric positive definite for y, s > 0, whatever the
///                             redundancy of the contacts: no regularisation needed)
/// (CHOLMOD's simplicial LL^T: faster than its supernodal one with reference BLAS here).
/// A wall clump touched by m contacts would make an m x m dense block of K; it is kept
/// out as the rank-1..3 term U U^T (dem/linalg/delassus.h, bodies with more than 64 contacts),
/// K_s = K - U U^T is factorised and K solved by Sherman-Morrison-Woodbury with one step
/// of iterative refinement (1.7 times faster per step at 16 000 grains, docs/performance.md);
/// - predictor: K dy = -r - s, ds = A' dy + r; the largest step alpha_a that keeps y, s >= 0
///   gives mu_a = (y + alpha_a dy).(s + alpha_a ds) / n and the centring sigma = (mu_a / mu)^3;
/// - corrector: K dy = -r - s + (sigma mu - dy_a ds_a) / y, ds = A' dy + r;
/// - centrality correctors (Gondzio), at most two, while the natural map is above 1e-3 of the
///   mean impulse: K dc = t / y with t pulling the products (y + a~ dy)_i (s + a~ ds)_i at
///   a longer trial step a~ = min(1, 1.5 alpha + 0.1) back into [0.1, 10] sigma mu; dy + dc
///   is kept while it lengthens the step (15 % fewer factorisations, docs/performance.md);
/// - step: 0.995 of the largest step that keeps y, s > 0, the same for both;
/// - crossover: once the natural map is below 1e-4 of the
///   mean impulse and the closed set C = {y_i > g_i} changed by at most 3 contacts in an
///   iteration, the impulses that close C exactly, z = y + d, (A' + U U^T)_CC d = -g_C with
///   d the least-norm correction (conjugate gradients from zero, preconditioned by the
///   factorised A'_CC + 1e-8 I), contacts whose z_i < 0 opened; accepted when z meets the
///   target and its mean impulse is within 1.5 times the warm start's (the iterate's
///   component along the redundant directions must not be frozen and inflated step after
///   step); otherwise the iteration goes on (at most 3 attempts, one factorisation each).
/// Start: y_0 = max(warm start, nu), s_0 = max(A'y_0 + b', nu), nu a hundredth of the
/// larger of the mean warm-started impulse and the mean |b'| (scaled). The iterate with the
/// smallest natural map is applied, its open contacts (y_i <= g_i) at zero impulse. It stops at the natural-map test of the other global
/// methods (SolverParameters::residual_target, the solution being y projected onto y >= 0)
/// or after SolverParameters::max_factorizations, or when K cannot be factorised even with
/// 1e-10 I added (a numerically singular K near the solution), or when, below 1e-6 of the
/// iterate's mean loaded impulse,
/// two iterations in a row do not halve the natural map (round-off: K's condition grows
/// like 1 / mu), keeping its iterate (reported not converged). Cost per iteration: one numeric factorisation (the symbolic analysis once
/// per step), two solves, two products with A'.

#include "dem/solvers/global_solver.h"

namespace tribo::dem
{
  class InteriorPointSolver : public GlobalSolver
  {
  public:
    using GlobalSolver::GlobalSolver;

  protected:
    /// The report counts factorizations.
    SolveReport solve_problem(std::vector<Contact> &contacts, BodyState &state, const ContactLaw &) override;
  };
} // namespace tribo::dem
