#include "dem/linalg/scaled_operator.h"

#include <cmath>

namespace tribo::dem
{
  ScaledOperator::ScaledOperator(const FrictionlessProblem::Scaled &p)
    : A(p.A)
    , start(p.A.outerIndexPtr())
    , row(p.A.innerIndexPtr())
    , value(p.A.valuePtr())
    , low_rank_start(p.U.rows() + 1, 0)
    , low_rank_norm2(p.U.squaredNorm())
    , Ut_v(p.U.cols())
  {
    for (Eigen::Index j = 0; j < p.U.rows(); ++j)
      {
        for (Eigen::Index k = 0; k < p.U.cols(); ++k)
          if (p.U(j, k) != 0)
            {
              low_rank_column.push_back(k);
              low_rank_value.push_back(p.U(j, k));
            }
        low_rank_start[j + 1] = static_cast<Eigen::Index>(low_rank_value.size());
        if (low_rank_start[j + 1] > low_rank_start[j])
          low_rank_rows.push_back(j);
      }
  }

  void ScaledOperator::set_vector(const Eigen::VectorXd &v)
  {
    Ut_v.setZero();
    for (const Eigen::Index j : low_rank_rows)
      for (Eigen::Index q = low_rank_start[j]; q < low_rank_start[j + 1]; ++q)
        Ut_v[low_rank_column[q]] += low_rank_value[q] * v[j];
  }

  double ScaledOperator::norm_bound() const
  {
    double bound = 0;
    for (Eigen::Index j = 0; j < A.cols(); ++j)
      {
        double sum = 0;
        for (int k = start[j]; k < start[j + 1]; ++k)
          sum += std::abs(value[k]);
        bound = std::max(bound, sum);
      }
    return bound + low_rank_norm2;
  }
} // namespace tribo::dem
