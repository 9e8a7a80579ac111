#include "dem/parallel/distributed_apgs.h"

#include "dem/solvers/sweep_problem.h"

#include <deal.II/base/mpi.h>

#include <algorithm>
#include <cmath>

namespace tribo::dem::parallel
{
  DistributedApgs::DistributedApgs(const RankProblem &p, MPI_Comm comm)
    : exchange(p, comm)
    , comm(comm)
  {}

  DistributedReport DistributedApgs::solve(RankProblem &p, const ContactLaw &law, const DistributedControls &controls,
                                           double theta_h)
  {
    DistributedReport     report;
    report.neighbours     = exchange.neighbours();
    std::vector<Contact> &contacts = p.contacts;
    const Eigen::Index    n = static_cast<Eigen::Index>(contacts.size());
    const unsigned int    n_local = static_cast<unsigned int>(p.serial_body.size()), first_rep = p.n_owned + p.n_ghost;

    // Shared bodies: grains other ranks' contacts touch (ghosts here, exported grains), whose
    // contacts are relaxed with momentum, and the walls with a free degree of freedom, whose
    // changes are summed over the ranks too.
    std::vector<char> shared(n_local, 0), across(n_local, 0);
    for (unsigned int l = p.n_owned; l < first_rep; ++l)
      shared[l] = across[l] = 1;
    for (const unsigned int l : exchange.exported())
      shared[l] = across[l] = 1;
    for (unsigned int l = first_rep; l < n_local; ++l)
      {
        const auto &im = p.state.inverse_mass[l];
        shared[l]      = im[0] > 0 || im[1] > 0 || im[2] > 0;
      }
    std::vector<Eigen::Index> interface;
    std::vector<char>         relaxed(n, 0);
    for (Eigen::Index j = 0; j < n; ++j)
      {
        const Contact &c = contacts[j];
        if (shared[c.body[0]] || shared[c.body[1]])
          interface.push_back(j);
        relaxed[j] = across[c.body[0]] || across[c.body[1]];
      }

    // The local free velocities: the state without this rank's warm-start impulses.
    std::vector<Eigen::Vector2d> caller_u_free(n);
    {
      BodyState without = p.state;
      for (const Contact &c : contacts)
        if (c.r.x() != 0 || c.r.y() != 0)
          without.apply_impulse(c, -c.r);
      for (Eigen::Index j = 0; j < n; ++j)
        {
          caller_u_free[j]   = contacts[j].u_free;
          contacts[j].u_free = without.local_velocity(contacts[j]);
        }
    }
    const SweepProblem     problem(contacts, p.state, law);
    const Eigen::VectorXd &s = problem.scaled.inv_root;
    const Eigen::Index     w = problem.width, rows = w * n;
    ScaledOperator         op(problem.scaled);
    Eigen::VectorXd        b = problem.scaled.b;

    // Exchange the interface contacts' impulses at @p v: their changes since the last
    // exchange go on the state, the velocities are exchanged, and what the other ranks
    // changed on a shared body moves b' of the contacts on it.
    std::vector<Eigen::Vector2d> sent(n);
    for (Eigen::Index j = 0; j < n; ++j)
      sent[j] = contacts[j].r;
    BodyState others;
    others.velocity.assign(n_local, Eigen::Vector3d::Zero());
    others.inverse_mass = p.state.inverse_mass;
    std::vector<Eigen::Vector3d> mine(n_local);
    const auto                   sync = [&](const Eigen::VectorXd &v) {
      exchange.remember(p.state);
      for (const Eigen::Index j : interface)
        {
          const Eigen::Vector2d r = problem.impulse(v, j), dr = r - sent[j];
          if (dr.x() != 0 || dr.y() != 0)
            p.state.apply_impulse(contacts[j], dr);
          sent[j] = r;
        }
      for (unsigned int l = 0; l < n_local; ++l)
        if (shared[l])
          mine[l] = p.state.velocity[l];
      exchange.exchange(p.state, report);
      for (unsigned int l = 0; l < n_local; ++l)
        if (shared[l])
          others.velocity[l] = p.state.velocity[l] - mine[l];
      for (const Eigen::Index j : interface)
        {
          const Eigen::Vector2d du = others.local_velocity(contacts[j]);
          for (Eigen::Index k = 0; k < w; ++k)
            b[w * j + k] += s[w * j + k] * du[k];
        }
    };

    // The map over every rank's contacts at @p v (exchanged), relative to the mean loaded
    // impulse (or, with none loaded, the largest of the ranks' scales).
    const auto relative_map = [&](const Eigen::VectorXd &v) {
      ++report.checks;
      report.reductions += 2;
      op.set_vector(v);
      double worst = 0, loaded[2] = {0, 0};
      for (Eigen::Index j = 0; j < n; ++j)
        {
          const Eigen::Index k = w * j;
          worst                = std::max(worst, problem.contact_map(op, b, v, j, op.row_times(v, k) + b[k]));
          if (v[k] > 0)
            {
              loaded[0] += v[k] * s[k];
              loaded[1] += 1;
            }
        }
      const double maxima[2] = {worst, problem.scale};
      double       global_max[2], global_loaded[2];
      dealii::Utilities::MPI::max(maxima, comm, global_max);
      dealii::Utilities::MPI::sum(loaded, comm, global_loaded);
      return global_max[0] / (global_loaded[1] > 0 ? global_loaded[0] / global_loaded[1] : global_max[1]);
    };

    // APGS's sweeps, with its momentum and gradient restart without friction.
    const bool      momentum = controls.momentum && w == 1;
    const double    omega    = momentum ? controls.interface_relaxation : 1.0;
    Eigen::VectorXd y = w == 1 ? Eigen::VectorXd(problem.scaled.y.cwiseMax(0.0)) : problem.scaled.y, y_last(rows),
                    z = y, next(rows);
    double t = 1;
    for (unsigned int sweep = 1; sweep <= controls.max_sweeps; ++sweep)
      {
        next = z;
        op.set_vector(next);
        for (Eigen::Index j = 0; j < n; ++j)
          problem.relax(op, law, b, next, j, nullptr, relaxed[j] ? omega : 1.0);
        report.sweeps    = sweep;
        const bool check = sweep % controls.check_interval == 0 || sweep == controls.max_sweeps;
        if (check)
          {
            sync(next);
            if (relative_map(next) <= controls.residual_target)
              {
                y.swap(next);
                report.converged = true;
                break;
              }
          }
        if (momentum)
          {
            ++report.reductions;
            double opposed = 0;
            for (Eigen::Index k = 0; k < rows; ++k)
              opposed += (z[k] - next[k]) * (next[k] - y[k]);
            if (dealii::Utilities::MPI::sum(opposed, comm) > 0)
              t = 1;
            const double t_next = 0.5 * (1 + std::sqrt(1 + 4 * t * t));
            const double beta   = (t - 1) / t_next;
            y_last.swap(y);
            y.swap(next);
            z = y + beta * (y - y_last);
            t = t_next;
          }
        else
          {
            y.swap(next);
            z = y;
          }
        if (!check || momentum)
          sync(z);
      }

    // Every contact's impulse at y: the interface contacts' through one more exchange, the
    // others' on the grains only this rank holds.
    sync(y);
    for (Eigen::Index j = 0; j < n; ++j)
      {
        Contact &c = contacts[j];
        if (!std::binary_search(interface.begin(), interface.end(), j))
          {
            const Eigen::Vector2d dr = problem.impulse(y, j) - c.r;
            if (dr.x() != 0 || dr.y() != 0)
              p.state.apply_impulse(c, dr);
          }
        c.r      = problem.impulse(y, j);
        c.u_free = caller_u_free[j];
      }
    const bool converged = report.converged;
    global_law_residual(p, law, theta_h, controls.residual_target, comm, report);
    report.converged = converged;
    return report;
  }
} // namespace tribo::dem::parallel
