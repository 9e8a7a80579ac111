#pragma once
/// @file The contact solve of one step across MPI ranks (dem/parallel/README.md): projected
/// Gauss-Seidel inside a rank, coupled across ranks after every sweep.
///
/// Each rank sweeps its own contacts (the NLGS local solve, gauss_seidel_update in
/// dem/solvers/nlgs.h: IQS or ELAS, cohesion, Coulomb friction) against its local bodies,
/// ghosts included. After the sweep the grains' velocity changes are exchanged
/// (GrainExchange, dem/parallel/distributed_solve.h).
/// Inside a rank this is the serial Gauss-Seidel sweep; across ranks it is a Jacobi step:
/// two contacts of different ranks on one grain both act on the velocity the last
/// exchange left. On one rank, without momentum, it is the serial NLGS sweep in detection
/// order, bit for bit.
///
/// The stopping test is the law residual (dem/laws/law_residual.h) over all ranks' contacts,
/// max |phi| over the mean loaded impulse: two reductions every check_interval sweeps; or, with
/// DistributedControls::nlgs_stop (Solver/Method = nlgs on N ranks), NLGS's own test, the
/// established code's norms over all ranks' contacts (NlgsCheckSums, dem/solvers/nlgs.h).
///
/// Without friction the sweeps carry Nesterov's momentum, as APGS's do: y_k+1 = S(z_k),
/// t_k+1 = (1 + sqrt(1 + 4 t_k^2)) / 2, z_k+1 = y_k+1 + (t_k - 1) / t_k+1 (y_k+1 - y_k), with the
/// gradient restart t_k = 1 when (z_k - y_k+1).(y_k+1 - y_k) > 0 (weighted by W_nn + c, APGS's
/// scaled variables): one more sum over the ranks per sweep. The extrapolation's velocity
/// changes travel with the sweep's in the one exchange per sweep (two on check sweeps, where
/// the residual is taken at y, before the extrapolation).

#include "dem/parallel/distributed_solve.h"

namespace tribo::dem::parallel
{
  class DistributedGaussSeidel : public DistributedSolver
  {
  public:
    using DistributedSolver::DistributedSolver;
    DistributedReport solve(RankProblem &problem, const ContactLaw &law, const DistributedControls &controls,
                            double theta_h = 0) override;
  };
} // namespace tribo::dem::parallel
