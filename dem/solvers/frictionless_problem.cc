#include "dem/solvers/frictionless_problem.h"

#include "dem/engine/body_state.h"
#include "dem/linalg/delassus.h"

#include <algorithm>
#include <cmath>

namespace tribo::dem
{
  FrictionlessProblem::FrictionlessProblem(const std::vector<Contact> &contacts,
                                           const BodyState &state, bool low_rank_bodies, unsigned int threads)
  {
    LowRankBodies low_rank;
    A = assemble_delassus(contacts, state, DelassusPart::normal, low_rank_bodies ? &low_rank : nullptr, threads);
    U = std::move(low_rank.U);
    const Eigen::Index n = static_cast<Eigen::Index>(contacts.size());
    b.resize(n);
    x.resize(n);
    diagonal.resize(n);
    cohesion.resize(n);
    for (Eigen::Index i = 0; i < n; ++i)
      {
        const Contact &c = contacts[i];
        cohesion[i]      = c.cohesion_impulse;
        b[i]             = c.u_free.x() + c.shift;
        x[i]             = std::max(0.0, c.r.x() + c.cohesion_impulse);
      }
    if ((cohesion.array() != 0).any())
      b -= product(cohesion);
    for (Eigen::Index i = 0; i < n; ++i)
      {
        A.coeffRef(i, i) += contacts[i].compliance;
        diagonal[i] = A.coeff(i, i) + (U.cols() > 0 ? U.row(i).squaredNorm() : 0.0);
      }
    double       loaded_sum = 0;
    unsigned int loaded     = 0;
    for (Eigen::Index i = 0; i < n; ++i)
      if (x[i] > 0)
        {
          loaded_sum += x[i];
          ++loaded;
        }
    scale = loaded    ? loaded_sum / loaded
            : n > 0 ? std::max(1e-300, b.cwiseAbs().cwiseQuotient(diagonal).mean())
                    : 1.0;
  }

  double FrictionlessProblem::mean_loaded(const Eigen::VectorXd &y) const
  {
    double       sum    = 0;
    unsigned int loaded = 0;
    for (Eigen::Index i = 0; i < y.size(); ++i)
      if (y[i] > 0)
        {
          sum += y[i];
          ++loaded;
        }
    return loaded ? sum / loaded : scale;
  }

  double FrictionlessProblem::natural_map(const Eigen::VectorXd &y, const Eigen::VectorXd &w) const
  {
    double worst = 0;
    for (Eigen::Index i = 0; i < y.size(); ++i)
      worst = std::max(worst, std::abs(std::min(y[i], w[i] / diagonal[i])));
    return worst;
  }

  FrictionlessProblem::Scaled FrictionlessProblem::scaled() const
  {
    Scaled p;
    p.inv_root = diagonal.cwiseSqrt().cwiseInverse();
    p.A        = A;
    for (Eigen::Index j = 0; j < p.A.cols(); ++j)
      for (Eigen::SparseMatrix<double>::InnerIterator a(p.A, j); a; ++a)
        a.valueRef() *= p.inv_root[a.row()] * p.inv_root[j];
    p.U = p.inv_root.asDiagonal() * U;
    p.b = b.cwiseProduct(p.inv_root);
    p.y = x.cwiseQuotient(p.inv_root);
    return p;
  }

  void FrictionlessProblem::apply(const Eigen::VectorXd &y, std::vector<Contact> &contacts,
                                  BodyState &state) const
  {
    for (Eigen::Index i = 0; i < y.size(); ++i)
      {
        Contact              &c = contacts[i];
        const Eigen::Vector2d r_new(std::max(0.0, y[i]) - cohesion[i], 0.0);
        const Eigen::Vector2d dr = r_new - c.r;
        if (dr.x() != 0 || dr.y() != 0)
          state.apply_impulse(c, dr);
        c.r = r_new;
      }
  }
} // namespace tribo::dem
