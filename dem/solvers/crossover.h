#pragma once
/// @file The closed-set pieces of the frictionless contact problem's direct methods, in the
/// scaled variables of dem/solvers/frictionless_problem.h (y = D^(1/2) x, operator A' + U'U'^T,
/// g = A'y + U'U'^T y + b'):
/// - ShiftedFactorisation: CHOLMOD's LL^T of K = A' + diag(barrier), with the walls'
///   low-rank part U'U'^T through Sherman-Morrison-Woodbury (the interior point's Newton
///   matrix, dem/solvers/interior_point.h);
/// - least_norm_crossover(): from an approximate solution y and its closed set C, the
///   impulses that close C exactly (the interior point's crossover; from APGD's or APGS's
///   iterates it fails, docs/performance.md).

#include "dem/linalg/bisected_cholesky.h"
#include "dem/solvers/frictionless_problem.h"

#include <Eigen/CholmodSupport>

#include <vector>

namespace tribo::dem
{
  /// K = A' + diag(barrier) + U'U'^T of a scaled problem, factorised by CHOLMOD (simplicial
  /// LL^T: twice as fast as its supernodal one with Debian's reference BLAS on the
  /// 3800-grain benchmark, docs/performance.md); given a @p partition of its rows (from 4000
  /// contacts, with a small separator), in two halves on both cores
  /// (dem/linalg/bisected_cholesky.h). The symbolic analysis is made once, by the constructor;
  /// each factorise() is one numeric factorisation. Whole, K is kept as the upper triangle
  /// of P K P^T (permuted_upper()), P the fill-reducing ordering, so that CHOLMOD
  /// factorises it as given: with its own ordering it would transpose K at every
  /// factorisation. A wall clump touched by m contacts would make an m x m dense block: it
  /// stays out as U'U'^T, K_s = K - U'U'^T is factorised and K solved by Woodbury,
  /// K^-1 v = K_s^-1 v - Z (I + U'^T Z)^-1 U'^T K_s^-1 v with Z = K_s^-1 U', optionally
  /// with one step of iterative refinement against K (the update loses digits that the
  /// plain factorisation keeps).
  class ShiftedFactorisation
  {
  public:
    /// @p partition: the rows' halves for two threads (grain_bisection()); empty: K whole.
    /// @p levels: with K whole, its rows' dissection levels (grain_dissection()), ordered
    /// level by level by CAMD; empty: CHOLMOD's own ordering (AMD).
    explicit ShiftedFactorisation(const FrictionlessProblem::Scaled &p,
                                  const std::vector<int> &partition = {},
                                  const std::vector<int> &levels    = {});
    /// Factorise K with this @p barrier (dimensionless, >= 0, one per contact); false if
    /// CHOLMOD fails (K numerically not positive definite).
    bool factorise(const Eigen::VectorXd &barrier);
    /// K^-1 @p v with the last factorisation; with walls, @p refine adds the step of
    /// iterative refinement.
    Eigen::VectorXd solve(const Eigen::VectorXd &v, bool refine = true) const;
    /// Numeric factorisations so far.
    unsigned int factorizations = 0;

  private:
    const FrictionlessProblem::Scaled &p;
    /// K, or with one thread the upper triangle of P K P^T
    Eigen::SparseMatrix<double>        K;
    /// P: row k of P K P^T is row order[k] of K (CHOLMOD's Perm)
    Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> ordering;
    std::vector<double *>              diagonal; ///< K's diagonal entries, in K's order
    Eigen::VectorXd                    unit;     ///< A''s diagonal (1 - |U'_i|^2 with low-rank walls)
    Eigen::VectorXd                    barrier;
    Eigen::CholmodDecomposition<Eigen::SparseMatrix<double>, Eigen::Upper> cholesky;
    BisectedCholesky                   halves;
    /// K_s^-1 @p v (K_s = A' + diag(barrier)), whole or in halves.
    Eigen::VectorXd                    solve_sparse(const Eigen::VectorXd &v) const;
    Eigen::MatrixXd                    solve_sparse(const Eigen::MatrixXd &V) const;
    Eigen::MatrixXd                    Z;
    Eigen::LDLT<Eigen::MatrixXd>       capacitance;
    Eigen::VectorXd                    woodbury(const Eigen::VectorXd &v) const;
  };

  /// What least_norm_crossover() tries to reach, and against what it accepts.
  struct CrossoverTarget
  {
    /// The natural map must be at most this times the smaller of the candidate's mean
    /// loaded impulse and @ref iterate_mean (SolverParameters::residual_target).
    double residual_target;
    /// The approximate solution's mean loaded impulse (scaled back to N s/m).
    double iterate_mean;
    /// The warm start's mean loaded impulse (N s/m): a candidate whose mean exceeds
    /// growth_limit times it is refused.
    double warm_mean;
  };

  /// The least-norm crossover. With C the contacts flagged in @p closed (on entry, the
  /// caller's closed set: y_i > g_i), z = y + d with
  ///     (A' + U'U'^T)_CC d = -g_C,   d in the range of that block,
  /// z = 0 off C: the impulses that close C exactly with nothing added along the redundant
  /// (hyperstatic) directions. d comes from conjugate gradients started at zero (which stay
  /// in the range), preconditioned by @p K factorised as A'_CC + 1e-8 I (a barrier of 1e20
  /// off C, one factorisation), to 0.3 of the target. Contacts of C with z_i < 0 open and d
  /// is solved again, at most twice. Accepted when z meets @p target and its mean loaded
  /// impulse is within growth_limit of the warm start's (an iterate's component along the
  /// redundant directions must not be frozen and inflated step after step,
  /// docs/performance.md): then @p y, @p g become z, A'z + U'U'^T z + b' and the function
  /// returns z's natural map (scaled back to N s/m); otherwise it returns a negative number
  /// and leaves @p y, @p g alone. @p closed ends as the set tried.
  double least_norm_crossover(const FrictionlessProblem::Scaled &p, ShiftedFactorisation &K,
                              std::vector<char> &closed, const CrossoverTarget &target,
                              Eigen::VectorXd &y, Eigen::VectorXd &g);

  /// The crossover's constants (docs/performance.md, "Design choices and ideas not kept": 0ac2662).
  namespace crossover
  {
    /// The shift of the preconditioner's closed block.
    constexpr double shift = 1e-8;
    /// Conjugate-gradient iterations per pass, at most (1-12 when it succeeds).
    constexpr unsigned int iterations = 15;
    /// The refused growth of the mean impulse over the warm start's.
    constexpr double growth_limit = 1.5;
  } // namespace crossover
} // namespace tribo::dem
