// The two-way split Cholesky factorisation (dem/linalg/bisected_cholesky.h) against the whole
// factor (the interior point on two threads: tests/unit/test_contact_solvers.cc), and the
// whole factor of the interior point's Newton matrix (dem/solvers/crossover.h).
#include "dem/linalg/bisected_cholesky.h"
#include "dem/solvers/crossover.h"

#include <Eigen/SparseCholesky>

#include <gtest/gtest.h>

#include <cmath>

using namespace tribo::dem;

namespace
{
  /// The graph Laplacian of a strip @p length x @p width, periodic along its length (the
  /// shear cell's shape), plus 1e-3 on the diagonal: symmetric positive definite.
  Eigen::SparseMatrix<double> periodic_strip(int length, int width)
  {
    std::vector<Eigen::Triplet<double>> t;
    auto node = [&](int i, int j) { return ((i + length) % length) * width + j; };
    for (int i = 0; i < length; ++i)
      for (int j = 0; j < width; ++j)
        {
          double degree = 1e-3;
          for (const auto &[di, dj] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}})
            if (j + dj >= 0 && j + dj < width)
              {
                t.emplace_back(node(i + di, j + dj), node(i, j), -1.0);
                degree += 1;
              }
          t.emplace_back(node(i, j), node(i, j), degree);
        }
    Eigen::SparseMatrix<double> A(length * width, length * width);
    A.setFromTriplets(t.begin(), t.end());
    return A;
  }

  /// The strip's rows split by two cuts across it, at columns 0 and length / 2 (the
  /// separator, 2 width rows), into the columns between them (0) and the others (1);
  /// with @p every > 0, every such column is a cut as well.
  std::vector<int> two_cuts(int length, int width, int every = 0)
  {
    std::vector<int> part(length * width);
    for (int i = 0; i < length; ++i)
      for (int j = 0; j < width; ++j)
        part[i * width + j] = i == 0 || i == length / 2 || (every > 0 && i % every == 0) ? 2
                              : i < length / 2                                         ? 0
                                                                                        : 1;
    return part;
  }
} // namespace

TEST(BisectedCholesky, SolvesAPeriodicStripAsTheWholeFactorDoes)
{
  const Eigen::SparseMatrix<double> A = periodic_strip(400, 12); // 4800 rows
  BisectedCholesky                  halves(A, two_cuts(400, 12));
  ASSERT_TRUE(halves.split());
  // The interior point's shifts span many decades, up to the crossover's 1e20 on open rows.
  Eigen::VectorXd v = Eigen::VectorXd::LinSpaced(A.rows(), -1.0, 2.0).array().sin();
  for (const double spread : {0.0, 10.0, 28.0})
    {
      Eigen::VectorXd shift(A.rows());
      for (Eigen::Index j = 0; j < A.rows(); ++j)
        shift[j] = spread == 0 ? 0.0 : std::pow(10.0, -8 + spread * double((j * 7919) % 97) / 96);
      ASSERT_TRUE(halves.factorise(shift)) << spread;
      Eigen::SparseMatrix<double> K = A;
      for (Eigen::Index j = 0; j < A.rows(); ++j)
        K.coeffRef(j, j) += shift[j];
      const Eigen::SimplicialLLT<Eigen::SparseMatrix<double>> whole(K);
      const Eigen::VectorXd x = halves.solve(v), x_whole = whole.solve(v);
      EXPECT_LT((K * x - v).norm(), 1e-12 * v.norm()) << spread;
      EXPECT_LT((x - x_whole).norm(), 1e-10 * x_whole.norm()) << spread;
    }
}

TEST(BisectedCholesky, SmallProblemsAndLargeSeparatorsAreNotSplit)
{
  EXPECT_TRUE(BisectedCholesky(periodic_strip(400, 12), two_cuts(400, 12)).split());
  EXPECT_FALSE(BisectedCholesky(periodic_strip(400, 12), {}).split());                   // no partition
  EXPECT_FALSE(BisectedCholesky(periodic_strip(300, 12), two_cuts(300, 12)).split());    // 3600 < min_rows
  EXPECT_FALSE(BisectedCholesky(periodic_strip(400, 12), two_cuts(400, 12, 10)).split()); // 10 % separator
}

TEST(ShiftedFactorisation, SolvesTheNewtonMatrixInItsOwnOrder)
{
  // K = A + diag(barrier) + U U^T, factorised whole in the analysis' order (P K P^T kept
  // as given): the solution must come back in K's own order, every factorisation.
  FrictionlessProblem::Scaled p;
  p.A = periodic_strip(60, 7);
  const Eigen::Index n = p.A.rows();
  for (const int walls : {0, 2})
    {
      p.U = Eigen::MatrixXd::Zero(n, walls);
      for (int c = 0; c < walls; ++c)
        for (Eigen::Index j = c; j < n; j += 7)
          p.U(j, c) = 0.1;
      ShiftedFactorisation K(p);
      const Eigen::VectorXd v = Eigen::VectorXd::LinSpaced(n, -1.0, 2.0).array().sin();
      for (const double spread : {0.0, 10.0, 28.0})
        {
          Eigen::VectorXd barrier(n);
          for (Eigen::Index j = 0; j < n; ++j)
            barrier[j] = spread == 0 ? 0.0 : std::pow(10.0, -8 + spread * double((j * 7919) % 97) / 96);
          ASSERT_TRUE(K.factorise(barrier)) << spread;
          const Eigen::VectorXd x  = K.solve(v);
          const Eigen::VectorXd Kx = p.product(x) + barrier.cwiseProduct(x);
          EXPECT_LT((Kx - v).norm(), 1e-12 * v.norm()) << walls << " walls, spread " << spread;
          // Without the refinement step (the interior point far from the solution):
          // Woodbury alone, a few digits fewer.
          const Eigen::VectorXd x0 = K.solve(v, false);
          EXPECT_LT((p.product(x0) + barrier.cwiseProduct(x0) - v).norm(), 1e-8 * v.norm())
            << walls << " walls, spread " << spread;
        }
      EXPECT_EQ(K.factorizations, 3U);
    }
}
