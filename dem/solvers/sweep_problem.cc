#include "dem/solvers/sweep_problem.h"

#include "dem/linalg/delassus.h"
#include "dem/engine/body_state.h"

#include <algorithm>
#include <cmath>

namespace tribo::dem
{
  SweepProblem::SweepProblem(const std::vector<Contact> &contacts, const BodyState &state,
                             const ContactLaw &law, unsigned int threads)
    : width(law.friction > 0 ? 2 : 1)
    , friction(law.friction > 0 ? law.friction : 0)
  {
    if (width == 1)
      {
        const FrictionlessProblem lcp(contacts, state, true, threads);
        scaled   = lcp.scaled();
        scale    = lcp.scale;
        cohesion = lcp.cohesion;
        return;
      }
    const Eigen::Index n = static_cast<Eigen::Index>(contacts.size());
    LowRankBodies      low_rank;
    Eigen::SparseMatrix<double> A = assemble_delassus(contacts, state, DelassusPart::full, &low_rank, threads);
    const Eigen::MatrixXd      &U = low_rank.U;
    Eigen::VectorXd b(2 * n), x(2 * n), shifted_cohesion = Eigen::VectorXd::Zero(2 * n);
    cohesion.resize(n);
    for (Eigen::Index i = 0; i < n; ++i)
      {
        const Contact &c        = contacts[i];
        cohesion[i]             = c.cohesion_impulse;
        shifted_cohesion[2 * i] = c.cohesion_impulse;
        b[2 * i]                = c.u_free.x() + c.shift;
        b[2 * i + 1]            = c.u_free.y();
        x[2 * i]                = std::max(0.0, c.r.x() + c.cohesion_impulse);
        x[2 * i + 1]            = std::clamp(c.r.y(), -friction * x[2 * i], friction * x[2 * i]);
      }
    if ((shifted_cohesion.array() != 0).any())
      b -= FrictionlessProblem::product_with(A, U, shifted_cohesion);
    scaled.inv_root.resize(2 * n);
    double       loaded_sum = 0, free_sum = 0;
    unsigned int loaded     = 0;
    for (Eigen::Index i = 0; i < n; ++i)
      {
        A.coeffRef(2 * i, 2 * i) += contacts[i].compliance;
        const double diagonal = A.coeff(2 * i, 2 * i) + (U.cols() > 0 ? U.row(2 * i).squaredNorm() : 0.0);
        scaled.inv_root[2 * i] = scaled.inv_root[2 * i + 1] = 1 / std::sqrt(diagonal);
        free_sum += std::abs(b[2 * i]) / diagonal;
        if (x[2 * i] > 0)
          {
            loaded_sum += x[2 * i];
            ++loaded;
          }
      }
    scale = loaded ? loaded_sum / loaded : n > 0 ? std::max(1e-300, free_sum / n) : 1.0;

    const Eigen::VectorXd &s = scaled.inv_root;
    scaled.A                 = A;
    for (Eigen::Index j = 0; j < scaled.A.cols(); ++j)
      for (Eigen::SparseMatrix<double>::InnerIterator a(scaled.A, j); a; ++a)
        a.valueRef() *= s[a.row()] * s[j];
    scaled.U = s.asDiagonal() * U;
    scaled.b = b.cwiseProduct(s);
    scaled.y = x.cwiseQuotient(s);
    own_block.resize(n);
    for (Eigen::Index i = 0; i < n; ++i)
      {
        Eigen::Matrix2d block;
        for (int p = 0; p < 2; ++p)
          for (int q = 0; q < 2; ++q)
            block(p, q) = scaled.A.coeff(2 * i + p, 2 * i + q) +
                          (scaled.U.cols() > 0 ? scaled.U.row(2 * i + p).dot(scaled.U.row(2 * i + q)) : 0.0);
        own_block[i] = block;
      }
  }

  void SweepProblem::apply(const Eigen::VectorXd &y, std::vector<Contact> &contacts, BodyState &state) const
  {
    for (Eigen::Index i = 0; i < n_contacts(); ++i)
      {
        Contact              &c     = contacts[i];
        const Eigen::Vector2d r_new = impulse(y, i);
        const Eigen::Vector2d dr    = r_new - c.r;
        if (dr.x() != 0 || dr.y() != 0)
          state.apply_impulse(c, dr);
        c.r = r_new;
      }
  }
} // namespace tribo::dem
