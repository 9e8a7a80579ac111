#include "dem/parallel/distributed_apgs.h"

#include "dem/solvers/apgs.h"
#include "dem/solvers/sweep_problem.h"

#include <deal.II/base/mpi.h>

#include <algorithm>
#include <cmath>
#include <utility>

namespace tribo::dem::parallel
{
  namespace
  {
    /// One rank's part of a distributed APGS solve (the method is in dem/parallel/distributed_apgs.h):
    /// its scaled problem with the moving b', the interface contacts and the exchange of their
    /// impulses, the sweep and the map over all ranks.
    class RankSweeps
    {
    public:
      /// @p gap_target (m; 0: none) and @p theta_h (s): with IQS the solve also aims at every
      /// contact's gap violation theta h max(0, -u~_n) at most gap_target, as the serial APGS.
      /// @p warm_from_others: the other ranks' warm-start impulses' velocity changes on this
      /// rank's bodies (DistributedSolver::add_impulses), which move b' as an exchange does.
      RankSweeps(RankProblem &p, const ContactLaw &law, GrainExchange &exchange, MPI_Comm comm,
                 DistributedReport &report, double gap_target, double theta_h,
                 const std::vector<Eigen::Vector3d> &warm_from_others);
      /// APGS's projected Gauss-Seidel sweep of @p v in place, the contacts on grains of two
      /// ranks relaxed by @p omega.
      void sweep(Eigen::VectorXd &v, double omega);
      /// Exchange the interface contacts' impulses at @p v: their changes since the last
      /// exchange go on the state, the velocities are exchanged, and what the other ranks
      /// changed on a shared body dv moves b' of the contacts on it by s_j H_j^T dv. With
      /// @p changed (increasing), only those contacts' impulses can have changed since.
      void sync(const Eigen::VectorXd &v, const std::vector<Eigen::Index> *changed = nullptr);
      /// The map over every rank's contacts at @p v (exchanged), relative to the mean loaded
      /// impulse (or, with none loaded, the largest of the ranks' scales); each contact's
      /// map and gap violation are kept for the polish.
      double relative_map(const Eigen::VectorXd &v);
      /// Whether the last check's largest gap violation over every rank is above the gap target.
      bool gaps_open() const { return gap_limit > 0 && worst_gap > gap_limit; }
      /// APGS's local polish on this rank (dem/solvers/apgs.h): polish_passes passes over
      /// its contacts whose map is above @p target times the mean loaded impulse of the last
      /// check (or whose gap violation is above the gap target) and their neighbours up to polish_rings rings away in A' (at most
      /// polish_fraction of its contacts), @p y changed in place and @p z by the same amount;
      /// the contacts on grains of two ranks relaxed by @p omega. Then (collective) the
      /// exchange of the interface contacts' impulses and the map again, recomputed only where
      /// it changed: the polished contacts' rows of A', the walls' low-rank rows, the interface
      /// contacts on a body another rank moved, into @p map. False, with nothing exchanged or changed, when no rank had
      /// anything to polish.
      bool polish(Eigen::VectorXd &y, Eigen::VectorXd &z, double target, double omega, double &map);
      /// Polishes after a check whose map @p map is above @p target (or whose gaps are open), as
      /// APGS's: until one reaches the target with the gaps closed (true: @p y is the answer), no rank has anything to polish, or
      /// polish_patience polishes in a row have not lowered the map (at most max_polishes).
      /// @p map becomes the last one; with friction a polished iterate below @p best_map
      /// becomes the safeguard's @p best.
      bool polish_to(Eigen::VectorXd &y, Eigen::VectorXd &z, double target, double omega, double &map,
                     Eigen::VectorXd &best, double &best_map);
      /// Every contact's impulse at @p y: the interface contacts' through one more exchange,
      /// the others' on the grains only this rank holds.
      void finish(const Eigen::VectorXd &y);
      /// The scaled warm start, rows per contact.
      const SweepProblem &problem() const { return sweep_problem; }

    private:
      RankProblem                 &p;
      const ContactLaw            &law;
      GrainExchange               &exchange;
      MPI_Comm                     comm;
      DistributedReport           &report;
      std::vector<char>            shared;       ///< local bodies whose velocity other ranks change
      std::vector<unsigned int>    shared_list;  ///< their local numbers
      std::vector<Eigen::Index>    interface;    ///< contacts on a shared body, increasing
      std::vector<char>            across;       ///< contacts on a grain of two ranks
      SweepProblem                 sweep_problem;
      ScaledOperator               op;
      Eigen::VectorXd              b;            ///< b', moved by the other ranks' impulses
      std::vector<Eigen::Vector2d> sent;         ///< each contact's impulse in the state, N s/m
      BodyState                    others;       ///< the other ranks' velocity changes at the last exchange
      std::vector<char>            moved;        ///< local bodies whose change in others is not zero
      std::vector<Eigen::Vector3d> mine;         ///< the shared bodies' velocities before it
      /// Each contact's map at the last check (N s/m), and the largest of each chunk of
      /// chunk_size consecutive contacts; this rank's loaded impulses' sum (N s/m) and count.
      /// A polish updates them where it changed the iterate or the maps.
      std::vector<double>          error, chunk_worst;
      /// Each contact's gap violation at the last check and the largest of each chunk (m), the
      /// largest over every rank, the gap target (m; 0: none) and theta h (s).
      std::vector<double>          gap, chunk_gap;
      double                       worst_gap = 0;
      const double                 gap_limit, theta_h;
      double                       loaded_sum = 0, loaded_count = 0;
      static constexpr Eigen::Index chunk_size = 64;
      double                       mean_loaded = 0; ///< over all ranks at the last check, N s/m
      std::vector<Eigen::Index>    local, affected_rows, dirty_chunks; ///< the polish's contacts, the maps it changed
      std::vector<char>            marked, affected, dirty;

      /// Contact @p j's map and gap violation into error and gap, from its normal row's
      /// gradient @p g_n at @p v (op set to v).
      void measure(const Eigen::VectorXd &v, Eigen::Index j, double g_n);
      /// Contact @p j's contribution to the loaded impulses at @p v, added with @p sign.
      void count_loaded(const Eigen::VectorXd &v, Eigen::Index j, double sign);
      /// The map over all ranks from chunk_worst and the loaded sums (two reductions),
      /// mean_loaded set.
      double reduced_map();

      /// b' of the interface contacts moved by the other ranks' velocity changes on the
      /// shared bodies, dv in others (moved where not zero): b'_j += s_j H_j^T dv.
      void add_to_b();
    };

    RankSweeps::RankSweeps(RankProblem &p, const ContactLaw &law, GrainExchange &exchange, MPI_Comm comm,
                           DistributedReport &report, double gap_target, double theta_h,
                           const std::vector<Eigen::Vector3d> &warm_from_others)
      : p(p)
      , law(law)
      , exchange(exchange)
      , comm(comm)
      , report(report)
      , shared(p.serial_body.size(), 0)
      , across(p.contacts.size(), 0)
      , sweep_problem(p.contacts, p.state, law)
      , op(sweep_problem.scaled)
      , b(sweep_problem.scaled.b)
      , mine(p.serial_body.size())
      , error(p.contacts.size(), 0)
      , chunk_worst((p.contacts.size() + chunk_size - 1) / chunk_size, 0)
      , gap(p.contacts.size(), 0)
      , chunk_gap(chunk_worst.size(), 0)
      , gap_limit(law.type == ContactLaw::Type::iqs && theta_h > 0 ? gap_target : 0.0)
      , theta_h(theta_h)
      , marked(p.contacts.size(), 0)
      , affected(p.contacts.size(), 0)
      , dirty(chunk_worst.size(), 0)
    {
      // Shared bodies: grains other ranks' contacts touch (ghosts here, exported grains),
      // whose contacts are relaxed with momentum, and the walls with a free degree of
      // freedom, whose changes are summed over the ranks too.
      const unsigned int n_local = static_cast<unsigned int>(p.serial_body.size()), first_rep = p.n_owned + p.n_ghost;
      std::vector<char>  two_ranks(n_local, 0);
      for (unsigned int l = p.n_owned; l < first_rep; ++l)
        shared[l] = two_ranks[l] = 1;
      for (const unsigned int l : exchange.exported())
        shared[l] = two_ranks[l] = 1;
      for (unsigned int l = first_rep; l < n_local; ++l)
        {
          const auto &im = p.state.inverse_mass[l];
          shared[l]      = im[0] > 0 || im[1] > 0 || im[2] > 0;
        }
      for (unsigned int l = 0; l < n_local; ++l)
        if (shared[l])
          shared_list.push_back(l);
      for (std::size_t j = 0; j < p.contacts.size(); ++j)
        {
          const Contact &c = p.contacts[j];
          if (shared[c.body[0]] || shared[c.body[1]])
            interface.push_back(Eigen::Index(j));
          across[j] = two_ranks[c.body[0]] || two_ranks[c.body[1]];
          sent.push_back(c.r);
        }
      // b' from the contacts' free velocities, with the other ranks' warm start on the shared
      // bodies: b'_j / s_j = u_j(state after add_impulses) - (W_local r_warm)_j.
      others.velocity     = warm_from_others;
      others.inverse_mass = p.state.inverse_mass;
      // A boundary body's nodes change on this rank only (it holds all their contacts).
      others.node_velocity = Eigen::VectorXd::Zero(p.state.node_velocity.size());
      others.node_blocks   = p.state.node_blocks;
      moved.assign(n_local, 0);
      for (const unsigned int l : shared_list)
        moved[l] = !others.velocity[l].isZero(0);
      add_to_b();
    }

    void RankSweeps::add_to_b()
    {
      const Eigen::Index     w = sweep_problem.width;
      const Eigen::VectorXd &s = sweep_problem.scaled.inv_root;
      for (const Eigen::Index j : interface)
        if (const Contact &c = p.contacts[j]; moved[c.body[0]] || moved[c.body[1]])
          {
            const Eigen::Vector2d du = others.local_velocity(c);
            for (Eigen::Index k = 0; k < w; ++k)
              b[w * j + k] += s[w * j + k] * du[k];
          }
    }

    void RankSweeps::sweep(Eigen::VectorXd &v, double omega)
    {
      op.set_vector(v);
      for (Eigen::Index j = 0; j < Eigen::Index(p.contacts.size()); ++j)
        sweep_problem.relax(op, law, b, v, j, nullptr, across[j] ? omega : 1.0);
    }

    void RankSweeps::sync(const Eigen::VectorXd &v, const std::vector<Eigen::Index> *changed)
    {
      exchange.remember(p.state);
      const auto put = [&](Eigen::Index j) {
        const Eigen::Vector2d r = sweep_problem.impulse(v, j), dr = r - sent[j];
        if (dr.x() != 0 || dr.y() != 0)
          p.state.apply_impulse(p.contacts[j], dr);
        sent[j] = r;
      };
      if (changed)
        {
          for (const Eigen::Index j : *changed)
            if (const Contact &c = p.contacts[j]; shared[c.body[0]] || shared[c.body[1]])
              put(j);
        }
      else
        for (const Eigen::Index j : interface)
          put(j);
      for (const unsigned int l : shared_list)
        mine[l] = p.state.velocity[l];
      exchange.exchange(p.state, report);
      for (const unsigned int l : shared_list)
        {
          others.velocity[l] = p.state.velocity[l] - mine[l];
          moved[l]           = !others.velocity[l].isZero(0);
        }
      add_to_b();
    }

    double RankSweeps::relative_map(const Eigen::VectorXd &v)
    {
      op.set_vector(v);
      const Eigen::Index w = sweep_problem.width, n = Eigen::Index(p.contacts.size());
      loaded_sum = loaded_count = 0;
      for (Eigen::Index c = 0; c < Eigen::Index(chunk_worst.size()); ++c)
        {
          chunk_worst[c] = chunk_gap[c] = 0;
          for (Eigen::Index j = c * chunk_size; j < std::min(n, (c + 1) * chunk_size); ++j)
            {
              measure(v, j, op.row_times(v, w * j) + b[w * j]);
              chunk_worst[c] = std::max(chunk_worst[c], error[j]);
              chunk_gap[c]   = std::max(chunk_gap[c], gap[j]);
              count_loaded(v, j, 1);
            }
        }
      return reduced_map();
    }

    void RankSweeps::measure(const Eigen::VectorXd &v, Eigen::Index j, double g_n)
    {
      error[j] = sweep_problem.contact_map(op, b, v, j, g_n);
      // u~_n = g_n sqrt(D) (m/s): its closing part times theta h.
      if (gap_limit > 0)
        gap[j] = theta_h * std::max(0.0, -g_n) / sweep_problem.scaled.inv_root[sweep_problem.width * j];
    }

    void RankSweeps::count_loaded(const Eigen::VectorXd &v, Eigen::Index j, double sign)
    {
      const Eigen::Index k = sweep_problem.width * j;
      if (v[k] > 0)
        {
          loaded_sum += sign * v[k] * sweep_problem.scaled.inv_root[k];
          loaded_count += sign;
        }
    }

    double RankSweeps::reduced_map()
    {
      ++report.checks;
      report.reductions += 2;
      const double worst     = chunk_worst.empty() ? 0 : *std::max_element(chunk_worst.begin(), chunk_worst.end());
      const double gaps      = chunk_gap.empty() ? 0 : *std::max_element(chunk_gap.begin(), chunk_gap.end());
      const double maxima[3] = {worst, sweep_problem.scale, gaps};
      const double loaded[2] = {loaded_sum, loaded_count};
      double       global_max[3], global_loaded[2];
      {
        const CommunicationTime timed(report);
        dealii::Utilities::MPI::max(maxima, comm, global_max);
        dealii::Utilities::MPI::sum(loaded, comm, global_loaded);
      }
      mean_loaded = global_loaded[1] > 0 ? global_loaded[0] / global_loaded[1] : global_max[1];
      worst_gap   = global_max[2];
      return global_max[0] / mean_loaded;
    }

    bool RankSweeps::polish(Eigen::VectorXd &y, Eigen::VectorXd &z, double target, double omega, double &map)
    {
      const Eigen::Index n = Eigen::Index(p.contacts.size()), w = sweep_problem.width;
      const auto        &A = sweep_problem.scaled.A;
      const double       threshold = target * mean_loaded;
      const auto         affect    = [&](Eigen::Index j) {
        if (!affected[j])
          {
            affected[j] = 1;
            affected_rows.push_back(j);
          }
      };
      local.clear();
      const auto open = [&](double map_of, double gap_of) {
        return map_of > threshold || (gap_limit > 0 && gap_of > gap_limit);
      };
      for (Eigen::Index c = 0; c < Eigen::Index(chunk_worst.size()); ++c)
        if (open(chunk_worst[c], chunk_gap[c]))
          for (Eigen::Index j = c * chunk_size; j < std::min(n, (c + 1) * chunk_size); ++j)
            if (open(error[j], gap[j]))
              {
                marked[j] = 1;
                local.push_back(j);
              }
      const double most = ApgsSolver::polish_fraction * double(n);
      sweep_problem.add_rings(local, marked, ApgsSolver::polish_rings, most);
      const bool polishing = !local.empty() && double(local.size()) <= most;
      bool       wall      = false;
      if (polishing)
        {
          std::sort(local.begin(), local.end()); // the sweep's order
          op.set_vector(y);
          for (const Eigen::Index j : local)
            count_loaded(y, j, -1);
          for (unsigned int pass = 0; pass < ApgsSolver::polish_passes; ++pass)
            for (const Eigen::Index j : local)
              sweep_problem.relax(op, law, b, y, j, &z, across[j] ? omega : 1.0);
          for (const Eigen::Index j : local)
            count_loaded(y, j, 1);
          for (const Eigen::Index j : local)
            {
              for (Eigen::Index k = w * j; k < w * j + w; ++k)
                {
                  for (Eigen::SparseMatrix<double>::InnerIterator a(A, k); a; ++a)
                    affect(a.row() / w);
                  wall = wall || op.has_low_rank(k);
                }
              affect(j);
            }
        }
      ++report.reductions;
      bool anyone_polishing = false;
      {
        const CommunicationTime timed(report);
        anyone_polishing = dealii::Utilities::MPI::logical_or(polishing, comm);
      }
      if (!anyone_polishing)
        return false;
      const std::vector<Eigen::Index> none;
      sync(y, polishing ? &local : &none);
      if (wall)
        for (const Eigen::Index k : op.low_rank_row_list())
          affect(k / w);
      for (const Eigen::Index j : interface)
        if (const Contact &c = p.contacts[j]; moved[c.body[0]] || moved[c.body[1]])
          affect(j);
      op.set_vector(y);
      for (const Eigen::Index j : affected_rows)
        {
          measure(y, j, op.row_times(y, w * j) + b[w * j]);
          affected[j] = 0;
          if (!dirty[j / chunk_size])
            {
              dirty[j / chunk_size] = 1;
              dirty_chunks.push_back(j / chunk_size);
            }
        }
      affected_rows.clear();
      for (const Eigen::Index c : dirty_chunks)
        {
          chunk_worst[c] = *std::max_element(error.begin() + c * chunk_size,
                                             error.begin() + std::min(n, (c + 1) * chunk_size));
          chunk_gap[c]   = *std::max_element(gap.begin() + c * chunk_size, gap.begin() + std::min(n, (c + 1) * chunk_size));
          dirty[c]       = 0;
        }
      dirty_chunks.clear();
      map = reduced_map();
      return true;
    }

    bool RankSweeps::polish_to(Eigen::VectorXd &y, Eigen::VectorXd &z, double target, double omega, double &map,
                               Eigen::VectorXd &best, double &best_map)
    {
      double       lowest = map;
      unsigned int stale  = 0;
      for (unsigned int q = 0; q < DistributedControls::max_polishes && stale < DistributedControls::polish_patience;
           ++q)
        {
          if (!polish(y, z, target, omega, map))
            break;
          if (map <= target && !gaps_open())
            return true;
          if (sweep_problem.width == 2 && map < best_map)
            {
              best     = y;
              best_map = map;
            }
          if (map < lowest)
            {
              lowest = map;
              stale  = 0;
            }
          else
            ++stale;
        }
      return false;
    }

    void RankSweeps::finish(const Eigen::VectorXd &y)
    {
      sync(y);
      for (Eigen::Index j = 0; j < Eigen::Index(p.contacts.size()); ++j)
        {
          Contact &c = p.contacts[j];
          if (!std::binary_search(interface.begin(), interface.end(), j))
            {
              const Eigen::Vector2d dr = sweep_problem.impulse(y, j) - c.r;
              if (dr.x() != 0 || dr.y() != 0)
                p.state.apply_impulse(c, dr);
            }
          c.r = sweep_problem.impulse(y, j);
        }
    }
  } // namespace

  DistributedReport DistributedApgs::solve(RankProblem &p, const ContactLaw &law, const DistributedControls &controls,
                                           double theta_h)
  {
    DistributedReport report;
    report.neighbours = exchange.neighbours();
    RankSweeps             rank(p, law, exchange, comm, report, controls.gap_target, theta_h, warm_from_others);
    const SweepProblem    &problem = rank.problem();
    const Eigen::Index     w = problem.width, rows = w * problem.n_contacts();

    // APGS's sweeps with its momentum and gradient restart; with friction under its safeguard:
    // the best iterate of the checks kept, the momentum dropped when a block raises the map.
    const bool      momentum = controls.momentum;
    const double    omega    = momentum ? controls.interface_relaxation : 1.0;
    Eigen::VectorXd y = w == 1 ? Eigen::VectorXd(problem.scaled.y.cwiseMax(0.0)) : problem.scaled.y, y_last(rows),
                    z = y, next(rows), best;
    double t = 1, map = INFINITY, best_map = INFINITY, block_map = INFINITY;
    bool   drop = false;
    for (unsigned int sweep = 1; sweep <= controls.max_sweeps; ++sweep)
      {
        next = z;
        rank.sweep(next, omega);
        report.sweeps    = sweep;
        const bool check = sweep % controls.check_interval == 0 || sweep == controls.max_sweeps;
        if (check)
          {
            rank.sync(next);
            map = rank.relative_map(next);
            if (map <= controls.residual_target && !rank.gaps_open())
              {
                y.swap(next);
                report.converged = true;
                break;
              }
            if (w == 2 && momentum)
              {
                if (map < best_map)
                  {
                    best     = next;
                    best_map = map;
                  }
                else
                  drop = map > block_map;
                block_map = map;
              }
          }
        if (momentum)
          {
            ++report.reductions;
            double opposed = 0;
            for (Eigen::Index k = 0; k < rows; ++k)
              opposed += (z[k] - next[k]) * (next[k] - y[k]);
            {
              const CommunicationTime timed(report);
              opposed = dealii::Utilities::MPI::sum(opposed, comm);
            }
            if (opposed > 0)
              t = 1;
            const double t_next = 0.5 * (1 + std::sqrt(1 + 4 * t * t));
            const double beta   = (t - 1) / t_next;
            y_last.swap(y);
            y.swap(next);
            z = y + beta * (y - y_last);
            t = t_next;
            if (std::exchange(drop, false))
              {
                t = 1;
                z = y;
              }
          }
        else
          {
            y.swap(next);
            z = y;
          }
        if (check && controls.polish && rank.polish_to(y, z, controls.residual_target, omega, map, best, best_map))
          {
            report.converged = true;
            break;
          }
        if (!check || momentum)
          rank.sync(z);
      }
    if (!report.converged && best_map < map)
      y = best; // the safeguard's best iterate
    rank.finish(y);
    const bool converged = report.converged;
    global_law_residual(p, law, theta_h, controls.residual_target, comm, report);
    report.converged = converged;
    return report;
  }
} // namespace tribo::dem::parallel
