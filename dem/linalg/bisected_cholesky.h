#pragma once
/// @file A sparse Cholesky factorisation of K = A + diag(shift) in two halves that CHOLMOD
/// factorises concurrently: one level of nested dissection by hand.
///
/// A partition of K's rows into two sides 0, 1 that share no entry and a separator s comes
/// from grain_bisection() (the contacts across an edge cut of the grains' contact graph).
/// Each side's extended block
///     E_i = [K_ii  K_is]
///           [K_si  K_ss]
/// is a principal submatrix of K, so it is positive definite; CHOLMOD factorises it
/// (simplicial LL^T, CAMD ordering with the separator last), E_i = P_i^T L_i L_i^T P_i with
///     L_i = [L_ii   0  ]     L_ii L_ii^T = K_ii,  W_i = L_ii^-1 K_is,
///           [W_i^T L_si]     L_si L_si^T = K_ss - W_i^T W_i.
/// The Schur complement of K on the separator is then
///     S = K_ss - K_s0 K_00^-1 K_0s - K_s1 K_11^-1 K_1s = L_s0 L_s0^T + L_s1 L_s1^T - K_ss,
/// a dense m x m matrix (m about 110 contacts for a cell of 4000 or 16 000 grains: the
/// separator cuts the thin layer across), factorised by Eigen's LLT. A solve K x = v:
///     t_i = K_si K_ii^-1 v_i = W_i^T L_ii^-1 v_i = -L_si c_i,
///         with [a_i; c_i] = L_i^-1 P_i [v_i; 0] (one forward solve per side),
///     x_s = S^-1 (v_s - t_0 - t_1),
///     x_i = K_ii^-1 (v_i - K_is x_s) = L_ii^-T (a_i - W_i x_s)
///         (the backward solve of L_i^T y = [a_i; L_si^T x_s], whose last rows are x_s),
/// two triangular solves per side, as many as the whole factor's solve.
/// The two sides' factorisations and solves run concurrently (on one core the split costs
/// about 10 % more than the whole factor, so the interior point makes it only for two
/// threads). Each side costs about half of K's factorisation (1.34e7 flops for the
/// 9167-contact K of the 4000-grain cell: 6.8e6 and 6.6e6; docs/performance.md).

#include <Eigen/Core>
#include <Eigen/Dense>
#include <Eigen/SparseCore>

#include <cholmod.h>

#include <vector>

namespace tribo::dem
{
  struct Contact;
  struct BodyState;

  /// The rows of a frictionless problem of @p contacts (dem/solvers/frictionless_problem.h, walls as
  /// low-rank columns) split in two: METIS cuts the graph of the bodies that couple contacts
  /// in A' (bodies with a free dof and at most LowRankBodies::contact_limit contacts; an edge
  /// per contact, a body weighted by its contacts) into two halves of about as many
  /// contacts; a contact between two bodies of one half is in that half (0 or 1), one
  /// across the cut is in the separator (2), one with a single such body goes with it.
  /// Contacts of the two halves share no body, so K has no entry between them. As many
  /// rows as METIS's node separator of K itself (105-115 against about 110 at 3800 and
  /// 16 000 grains) from a graph of a tenth the edges: 4-7 ms less per step at 3800 grains
  /// (docs/performance.md). Empty with a contact on a boundary body (its compliance couples
  /// every half-disc contact).
  std::vector<int> grain_bisection(const std::vector<Contact> &contacts, const BodyState &state);

  /// The grains per part of grain_dissection(), at least.
  constexpr int grains_per_part = 256;

  /// A nested dissection of the same problem's rows along edge cuts of the grains' graph
  /// of grain_bisection(): METIS bisects it recursively into 2^L parts of at least
  /// grains_per_part grains, and a row's level is 0 for a contact inside a part (or with
  /// one body outside the graph) and l for one across a cut made l levels above the parts
  /// (l = 1 .. L, L the first cut). Contacts of different parts share no body, so K
  /// eliminated level by level, each level in CAMD's order (cholmod_camd with the levels
  /// as constraint sets), is dissected as the grains are: 18 % fewer flops than AMD's
  /// order of the whole K on the paper's sample, at a cost of 2-3 ms per step
  /// (docs/performance.md). Empty below 2 grains_per_part grains and where
  /// grain_bisection() is.
  std::vector<int> grain_dissection(const std::vector<Contact> &contacts, const BodyState &state);

  /// The upper triangle of P @p A P^T (@p A symmetric, its lower triangle read), row k of
  /// it row @p order[k] of @p A, each column's rows sorted: the matrix a fill-reducing
  /// @p order asks CHOLMOD to factorise, handed over already permuted so that it is
  /// factorised as given (natural ordering, stype > 0). With an ordering of its own CHOLMOD
  /// forms that matrix by a transpose at every factorisation (6 % of the interior point's
  /// step, docs/performance.md).
  Eigen::SparseMatrix<double> permuted_upper(const Eigen::SparseMatrix<double> &A, const int *order);

  class BisectedCholesky
  {
  public:
    /// Analyse both sides of @p A (symmetric, both triangles stored) as @p partition splits
    /// its rows: 0, 1 or 2 (separator) per row, no entry of A between sides 0 and 1 (the
    /// caller's guarantee, e.g. grain_bisection()). split() is false for an empty
    /// partition, when A has fewer than min_rows rows or when the separator is not small
    /// (more than max_separator rows or max_separator_fraction of them): then the object
    /// holds nothing and must not be used.
    BisectedCholesky(const Eigen::SparseMatrix<double> &A, const std::vector<int> &partition);
    ~BisectedCholesky();
    BisectedCholesky(const BisectedCholesky &)            = delete;
    BisectedCholesky &operator=(const BisectedCholesky &) = delete;

    bool split() const { return usable; }
    /// Factorise K = A + diag(@p shift); false if K is numerically not positive definite.
    bool factorise(const Eigen::VectorXd &shift);
    /// K^-1 @p v with the last factorisation.
    Eigen::VectorXd solve(const Eigen::VectorXd &v) const;

    /// Rows below which K is factorised whole (the split's overhead is not repaid).
    static constexpr Eigen::Index min_rows = 4000;
    /// The largest separator, in rows and as a fraction of K's rows.
    static constexpr Eigen::Index max_separator          = 600;
    static constexpr double       max_separator_fraction = 0.05;

  private:
    /// One side with the separator: rows[j] is the row of K of local row j (the side's rows
    /// ascending, then the separator's in its order).
    struct Side
    {
      std::vector<int>            rows;
      Eigen::Index                own = 0;      ///< the side's own rows (local 0 .. own - 1)
      Eigen::SparseMatrix<double> E;            ///< the upper triangle of P_i E_i P_i^T
      std::vector<double *>       diagonal;     ///< its diagonal entries, in P_i's order
      Eigen::VectorXd             unit;         ///< A's diagonal there
      mutable cholmod_common      common; ///< per side: the two run concurrently
      cholmod_factor             *L = nullptr;
      std::vector<int>            permutation;  ///< local row at permuted position q
      std::vector<int>            separator_at; ///< separator index at permuted position own + q
      Eigen::MatrixXd             Ls;           ///< L_si, permuted separator order
      Eigen::MatrixXd             LsLsT;        ///< L_si L_si^T (its lower triangle)
      mutable Eigen::VectorXd     work;
      mutable cholmod_dense      *X = nullptr, *Y = nullptr, *E_work = nullptr; ///< cholmod_solve2's
    };

    /// Run @p f(side) for both sides concurrently.
    template <typename F>
    void for_both_sides(const F &f) const;
    /// Side @p s's work vector (permuted: P_i [v_i; v_s]) replaced by L_i^-1 or L_i^-T of
    /// it (@p system CHOLMOD_L or CHOLMOD_Lt; CHOLMOD's solve with reused workspace).
    void triangular(const Side &s, int system) const;

    bool                        usable = false;
    Side                        sides[2];
    std::vector<int>            separator; ///< rows of K, ascending
    Eigen::MatrixXd             K_ss;      ///< A on the separator (dense)
    Eigen::LLT<Eigen::MatrixXd> schur;
  };
} // namespace tribo::dem
