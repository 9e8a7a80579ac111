#include "dem/parallel/solve_across_ranks.h"

#include "dem/parallel/distributed_apgs.h"
#include "dem/parallel/distributed_gauss_seidel.h"
#include "dem/parallel/rank_problem.h"

#include "core/errors.h"

#include <deal.II/base/mpi.h>

#include <chrono>
#include <cstdint>

namespace tribo::dem::parallel
{
  SolveAcrossRanks::SolveAcrossRanks(const SolverParameters &p, const ParticleSystem &system,
                                     std::shared_ptr<const BandSplit> split)
    : ContactSolver(p)
    , system(system)
    , split(std::move(split))
    , comm(this->split->communicator())
  {
    whole = make_contact_solver(p);
  }

  SolveAcrossRanks::~SolveAcrossRanks() = default;

  void SolveAcrossRanks::check_same_nodes(const BodyState &state) const
  {
    if (state.node_velocity.size() == 0)
      return;
    // FNV-1a over the bytes of the node velocities: the least and the largest over the ranks.
    std::uint64_t hash  = 1469598103934665603ULL;
    const auto   *bytes = reinterpret_cast<const unsigned char *>(state.node_velocity.data());
    for (std::size_t k = 0; k < sizeof(double) * std::size_t(state.node_velocity.size()); ++k)
      hash = (hash ^ bytes[k]) * 1099511628211ULL;
    std::uint64_t least = 0, largest = 0;
    MPI_Allreduce(&hash, &least, 1, MPI_UINT64_T, MPI_MIN, comm);
    MPI_Allreduce(&hash, &largest, 1, MPI_UINT64_T, MPI_MAX, comm);
    if (least != largest)
      throw RunError("the deformable first body's node velocities differ between the MPI ranks at the start of "
                     "a contact solve: its update did not repeat bit for bit on every rank (docs/scaling.md); run "
                     "the case without mpirun");
  }

  SolveReport SolveAcrossRanks::solve(std::vector<Contact> &contacts, BodyState &state, const ContactLaw &law,
                                      double theta_h)
  {
    check_same_nodes(state);
    if (!split->holds_share())
      return whole->solve(contacts, state, law, theta_h);

    const auto                         start   = std::chrono::steady_clock::now();
    const unsigned int                 rank    = dealii::Utilities::MPI::this_mpi_process(comm);
    RankProblem                        problem =
      own_share(system, contacts, state, split->bands(), rank, split->grain_ownership());
    const bool                         nlgs    = prm.method == SolverParameters::Method::nlgs;
    std::unique_ptr<DistributedSolver> sweeps;
    if (nlgs)
      sweeps = std::make_unique<DistributedGaussSeidel>(problem, comm);
    else
      sweeps = std::make_unique<DistributedApgs>(problem, comm);
    DistributedReport warm;
    sweeps->add_impulses(problem, warm);
    const double set_up = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    DistributedControls controls;
    controls.residual_target = prm.residual_target;
    controls.max_sweeps      = prm.max_iterations;
    controls.gap_target      = prm.apgs_gap_stop();
    if (nlgs)
      {
        controls.momentum           = false;
        controls.nlgs_stop          = true;
        controls.check_interval     = prm.check_interval;
        controls.nlgs_norm          = prm.norm;
        controls.nlgs_tolerance     = prm.tolerance;
        controls.nlgs_gap_tolerance = prm.gap_tolerance;
        controls.nlgs_relaxation    = prm.relaxation;
      }
    DistributedReport done = sweeps->solve(problem, law, controls, theta_h);
    // NLGS stops by its own norm: the law residual of its answer over all ranks.
    if (nlgs)
      global_law_residual(problem, law, theta_h, prm.residual_target, comm, done);

    give_back(problem, contacts);
    if (state.node_velocity.size() > 0 && split->keeps_boundary_contacts())
      state.node_velocity = problem.state.node_velocity;

    SolveReport report;
    report.time_exchange  = set_up + done.time_communication;
    report.iterations     = done.sweeps;
    report.check_passes   = done.checks;
    report.law_residual   = done.law_residual;
    report.law_assessed   = true;
    report.residual       = nlgs ? done.nlgs_residual : done.law_residual;
    report.solved_by_nlgs = nlgs;
    report.gap_violation  = done.gap_violation;
    report.converged      = done.converged;
    report.concurrent     = true;
    return report;
  }
} // namespace tribo::dem::parallel
