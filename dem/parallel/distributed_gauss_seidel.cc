#include "dem/parallel/distributed_gauss_seidel.h"

#include "dem/laws/law_residual.h"
#include "dem/solvers/nlgs.h"

#include <deal.II/base/index_set.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/partitioner.h>
#include <deal.II/lac/la_parallel_vector.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace tribo::dem::parallel
{
  /// The distributed vector of the grains' velocities, three entries per grain
  /// (v_x, v_y, spin at 3 g, 3 g + 1, 3 g + 2 for global grain g). Its owned entries of the
  /// exported grains (owned grains that are ghosts on another rank) hold their velocities;
  /// the other owned entries are never read.
  struct DistributedGaussSeidel::Exchange
  {
    dealii::LinearAlgebra::distributed::Vector<double> v;
    unsigned int                                        owned_entries = 0;
    std::vector<unsigned int>                           exported; ///< local numbers of the exported grains
  };

  DistributedGaussSeidel::DistributedGaussSeidel(const RankProblem &p, MPI_Comm comm)
    : exchange(std::make_unique<Exchange>())
    , comm(comm)
  {
    dealii::IndexSet owned(3 * p.n_grains), ghosts(3 * p.n_grains);
    if (p.n_owned > 0)
      owned.add_range(3 * p.global_grain[0], 3 * (p.global_grain[p.n_owned - 1] + 1));
    for (unsigned int l = p.n_owned; l < p.n_owned + p.n_ghost; ++l)
      ghosts.add_range(3 * p.global_grain[l], 3 * (p.global_grain[l] + 1));
    owned.compress();
    ghosts.compress();
    auto &v = exchange->v;
    v.reinit(owned, ghosts, comm);
    exchange->owned_entries = 3 * p.n_owned;
    // The exported grains: those whose entries a compress of ones on every ghost reaches.
    for (unsigned int j = 0; j < 3 * p.n_ghost; ++j)
      v.local_element(exchange->owned_entries + j) = 1;
    v.compress(dealii::VectorOperation::add);
    for (unsigned int l = 0; l < p.n_owned; ++l)
      if (v.local_element(3 * l) != 0)
        exchange->exported.push_back(l);
  }

  DistributedGaussSeidel::~DistributedGaussSeidel() = default;

  DistributedReport DistributedGaussSeidel::solve(RankProblem &p, const ContactLaw &law,
                                                  const DistributedControls &controls, double theta_h)
  {
    DistributedReport report;
    auto             &v          = exchange->v;
    const unsigned    first_rep  = p.n_owned + p.n_ghost, n_local = static_cast<unsigned>(p.serial_body.size());
    const unsigned    n_rep      = n_local - first_rep;
    std::vector<Eigen::Vector3d> before(n_local - p.n_owned);
    std::vector<double>          wall_change(3 * n_rep), wall_sum(3 * n_rep);
    const auto                   remember = [&] {
      for (unsigned int l = p.n_owned; l < n_local; ++l)
        before[l - p.n_owned] = p.state.velocity[l];
    };

    // After local changes since remember(): ghost-to-owner (the changes this rank made to
    // ghosts, added by their owners to their exported grains), owner-to-ghost, and the
    // replicated bodies' changes summed over the ranks.
    const auto                  &partitioner = *v.get_partitioner();
    std::vector<unsigned int>    peers;
    for (const auto &target : partitioner.ghost_targets())
      peers.push_back(target.first);
    for (const auto &target : partitioner.import_targets())
      peers.push_back(target.first);
    std::sort(peers.begin(), peers.end());
    report.neighbours = static_cast<unsigned int>(std::unique(peers.begin(), peers.end()) - peers.begin());
    const auto exchange_changes = [&] {
      ++report.exchanges;
      report.bytes_sent += sizeof(double) * (partitioner.n_ghost_indices() + partitioner.n_import_indices());
      v.zero_out_ghost_values();
      for (unsigned int j = 0; j < p.n_ghost; ++j)
        for (unsigned int k = 0; k < 3; ++k)
          v.local_element(exchange->owned_entries + 3 * j + k) = p.state.velocity[p.n_owned + j][k] - before[j][k];
      for (const unsigned int l : exchange->exported)
        for (unsigned int k = 0; k < 3; ++k)
          v.local_element(3 * l + k) = p.state.velocity[l][k];
      v.compress(dealii::VectorOperation::add);
      for (const unsigned int l : exchange->exported)
        for (unsigned int k = 0; k < 3; ++k)
          p.state.velocity[l][k] = v.local_element(3 * l + k);
      v.update_ghost_values();
      for (unsigned int j = 0; j < p.n_ghost; ++j)
        for (unsigned int k = 0; k < 3; ++k)
          p.state.velocity[p.n_owned + j][k] = v.local_element(exchange->owned_entries + 3 * j + k);
      if (n_rep > 0)
        {
          ++report.reductions;
          for (unsigned int j = 0; j < n_rep; ++j)
            for (unsigned int k = 0; k < 3; ++k)
              wall_change[3 * j + k] = p.state.velocity[first_rep + j][k] - before[p.n_ghost + j][k];
          dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(wall_change), comm,
                                      dealii::ArrayView<double>(wall_sum));
          for (unsigned int j = 0; j < n_rep; ++j)
            for (unsigned int k = 0; k < 3; ++k)
              p.state.velocity[first_rep + j][k] = before[p.n_ghost + j][k] + wall_sum[3 * j + k];
        }
    };

    // The law residual over every rank's contacts: max |phi| and the gap violation
    // (maxima), the loaded impulses' sum and count (sums). True when below the target.
    const auto converged = [&] {
      ++report.checks;
      report.reductions += 2;
      const LawResidual local     = law_residual(p.contacts, p.state, law, theta_h);
      const double      loaded[2] = {local.mean_impulse * local.loaded, double(local.loaded)};
      const double      maxima[2] = {local.max_phi, local.gap_violation};
      double            global_max[2], global_loaded[2];
      dealii::Utilities::MPI::max(maxima, comm, global_max);
      dealii::Utilities::MPI::sum(loaded, comm, global_loaded);
      const double mean    = global_loaded[1] > 0 ? global_loaded[0] / global_loaded[1] : 0;
      report.law_residual  = mean > 0 ? global_max[0] / mean : (global_max[0] > 0 ? 1 : 0);
      report.gap_violation = global_max[1];
      return report.law_residual <= controls.residual_target;
    };

    // Nesterov's momentum on the sweeps (APGS's, dem/solvers/apgs.h), without friction:
    // y_k the impulses a sweep leaves, z_k those the next sweep starts from.
    // The contacts that touch a grain other ranks' contacts also touch (a ghost here, or an
    // exported grain): across the ranks their sweeps are Jacobi steps, whose overshoot the
    // momentum amplifies until the solve diverges; with momentum they are relaxed.
    const bool                   momentum = controls.momentum && law.friction <= 0;
    std::vector<Eigen::Vector2d> y_last;
    std::vector<bool>            shared(n_local, false), interface(p.contacts.size(), false);
    double                       t = 1;
    if (momentum)
      {
        for (unsigned int l = p.n_owned; l < first_rep; ++l)
          shared[l] = true;
        for (const unsigned int l : exchange->exported)
          shared[l] = true;
        for (std::size_t i = 0; i < p.contacts.size(); ++i)
          {
            const Contact &c = p.contacts[i];
            interface[i]     = shared[c.body[0]] || shared[c.body[1]];
            y_last.push_back(c.r);
          }
      }

    for (unsigned int sweep = 1; sweep <= controls.max_sweeps; ++sweep)
      {
        remember();
        // The sweep, and with momentum the gradient restart's sum over it: no momentum when the
        // sweep's step opposes it, (z_k - y_k+1).(y_k+1 - y_k) > 0 in the scaled variables
        // (weights W_nn + c), z_k a contact's impulse before its local solve, y_k+1 after it.
        double opposing = 0;
        for (std::size_t i = 0; i < p.contacts.size(); ++i)
          {
            Contact              &c = p.contacts[i];
            const Eigen::Vector2d z = c.r;
            gauss_seidel_update(c, p.state, law, interface[i] ? controls.interface_relaxation : 1.0);
            if (momentum)
              opposing += (c.W(0, 0) + c.compliance) * (z - c.r).dot(c.r - y_last[i]);
          }
        report.sweeps = sweep;
        const bool check = sweep % controls.check_interval == 0 || sweep == controls.max_sweeps;
        if (check)
          {
            exchange_changes();
            if (converged())
              {
                report.converged = true;
                break;
              }
            remember();
          }
        if (momentum)
          {
            ++report.reductions;
            if (dealii::Utilities::MPI::sum(opposing, comm) > 0)
              t = 1;
            const double t_next = 0.5 * (1 + std::sqrt(1 + 4 * t * t));
            const double beta   = (t - 1) / t_next;
            t                   = t_next;
            for (std::size_t i = 0; i < p.contacts.size(); ++i)
              {
                Contact              &c  = p.contacts[i];
                const Eigen::Vector2d dr = beta * (c.r - y_last[i]);
                y_last[i]                = c.r;
                if (dr.x() != 0 || dr.y() != 0)
                  {
                    p.state.apply_impulse(c, dr);
                    c.r += dr;
                  }
              }
          }
        if (!check || momentum)
          exchange_changes();
      }
    return report;
  }
} // namespace tribo::dem::parallel
