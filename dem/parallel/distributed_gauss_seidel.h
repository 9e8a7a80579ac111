#pragma once
/// @file The contact solve of one step across MPI ranks (dem/parallel/README.md): projected
/// Gauss-Seidel inside a rank, coupled across ranks after every sweep.
///
/// Each rank sweeps its own contacts (the NLGS local solve, gauss_seidel_update in
/// dem/solvers/nlgs.h: IQS or ELAS, cohesion, Coulomb friction) against its local bodies,
/// ghosts included. After the sweep:
/// - the velocity changes it made to ghost grains go to their owners, which add them
///   (ghost-to-owner sums: deal.II's LinearAlgebra::distributed::Vector::compress(add));
/// - the changes every rank made to the replicated bodies (the walls) are summed over the
///   ranks (one reduction of 3 values per replicated body);
/// - the owners' velocities go to the ghosts (owner-to-ghost: update_ghost_values()).
/// Inside a rank this is the serial Gauss-Seidel sweep; across ranks it is a Jacobi step:
/// two contacts of different ranks on one grain both act on the velocity the last
/// exchange left. On one rank, without momentum, it is the serial NLGS sweep in detection
/// order, bit for bit.
///
/// The stopping test is the law residual (dem/laws/law_residual.h) over all ranks' contacts,
/// max |phi| over the mean loaded impulse: two reductions every check_interval sweeps.
///
/// Without friction the sweeps carry Nesterov's momentum, as APGS's do: y_k+1 = S(z_k),
/// t_k+1 = (1 + sqrt(1 + 4 t_k^2)) / 2, z_k+1 = y_k+1 + (t_k - 1) / t_k+1 (y_k+1 - y_k), with the
/// gradient restart t_k = 1 when (z_k - y_k+1).(y_k+1 - y_k) > 0 (weighted by W_nn + c, APGS's
/// scaled variables): one more sum over the ranks per sweep. The extrapolation's velocity
/// changes travel with the sweep's in the one exchange per sweep (two on check sweeps, where
/// the residual is taken at y, before the extrapolation).

#include "dem/laws/contact_law.h"
#include "dem/parallel/rank_problem.h"

#include <mpi.h>

#include <cstdint>
#include <memory>

namespace tribo::dem::parallel
{
  struct DistributedControls
  {
    double       residual_target = 1e-4;  ///< stop below this global relative law residual
    unsigned int max_sweeps      = 10000; ///< then stop, not converged
    unsigned int check_interval  = 10;    ///< sweeps between law-residual checks
    /// Nesterov's momentum on the sweeps with the gradient restart, as APGS (dem/solvers/apgs.h)
    /// puts it on its own: on the frictionless law only (with friction the law is not
    /// associated and plain sweeps are used). Off: the plain NLGS sweep.
    bool momentum = true;
    /// With momentum, the relaxation omega (r <- omega r_law + (1 - omega) r) of the contacts
    /// that touch a grain other ranks' contacts touch too. Their sweeps are Jacobi steps across
    /// the ranks, and with omega = 1 the momentum amplifies their overshoot until the solve
    /// diverges (the established code's sample on two ranks); 0.5 halves what two ranks
    /// put on one grain at once, and the sweeps are then the one-rank count (docs/scaling.md).
    double interface_relaxation = 0.5;
  };

  /// What a distributed solve achieved; the same on every rank.
  struct DistributedReport
  {
    unsigned int sweeps        = 0;
    unsigned int checks        = 0;
    double       law_residual  = 0; ///< over every rank's contacts at the last check
    double       gap_violation = 0; ///< theta h max(0, -(u_n + b)) over every IQS contact, m
    bool         converged     = false;
    /// This rank's traffic over the solve: exchanges (each two messages to every neighbour,
    /// ghost-to-owner and owner-to-ghost), the bytes it sent in them, and the sums over all
    /// ranks it took part in (the walls', the momentum's restart, the stopping test's).
    unsigned int  exchanges  = 0;
    std::uint64_t bytes_sent = 0;
    unsigned int  reductions = 0;
    unsigned int  neighbours = 0; ///< ranks it exchanges with
  };

  class DistributedGaussSeidel
  {
  public:
    /// The exchange pattern of @p problem's owned and ghost grains (collective on @p comm).
    DistributedGaussSeidel(const RankProblem &problem, MPI_Comm comm);
    ~DistributedGaussSeidel();
    /// Solve @p problem's contacts (warm-started from their impulses, whose effect must be
    /// in its state) under @p law; @p theta_h turns velocity violations into gap violations.
    /// Collective; every rank returns the same report, and its owned and ghost velocities
    /// agree with their owners' after the last exchange.
    DistributedReport solve(RankProblem &problem, const ContactLaw &law, const DistributedControls &controls,
                            double theta_h = 0);

  private:
    struct Exchange;
    std::unique_ptr<Exchange> exchange;
    MPI_Comm                  comm;
  };
} // namespace tribo::dem::parallel
