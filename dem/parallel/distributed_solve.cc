#include "dem/parallel/distributed_solve.h"

#include "dem/laws/law_residual.h"

#include <deal.II/base/index_set.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/partitioner.h>
#include <deal.II/lac/la_parallel_vector.h>

#include <algorithm>

namespace tribo::dem::parallel
{
  /// The distributed vector of the grains' velocities, three entries per grain
  /// (v_x, v_y, spin at 3 g, 3 g + 1, 3 g + 2 for global grain g). Its owned entries of the
  /// exported grains hold their velocities; the other owned entries are never read.
  struct GrainExchange::Vector
  {
    dealii::LinearAlgebra::distributed::Vector<double> v;
    std::vector<unsigned int>                           exported; ///< local numbers of the exported grains
  };

  GrainExchange::GrainExchange(const RankProblem &p, MPI_Comm comm)
    : vector(std::make_unique<Vector>())
    , comm(comm)
    , n_owned(p.n_owned)
    , n_ghost(p.n_ghost)
    , n_local(static_cast<unsigned int>(p.serial_body.size()))
    , before(n_local - n_owned)
    , wall_change(3 * p.n_replicated())
    , wall_sum(3 * p.n_replicated())
  {
    dealii::IndexSet owned(3 * p.n_grains), ghosts(3 * p.n_grains);
    if (p.n_owned > 0)
      owned.add_range(3 * p.global_grain[0], 3 * (p.global_grain[p.n_owned - 1] + 1));
    for (unsigned int l = p.n_owned; l < p.n_owned + p.n_ghost; ++l)
      ghosts.add_range(3 * p.global_grain[l], 3 * (p.global_grain[l] + 1));
    owned.compress();
    ghosts.compress();
    auto &v = vector->v;
    v.reinit(owned, ghosts, comm);
    // The exported grains: those whose entries a compress of ones on every ghost reaches.
    for (unsigned int j = 0; j < 3 * p.n_ghost; ++j)
      v.local_element(3 * n_owned + j) = 1;
    v.compress(dealii::VectorOperation::add);
    for (unsigned int l = 0; l < p.n_owned; ++l)
      if (v.local_element(3 * l) != 0)
        vector->exported.push_back(l);
    const auto               &partitioner = *v.get_partitioner();
    std::vector<unsigned int> ranks;
    for (const auto &target : partitioner.ghost_targets())
      ranks.push_back(target.first);
    for (const auto &target : partitioner.import_targets())
      ranks.push_back(target.first);
    std::sort(ranks.begin(), ranks.end());
    peers = static_cast<unsigned int>(std::unique(ranks.begin(), ranks.end()) - ranks.begin());
  }

  GrainExchange::~GrainExchange() = default;

  const std::vector<unsigned int> &GrainExchange::exported() const { return vector->exported; }

  unsigned int GrainExchange::neighbours() const { return peers; }

  void GrainExchange::remember(const BodyState &state)
  {
    for (unsigned int l = n_owned; l < n_local; ++l)
      before[l - n_owned] = state.velocity[l];
  }

  void GrainExchange::exchange(BodyState &state, DistributedReport &report)
  {
    const CommunicationTime timed(report);
    auto             &v           = vector->v;
    const auto       &partitioner = *v.get_partitioner();
    const unsigned    first_rep   = n_owned + n_ghost, n_rep = n_local - first_rep;
    ++report.exchanges;
    report.bytes_sent += sizeof(double) * (partitioner.n_ghost_indices() + partitioner.n_import_indices());
    v.zero_out_ghost_values();
    for (unsigned int j = 0; j < n_ghost; ++j)
      for (unsigned int k = 0; k < 3; ++k)
        v.local_element(3 * n_owned + 3 * j + k) = state.velocity[n_owned + j][k] - before[j][k];
    for (const unsigned int l : vector->exported)
      for (unsigned int k = 0; k < 3; ++k)
        v.local_element(3 * l + k) = state.velocity[l][k];
    v.compress(dealii::VectorOperation::add);
    for (const unsigned int l : vector->exported)
      for (unsigned int k = 0; k < 3; ++k)
        state.velocity[l][k] = v.local_element(3 * l + k);
    v.update_ghost_values();
    for (unsigned int j = 0; j < n_ghost; ++j)
      for (unsigned int k = 0; k < 3; ++k)
        state.velocity[n_owned + j][k] = v.local_element(3 * n_owned + 3 * j + k);
    if (n_rep > 0)
      {
        ++report.reductions;
        for (unsigned int j = 0; j < n_rep; ++j)
          for (unsigned int k = 0; k < 3; ++k)
            wall_change[3 * j + k] = state.velocity[first_rep + j][k] - before[n_ghost + j][k];
        dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(wall_change), comm,
                                    dealii::ArrayView<double>(wall_sum));
        for (unsigned int j = 0; j < n_rep; ++j)
          for (unsigned int k = 0; k < 3; ++k)
            state.velocity[first_rep + j][k] = before[n_ghost + j][k] + wall_sum[3 * j + k];
      }
  }

  void DistributedSolver::add_impulses(RankProblem &p, DistributedReport &report)
  {
    exchange.remember(p.state);
    for (const Contact &c : p.contacts)
      if (c.r.x() != 0 || c.r.y() != 0)
        p.state.apply_impulse(c, c.r);
    warm_from_others = p.state.velocity;
    exchange.exchange(p.state, report);
    for (std::size_t l = 0; l < warm_from_others.size(); ++l)
      warm_from_others[l] = p.state.velocity[l] - warm_from_others[l];
  }

  bool global_law_residual(const RankProblem &p, const ContactLaw &law, double theta_h, double target,
                           MPI_Comm comm, DistributedReport &report)
  {
    ++report.checks;
    report.reductions += 2;
    const LawResidual local     = law_residual(p.contacts, p.state, law, theta_h);
    const double      loaded[4] = {local.mean_impulse * local.loaded, double(local.loaded),
                                   local.velocity_scale * double(p.contacts.size()), double(p.contacts.size())};
    const double      maxima[2] = {local.max_phi, local.gap_violation};
    double            global_max[2], global_loaded[4];
    {
      const CommunicationTime timed(report);
      dealii::Utilities::MPI::max(maxima, comm, global_max);
      dealii::Utilities::MPI::sum(loaded, comm, global_loaded);
    }
    const double mean    = global_loaded[1] > 0 ? global_loaded[0] / global_loaded[1] : 0;
    const double scale   = global_loaded[3] > 0 ? global_loaded[2] / global_loaded[3] : 0;
    report.law_residual  = relative_law_residual(global_max[0], mean, scale);
    report.gap_violation = global_max[1];
    return report.law_residual <= target;
  }
} // namespace tribo::dem::parallel
