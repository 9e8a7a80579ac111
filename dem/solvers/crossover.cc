#include "dem/solvers/crossover.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace tribo::dem
{
  ShiftedFactorisation::ShiftedFactorisation(const FrictionlessProblem::Scaled &problem,
                                             const std::vector<int> &partition,
                                             const std::vector<int> &levels)
    : p(problem), K(problem.A), diagonal(problem.A.rows()), unit(problem.A.rows()),
      barrier(Eigen::VectorXd::Zero(problem.A.rows())), halves(problem.A, partition)
  {
    if (halves.split())
      return;
    cholmod_common &common = cholesky.cholmod();
    common.print           = 0; // a failed factorisation is reported by factorise()
    cholesky.setMode(Eigen::CholmodSimplicialLLt);
    // P: CAMD's order of the dissection's levels, or CHOLMOD's own (AMD, or METIS if AMD
    // fills badly); postordered by the analysis.
    cholmod_sparse lower = Eigen::viewAsCholmod(K);
    lower.stype          = -1;
    std::vector<int> camd(levels.size());
    const bool       dissected = !levels.empty() && Eigen::Index(levels.size()) == K.rows() &&
                           cholmod_camd(&lower, nullptr, 0, const_cast<int *>(levels.data()), camd.data(), &common);
    if (dissected)
      {
        common.nmethods           = 1;
        common.method[0].ordering = CHOLMOD_GIVEN;
      }
    cholmod_factor *symbolic =
      dissected ? cholmod_analyze_p(&lower, camd.data(), nullptr, 0, &common) : cholmod_analyze(&lower, &common);
    if (symbolic == nullptr)
      throw std::runtime_error("CHOLMOD could not analyse the interior point's Newton matrix");
    const int *order = static_cast<const int *>(symbolic->Perm);
    ordering.resize(K.rows());
    for (int k = 0; k < K.rows(); ++k)
      ordering.indices()[order[k]] = k; // Eigen's P x puts x[order[k]] at k
    K = permuted_upper(K, order);        // analysed in its natural order below
    cholmod_free_factor(&symbolic, &common);
    common.nmethods             = 1;
    common.method[0].ordering   = CHOLMOD_NATURAL;
    common.postorder            = 0;
    cholesky.analyzePattern(K);
    for (Eigen::Index j = 0; j < K.rows(); ++j)
      {
        diagonal[j] = &K.coeffRef(ordering.indices()[j], ordering.indices()[j]);
        unit[j]     = *diagonal[j];
      }
  }

  bool ShiftedFactorisation::factorise(const Eigen::VectorXd &b)
  {
    barrier = b;
    ++factorizations;
    if (halves.split())
      {
        if (!halves.factorise(barrier))
          return false;
      }
    else
      {
        for (Eigen::Index j = 0; j < K.rows(); ++j)
          *diagonal[j] = unit[j] + barrier[j];
        cholesky.factorize(K);
        if (cholesky.info() != Eigen::Success)
          return false;
      }
    if (p.U.cols() > 0)
      {
        Z = solve_sparse(p.U);
        capacitance.compute(Eigen::MatrixXd::Identity(p.U.cols(), p.U.cols()) + p.U.transpose() * Z);
      }
    return true;
  }

  Eigen::VectorXd ShiftedFactorisation::solve_sparse(const Eigen::VectorXd &v) const
  {
    if (halves.split())
      return halves.solve(v);
    return ordering.transpose() * Eigen::VectorXd(cholesky.solve(ordering * v));
  }

  Eigen::MatrixXd ShiftedFactorisation::solve_sparse(const Eigen::MatrixXd &V) const
  {
    if (!halves.split())
      return ordering.transpose() * Eigen::MatrixXd(cholesky.solve(ordering * V));
    Eigen::MatrixXd X(V.rows(), V.cols());
    for (Eigen::Index c = 0; c < V.cols(); ++c)
      X.col(c) = halves.solve(V.col(c));
    return X;
  }

  Eigen::VectorXd ShiftedFactorisation::woodbury(const Eigen::VectorXd &v) const
  {
    Eigen::VectorXd t = solve_sparse(v);
    t -= Z * capacitance.solve(p.U.transpose() * t);
    return t;
  }

  Eigen::VectorXd ShiftedFactorisation::solve(const Eigen::VectorXd &v, bool refine) const
  {
    if (p.U.cols() == 0)
      return solve_sparse(v);
    Eigen::VectorXd t = woodbury(v);
    if (!refine)
      return t;
    t += woodbury(v - p.product(t) - barrier.cwiseProduct(t));
    return t;
  }

  double least_norm_crossover(const FrictionlessProblem::Scaled &p, ShiftedFactorisation &K,
                              std::vector<char> &closed, const CrossoverTarget &target,
                              Eigen::VectorXd &y, Eigen::VectorXd &g)
  {
    const Eigen::Index     n        = y.size();
    const Eigen::VectorXd &inv_root = p.inv_root;
    Eigen::VectorXd        barrier(n);
    for (Eigen::Index j = 0; j < n; ++j)
      barrier[j] = closed[j] ? crossover::shift : 1e20;
    if (!K.factorise(barrier))
      return -1;
    auto restrict_to_closed = [&](Eigen::VectorXd &v) {
      for (Eigen::Index j = 0; j < n; ++j)
        if (!closed[j])
          v[j] = 0;
    };
    const double tolerance = 0.3 * target.residual_target * target.iterate_mean;
    // Preconditioned conjugate gradients on the closed block from d = 0.
    auto close_exactly = [&]() {
      Eigen::VectorXd z = y;
      restrict_to_closed(z);
      Eigen::VectorXd residual = -(p.product(z) + p.b);
      restrict_to_closed(residual);
      Eigen::VectorXd w = K.solve(residual);
      restrict_to_closed(w);
      Eigen::VectorXd direction = w, q;
      double          rw        = residual.dot(w);
      for (unsigned int k = 0; k < crossover::iterations; ++k)
        {
          q = p.product(direction);
          restrict_to_closed(q);
          const double curvature = direction.dot(q);
          if (!(curvature > 0))
            break;
          const double a = rw / curvature;
          z += a * direction;
          residual -= a * q;
          if ((residual.cwiseAbs().cwiseProduct(inv_root)).maxCoeff() <= tolerance)
            break;
          w = K.solve(residual);
          restrict_to_closed(w);
          const double rw_next = residual.dot(w);
          direction            = w + (rw_next / rw) * direction;
          rw                   = rw_next;
        }
      return z;
    };
    Eigen::VectorXd z = close_exactly();
    for (unsigned int pass = 0; pass < 2 && z.minCoeff() < 0; ++pass)
      {
        for (Eigen::Index j = 0; j < n; ++j)
          if (z[j] < 0)
            closed[j] = 0;
        z = close_exactly();
      }
    z                        = z.cwiseMax(0.0);
    const Eigen::VectorXd gz = p.product(z) + p.b;
    double                map = 0, sum = 0, count = 0;
    for (Eigen::Index j = 0; j < n; ++j)
      {
        map = std::max(map, std::abs(std::min(z[j], gz[j])) * inv_root[j]);
        if (z[j] > gz[j])
          {
            sum += z[j] * inv_root[j];
            ++count;
          }
      }
    // Without a closed contact the mean is the iterate's (nothing to compare).
    const double z_mean = count > 0 ? sum / count : target.iterate_mean;
    if (map > target.residual_target * std::min(z_mean, target.iterate_mean) ||
        !(z_mean <= crossover::growth_limit * target.warm_mean))
      return -1;
    y = z;
    g = gz;
    return map;
  }
} // namespace tribo::dem
