#pragma once
/// @file Every rank's vector of plain records concatenated in rank order, on every rank.

#include <mpi.h>

#include <deal.II/base/mpi.h>

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
} // namespace tribo::dem::parallel
