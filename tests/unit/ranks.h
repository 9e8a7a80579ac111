#pragma once
// What the tests run on 1 to 4 MPI ranks share (tests/unit/CMakeLists.txt): the world's
// ranks and a sum over them.
#include <deal.II/base/mpi.h>

#include <vector>

namespace tribo::dem::test
{
  inline MPI_Comm     world() { return MPI_COMM_WORLD; }
  inline unsigned int n_ranks() { return dealii::Utilities::MPI::n_mpi_processes(world()); }
  inline unsigned int my_rank() { return dealii::Utilities::MPI::this_mpi_process(world()); }

  /// @p values summed over the ranks.
  inline std::vector<double> summed(const std::vector<double> &values)
  {
    std::vector<double> sum(values.size());
    dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(values), world(), dealii::ArrayView<double>(sum));
    return sum;
  }
} // namespace tribo::dem::test
