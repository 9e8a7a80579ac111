#pragma once
/// @file APGS's sweeps (dem/solvers/apgs.h) across MPI ranks (dem/parallel/README.md): each
/// rank sweeps its own contacts in APGS's operator form, coupled across ranks after every
/// sweep through the grains' velocities.
///
/// Each rank assembles the scaled problem of its own contacts (dem/solvers/sweep_problem.h:
/// y, A' + U'U'^T over the bodies they share, ghosts and walls included, b') from the
/// contacts' free velocities, b' then moved by s_j H_j^T dv_warm for the contacts on a shared
/// body: dv_warm, what every other rank's warm-start impulses put on its ghost grains, its
/// exported grains and the walls (the exchange of DistributedSolver::add_impulses), so that
/// b'_j / s_j is u_j(state) - (W_local r_warm)_j, the local velocity of contact j without this
/// rank's warm-start impulses. A sweep is
/// APGS's projected Gauss-Seidel sweep over the rank's contacts (SweepProblem::relax, the
/// walls' low-rank part kept current in place). After it, the contacts that touch a shared
/// body (a ghost, an exported grain, a wall with a free degree of freedom) put their impulse
/// changes since the last exchange on the state's velocities, the grains' velocities are
/// exchanged (GrainExchange: ghost-to-owner sums, owner-to-ghost values, the walls' changes
/// summed), and what the other ranks changed on a shared body, dv, moves b' of the contacts
/// on it by s_j H_j^T dv. Inside a rank this is APGS's sweep; across ranks a Jacobi step, as
/// in DistributedGaussSeidel: those interface contacts are relaxed by
/// DistributedControls::interface_relaxation when the momentum is on.
///
/// The sweeps carry APGS's Nesterov momentum with its gradient restart (one sum over the ranks
/// per sweep), the next sweep's start exchanged after the extrapolation. Every check_interval
/// sweeps the iterate is exchanged and its map, max_j |phi_j| (N s/m, SweepProblem::contact_map)
/// over the mean loaded impulse, is reduced over the ranks: the stopping test, as APGS's. With
/// friction (the law is not associated) APGS's safeguard: the best iterate of the checks is
/// kept and returned by a solve that ends above it, and a check that raises the map drops the
/// momentum (t = 1, the next sweep from the iterate); every rank takes the same decision from
/// the reduced map. After a check that fails, APGS's local polish on each rank's own
/// contacts above the target (and two rings of their neighbours), then an exchange and the map
/// again where it changed (DistributedControls::polish): the tail of a warm start's worst
/// contacts, which whole sweeps would chase, costs local passes. At the end every contact's
/// impulse is written, the velocities are exchanged once more, and the report's law residual
/// is the velocity form's over all ranks (global_law_residual).

#include "dem/parallel/distributed_solve.h"

namespace tribo::dem::parallel
{
  class DistributedApgs : public DistributedSolver
  {
  public:
    using DistributedSolver::DistributedSolver;
    /// The report's sweeps count APGS's sweeps; its checks include the final one in velocity form.
    DistributedReport solve(RankProblem &problem, const ContactLaw &law, const DistributedControls &controls,
                            double theta_h = 0) override;
  };
} // namespace tribo::dem::parallel
