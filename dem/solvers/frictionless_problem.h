#pragma once
/// @file The frictionless contact problem of a step as a linear complementarity problem,
/// shared by the global solvers (dem/solvers/active_set.h, dem/solvers/mprgp.h).
///
/// With x = r~ = r_n + gamma h the shifted normal impulses (N s/m) and
///     w = A x + b,  A = W_nn + C,  b = u_free,n + shift - W_nn (gamma h)
/// the law's normal velocities (m/s; W_nn the normal part of the sparse Delassus operator,
/// dem/linalg/delassus.h; C the diagonal ELAS compliances 1/(theta k h^2), 0 for IQS; shift the
/// law's gap term, dem/laws/contact_law.h), both IQS and ELAS are
///     0 <= x  _|_  w >= 0,
/// i.e. the minimum over x >= 0 of the contact energy f(x) = x.A x / 2 + b.x, whose
/// gradient is w (A is symmetric positive semidefinite). The natural map
///     phi_i = min(x_i, w_i / A_ii)      (N s/m)
/// is zero exactly at a solution; it is the law residual's phi_n (dem/laws/law_residual.h).

#include "dem/engine/contact.h"
#include "dem/laws/contact_law.h"

#include <Eigen/Core>
#include <Eigen/Dense>
#include <Eigen/SparseCore>

#include <vector>

namespace tribo::dem
{
  struct BodyState;

  struct FrictionlessProblem
  {
    /// The problem of @p contacts against @p state, whose velocities must already hold the
    /// contacts' warm-start impulses c.r; x starts at max(0, r_n + gamma h). With
    /// @p low_rank_bodies, the bodies with many contacts (walls) are kept out of A as the
    /// columns U (dem/linalg/delassus.h): the operator is A + U U^T.
    /// A is assembled on @p threads threads (the same bits on any number).
    FrictionlessProblem(const std::vector<Contact> &contacts, const BodyState &state,
                        bool low_rank_bodies = false, unsigned int threads = 1);

    Eigen::SparseMatrix<double> A;  ///< W_nn + C (- U U^T), both triangles, column-major
    Eigen::MatrixXd             U;  ///< n x k, k = 0 without low_rank_bodies
    Eigen::VectorXd b;              ///< m/s
    Eigen::VectorXd x;              ///< the warm start, N s/m
    Eigen::VectorXd diagonal;       ///< A_ii
    Eigen::VectorXd cohesion;       ///< gamma h of each contact, N s/m
    /// Scale of the impulses for relative tests: the warm start's mean loaded impulse,
    /// or, without one, the mean of |b_i| / A_ii.
    double scale = 0;

    Eigen::Index size() const { return b.size(); }
    /// (A + U U^T) v.
    Eigen::VectorXd product(const Eigen::VectorXd &v) const { return product_with(A, U, v); }
    /// (@p A + @p U @p U^T) @p v, for this problem and its scaled form.
    static Eigen::VectorXd product_with(const Eigen::SparseMatrix<double> &A, const Eigen::MatrixXd &U,
                                        const Eigen::VectorXd &v)
    {
      return U.cols() > 0 ? Eigen::VectorXd(A * v + U * (U.transpose() * v)) : Eigen::VectorXd(A * v);
    }
    /// The mean of the positive entries of @p y (N s/m), or scale without one: the
    /// denominator of the law residual (dem/laws/law_residual.h).
    double mean_loaded(const Eigen::VectorXd &y) const;
    /// max_i |min(y_i, w_i / A_ii)| with w = A y + b given, N s/m.
    double natural_map(const Eigen::VectorXd &y, const Eigen::VectorXd &w) const;
    /// f(y) = y.A y / 2 + b.y with w = A y + b given.
    double energy(const Eigen::VectorXd &y, const Eigen::VectorXd &w) const
    {
      return 0.5 * y.dot(w + b);
    }
    /// The problem in the variables y = D^(1/2) x (D = diag A): A' = D^(-1/2) A D^(-1/2)
    /// (unit diagonal), b' = D^(-1/2) b, the same bounds y >= 0; g = A'y + b' = D^(-1/2) w.
    struct Scaled
    {
      Eigen::VectorXd             inv_root; ///< D^(-1/2), x = inv_root y
      Eigen::SparseMatrix<double> A;
      Eigen::MatrixXd             U; ///< D^(-1/2) U: the operator is A + U U^T
      Eigen::VectorXd             b;
      Eigen::VectorXd             y; ///< the warm start
      /// (A' + U' U'^T) v.
      Eigen::VectorXd product(const Eigen::VectorXd &v) const { return product_with(A, U, v); }
    };
    Scaled scaled() const;

    /// Write the impulses r_n = max(0, y) - gamma h into @p contacts (r_t = 0) and apply
    /// the change to @p state's velocities.
    void apply(const Eigen::VectorXd &y, std::vector<Contact> &contacts, BodyState &state) const;
  };
} // namespace tribo::dem
