#include "dem/parallel/band_split.h"

#include "dem/parallel/all_gather.h"
#include "dem/parallel/rank_problem.h"

#include <deal.II/base/mpi.h>

#include <algorithm>
#include <cstdint>
#include <limits>

namespace tribo::dem::parallel
{
  BandSplit::BandSplit(MPI_Comm comm, double margin, double rebalance_at)
    : comm(comm)
    , rank(dealii::Utilities::MPI::this_mpi_process(comm))
    , ranks(dealii::Utilities::MPI::n_mpi_processes(comm))
    , rebalance_at(rebalance_at)
    , margin(margin)
  {}

  std::optional<PairBand> BandSplit::own_band(const ParticleSystem &system)
  {
    if (!partition)
      return std::nullopt;
    if (!ownership)
      heights = disc_heights(system);
    else
      {
        // The discs of grains this rank does not hold are stale: no pair of theirs is its own.
        heights.resize(system.discs.size());
        for (std::size_t d = 0; d < heights.size(); ++d)
          heights[d] = ownership->holds(system.discs[d].body) ? disc_height(system, static_cast<unsigned int>(d))
                                                              : std::numeric_limits<double>::quiet_NaN();
      }
    return PairBand{partition->cut[rank], partition->cut[rank + 1], &heights};
  }

  ContactSplit::Share BandSplit::divide(const ParticleSystem &system, std::vector<Contact> &pairs, bool all)
  {
    if (!all)
      {
        // The pairs are this rank's already: compare the counts.
        const std::vector<std::uint64_t> counts =
          dealii::Utilities::MPI::all_gather(comm, std::uint64_t(pairs.size()));
        std::uint64_t total = 0, largest = 0;
        for (const std::uint64_t c : counts)
          {
            total += c;
            largest = std::max(largest, c);
          }
        if (total < std::uint64_t(min_contacts_per_rank) * ranks || double(largest) * ranks > rebalance_at * double(total))
          {
            // The ownership stays until the caller has made the state whole (make_whole()).
            partition.reset();
            return last = Share::search_all;
          }
        return last = Share::own;
      }
    // Every pair: the state is whole on every rank.
    ownership.reset();
    if (pairs.size() < std::size_t(min_contacts_per_rank) * ranks)
      {
        partition.reset();
        return last = Share::whole;
      }
    heights = disc_heights(system);
    std::vector<double> y(pairs.size());
    for (std::size_t i = 0; i < pairs.size(); ++i)
      y[i] = 0.5 * (heights[pairs[i].disc[0]] + heights[pairs[i].disc[1]]);
    partition = BandPartition::balanced(y, ranks);
    ++n_cuts;
    ownership.emplace(comm, margin);
    ownership->start(system, *partition);
    std::size_t kept = 0;
    for (std::size_t i = 0; i < pairs.size(); ++i)
      if (partition->band_of(y[i]) == rank)
        pairs[kept++] = pairs[i];
    pairs.resize(kept);
    return last = Share::own;
  }

  void BandSplit::sum(double *values, std::size_t n) const
  {
    sum_with_the_same_bits(values, n, comm);
  }

  void BandSplit::min(double *values, std::size_t n) const
  {
    MPI_Allreduce(MPI_IN_PLACE, values, static_cast<int>(n), MPI_DOUBLE, MPI_MIN, comm);
  }

  void BandSplit::make_whole(ParticleSystem &system) const
  {
    if (ownership)
      ownership->gather(system);
  }

  void BandSplit::keep()
  {
    kept = Kept{partition, ownership, last};
  }

  void BandSplit::go_back()
  {
    partition = kept->partition;
    ownership = kept->ownership;
    last      = kept->last;
  }

  std::vector<KeyedImpulse> BandSplit::all_gathered(const std::vector<KeyedImpulse> &mine) const
  {
    return parallel::all_gathered(mine, comm);
  }
} // namespace tribo::dem::parallel
