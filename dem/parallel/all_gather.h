#pragma once
/// @file Every rank's vector of plain records concatenated in rank order, on every rank; and
/// sums over the ranks with the same bits on every rank.

#include <mpi.h>

#include <deal.II/base/mpi.h>

#include <cstddef>
#include <type_traits>
#include <vector>

namespace tribo::dem::parallel
{
  /// Every rank's @p mine concatenated in rank order, on every rank (one MPI_Allgatherv of
  /// the records' bytes; @p T trivially copyable). Collective on @p comm.
  template <typename T>
  std::vector<T> all_gathered(const std::vector<T> &mine, MPI_Comm comm)
  {
    static_assert(std::is_trivially_copyable_v<T>, "records are sent as bytes");
    const int        bytes = static_cast<int>(mine.size() * sizeof(T));
    std::vector<int> sizes = dealii::Utilities::MPI::all_gather(comm, bytes);
    std::vector<int> offsets(sizes.size() + 1, 0);
    for (std::size_t k = 0; k < sizes.size(); ++k)
      offsets[k + 1] = offsets[k] + sizes[k];
    std::vector<T> all(std::size_t(offsets.back()) / sizeof(T));
    MPI_Allgatherv(mine.data(), bytes, MPI_BYTE, all.data(), sizes.data(), offsets.data(), MPI_BYTE, comm);
    return all;
  }

  /// @p values (@p n) summed over the ranks of @p comm, reduced on rank 0 and broadcast: the
  /// same bits on every rank (an all-reduce may add in a different order on each). Collective.
  inline void sum_with_the_same_bits(double *values, std::size_t n, MPI_Comm comm)
  {
    const int count = static_cast<int>(n);
    if (dealii::Utilities::MPI::this_mpi_process(comm) == 0)
      MPI_Reduce(MPI_IN_PLACE, values, count, MPI_DOUBLE, MPI_SUM, 0, comm);
    else
      MPI_Reduce(values, nullptr, count, MPI_DOUBLE, MPI_SUM, 0, comm);
    MPI_Bcast(values, count, MPI_DOUBLE, 0, comm);
  }
} // namespace tribo::dem::parallel
