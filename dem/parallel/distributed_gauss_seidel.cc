#include "dem/parallel/distributed_gauss_seidel.h"

#include "dem/solvers/nlgs.h"

#include <deal.II/base/mpi.h>

#include <algorithm>
#include <cmath>

namespace tribo::dem::parallel
{
  namespace
  {
    /// NLGS's check over every rank's contacts (DistributedControls::nlgs_stop): each rank's
    /// check pass, its sums and maxima reduced over the ranks; true when converged.
    bool nlgs_converged(const RankProblem &p, const ContactLaw &law, const DistributedControls &controls,
                        double theta_h, MPI_Comm comm, DistributedReport &report)
    {
      ++report.checks;
      report.reductions += 2;
      NlgsCheckSums local;
      double        closing = 0;
      for (const Contact &c : p.contacts)
        closing = std::max(closing, local.check(c, p.state, law));
      const double sums[6]   = {local.wrwr, local.wrr, local.dvdv, local.dvdvrr, local.dvor, double(local.active)};
      const double maxima[3] = {local.max_dvdv, local.max_dvdvrr, law.type == ContactLaw::Type::iqs ? closing : 0.0};
      double       all_sums[6], all_maxima[3];
      {
        const CommunicationTime timed(report);
        dealii::Utilities::MPI::sum(sums, comm, all_sums);
        dealii::Utilities::MPI::max(maxima, comm, all_maxima);
      }
      NlgsCheckSums all;
      all.wrwr       = all_sums[0];
      all.wrr        = all_sums[1];
      all.dvdv       = all_sums[2];
      all.dvdvrr     = all_sums[3];
      all.dvor       = all_sums[4];
      all.active     = static_cast<unsigned int>(all_sums[5]);
      all.max_dvdv   = all_maxima[0];
      all.max_dvdvrr = all_maxima[1];
      report.gap_violation = theta_h * std::max(0.0, all_maxima[2]);
      const bool gaps_ok   = controls.nlgs_gap_tolerance <= 0 || report.gap_violation <= controls.nlgs_gap_tolerance;
      if (all.active == 0)
        {
          report.nlgs_residual = 0;
          return true;
        }
      const double criterion = all.criterion(controls.nlgs_norm, controls.nlgs_tolerance);
      report.nlgs_residual   = criterion * controls.nlgs_tolerance;
      return criterion < 1 && gaps_ok;
    }
  } // namespace

  DistributedReport DistributedGaussSeidel::solve(RankProblem &p, const ContactLaw &law,
                                                  const DistributedControls &controls, double theta_h)
  {
    DistributedReport report;
    report.neighbours    = exchange.neighbours();
    const unsigned n_local = static_cast<unsigned>(p.serial_body.size()), first_rep = p.n_owned + p.n_ghost;

    // Nesterov's momentum on the sweeps (APGS's, dem/solvers/apgs.h), without friction:
    // y_k the impulses a sweep leaves, z_k those the next sweep starts from.
    // The contacts that touch a grain other ranks' contacts also touch (a ghost here, or an
    // exported grain): across the ranks their sweeps are Jacobi steps, whose overshoot the
    // momentum amplifies until the solve diverges; with momentum they are relaxed.
    const bool                   momentum = controls.momentum && law.friction <= 0 && !controls.nlgs_stop;
    const double                 omega    = controls.nlgs_stop ? controls.nlgs_relaxation : 1.0;
    std::vector<Eigen::Vector2d> y_last;
    std::vector<bool>            shared(n_local, false), interface(p.contacts.size(), false);
    double                       t = 1;
    if (momentum)
      {
        for (unsigned int l = p.n_owned; l < first_rep; ++l)
          shared[l] = true;
        for (const unsigned int l : exchange.exported())
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
        exchange.remember(p.state);
        // The sweep, and with momentum the gradient restart's sum over it: no momentum when the
        // sweep's step opposes it, (z_k - y_k+1).(y_k+1 - y_k) > 0 in the scaled variables
        // (weights W_nn + c), z_k a contact's impulse before its local solve, y_k+1 after it.
        double opposing = 0;
        for (std::size_t i = 0; i < p.contacts.size(); ++i)
          {
            Contact              &c = p.contacts[i];
            const Eigen::Vector2d z = c.r;
            gauss_seidel_update(c, p.state, law, interface[i] ? controls.interface_relaxation : omega);
            if (momentum)
              opposing += (c.W(0, 0) + c.compliance) * (z - c.r).dot(c.r - y_last[i]);
          }
        report.sweeps = sweep;
        const bool check = sweep % controls.check_interval == 0 || sweep == controls.max_sweeps;
        if (check)
          {
            exchange.exchange(p.state, report);
            if (controls.nlgs_stop ? nlgs_converged(p, law, controls, theta_h, comm, report)
                                   : global_law_residual(p, law, theta_h, controls.residual_target, comm, report))
              {
                report.converged = true;
                break;
              }
            exchange.remember(p.state);
          }
        if (momentum)
          {
            ++report.reductions;
            {
              const CommunicationTime timed(report);
              opposing = dealii::Utilities::MPI::sum(opposing, comm);
            }
            if (opposing > 0)
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
          exchange.exchange(p.state, report);
      }
    return report;
  }
} // namespace tribo::dem::parallel
