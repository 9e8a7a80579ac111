#pragma once
/// @file The matrix-free pieces shared by the first-order global methods (dem/solvers/mprgp.h,
/// dem/solvers/apgd.h): the scaled Delassus operator A' + U'U'^T of a FrictionlessProblem::Scaled
/// applied one row at a time, and passes over fixed chunks of the contacts whose partial
/// results are merged in chunk order, so that every product and sum gives the same bits
/// on any number of threads (SolverParameters::threads).

#include "dem/solvers/frictionless_problem.h"

#include <deal.II/base/parallel.h>

#include <algorithm>
#include <vector>

namespace tribo::dem
{
  /// Entries per chunk of the fused passes.
  constexpr Eigen::Index chunk_size = 256;

  /// Number of fixed chunks of [0, n).
  inline Eigen::Index chunk_count(Eigen::Index n) { return (n + chunk_size - 1) / chunk_size; }

  /// @p partial[c] = @p body(begin, end) -> Partial over each fixed chunk c of [0, n),
  /// concurrently when @p threads > 1 (@p partial resized to chunk_count(n)).
  template <typename Partial, typename Body>
  void chunk_partials(Eigen::Index n, unsigned int threads, const Body &body, std::vector<Partial> &partial)
  {
    const Eigen::Index count = chunk_count(n);
    partial.resize(count);
    auto work = [&](Eigen::Index first, Eigen::Index last) {
      for (Eigen::Index c = first; c < last; ++c)
        partial[c] = body(c * chunk_size, std::min(n, (c + 1) * chunk_size));
    };
    if (threads > 1 && count > 1)
      dealii::parallel::apply_to_subranges(Eigen::Index(0), count, work, 1);
    else
      work(0, count);
  }

  /// The partials merged (Partial::merge) in chunk order: the same bits on any number of threads.
  template <typename Partial>
  Partial merged_in_order(const std::vector<Partial> &partial)
  {
    Partial total;
    for (const Partial &p : partial)
      total.merge(p);
    return total;
  }

  /// Run @p body(begin, end) -> Partial over fixed chunks of [0, n), concurrently when
  /// @p threads > 1, and merge the partials (Partial::merge) in chunk order.
  template <typename Partial, typename Body>
  Partial over_chunks(Eigen::Index n, unsigned int threads, const Body &body)
  {
    std::vector<Partial> partial;
    chunk_partials(n, threads, body, partial);
    return merged_in_order(partial);
  }

  /// A pass with nothing to reduce.
  struct NoSums
  {
    void merge(const NoSums &) {}
  };

  /// The operator A' + U'U'^T of a scaled frictionless problem (dimensionless: A' has a unit
  /// diagonal), row by row. A' is symmetric, so its column j, stored, is its row j; U' (n x k,
  /// the walls' low-rank columns, dem/linalg/delassus.h) is kept by rows so that its part of a
  /// product costs O(wall contacts), not O(n k).
  class ScaledOperator
  {
  public:
    explicit ScaledOperator(const FrictionlessProblem::Scaled &p);

    /// The rows with low-rank entries (the walls' contacts), increasing.
    const std::vector<Eigen::Index> &low_rank_row_list() const { return low_rank_rows; }
    /// Whether row @p j has low-rank entries.
    bool has_low_rank(Eigen::Index j) const { return low_rank_start[j + 1] > low_rank_start[j]; }
    /// Prepare the row products with @p v (computes U'^T v); call before row_times(v, .).
    void set_vector(const Eigen::VectorXd &v);
    /// After v_j changed by @p change in place: keep U'^T v current (Gauss-Seidel sweeps,
    /// dem/solvers/apgs.h), O(the row's low-rank entries).
    void add_to_low_rank(Eigen::Index j, double change)
    {
      for (Eigen::Index q = low_rank_start[j]; q < low_rank_start[j + 1]; ++q)
        Ut_v[low_rank_column[q]] += low_rank_value[q] * change;
    }
    /// ((A' + U'U'^T) v)_j for the v given to set_vector.
    double row_times(const Eigen::VectorXd &v, Eigen::Index j) const
    {
      double sum = 0;
      for (int k = start[j]; k < start[j + 1]; ++k)
        sum += value[k] * v[row[k]];
      double low_rank = 0;
      for (Eigen::Index q = low_rank_start[j]; q < low_rank_start[j + 1]; ++q)
        low_rank += low_rank_value[q] * Ut_v[low_rank_column[q]];
      return sum + low_rank;
    }
    /// An upper bound of ||A' + U'U'^T||_2: the largest absolute column sum of A' plus
    /// ||U'||_F^2.
    double norm_bound() const;

  private:
    const Eigen::SparseMatrix<double> &A;
    const int                         *start, *row;
    const double                      *value;
    std::vector<Eigen::Index>          low_rank_start, low_rank_rows, low_rank_column;
    std::vector<double>                low_rank_value;
    double                             low_rank_norm2 = 0; ///< ||U'||_F^2
    Eigen::VectorXd                    Ut_v;
  };
} // namespace tribo::dem
