#include "dem/parallel/distributed_gauss_seidel.h"

#include "dem/solvers/nlgs.h"

#include <deal.II/base/mpi.h>

#include <cmath>

namespace tribo::dem::parallel
{
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
    const bool                   momentum = controls.momentum && law.friction <= 0;
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
            gauss_seidel_update(c, p.state, law, interface[i] ? controls.interface_relaxation : 1.0);
            if (momentum)
              opposing += (c.W(0, 0) + c.compliance) * (z - c.r).dot(c.r - y_last[i]);
          }
        report.sweeps = sweep;
        const bool check = sweep % controls.check_interval == 0 || sweep == controls.max_sweeps;
        if (check)
          {
            exchange.exchange(p.state, report);
            if (global_law_residual(p, law, theta_h, controls.residual_target, comm, report))
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
