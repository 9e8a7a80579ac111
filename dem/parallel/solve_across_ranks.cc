#include "dem/parallel/solve_across_ranks.h"

#include "dem/parallel/all_gather.h"
#include "dem/parallel/distributed_apgs.h"
#include "dem/parallel/distributed_gauss_seidel.h"
#include "dem/parallel/rank_problem.h"

#include "core/errors.h"

#include <deal.II/base/mpi.h>

#include <chrono>
#include <cstdint>

namespace tribo::dem::parallel
{
  namespace
  {
    /// A contact's impulse from its owner (its serial index, N s/m).
    struct ImpulseRecord
    {
      std::uint32_t contact;
      double        r[2];
    };
    /// A grain's velocity from its owner (its serial body index; m/s and rad/s).
    struct VelocityRecord
    {
      std::uint32_t body;
      double        v[3];
    };
  } // namespace

  SolveAcrossRanks::SolveAcrossRanks(const SolverParameters &p, const ParticleSystem &system, MPI_Comm comm)
    : ContactSolver(p)
    , system(system)
    , comm(comm)
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
    const unsigned int ranks = dealii::Utilities::MPI::n_mpi_processes(comm);
    check_same_nodes(state);
    if (contacts.size() < std::size_t(min_contacts_per_rank) * ranks)
      return whole->solve(contacts, state, law, theta_h);

    const auto                since   = [](const auto &start) {
      return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    };
    auto                      start   = std::chrono::steady_clock::now();
    const std::vector<double> heights = contact_heights(system, contacts);
    RankProblem problem = share_of(system, contacts, heights, state, BandPartition::balanced(heights, ranks),
                                   dealii::Utilities::MPI::this_mpi_process(comm));
    const bool                       nlgs = prm.method == SolverParameters::Method::nlgs;
    std::unique_ptr<DistributedSolver> sweeps;
    if (nlgs)
      sweeps = std::make_unique<DistributedGaussSeidel>(problem, comm);
    else
      sweeps = std::make_unique<DistributedApgs>(problem, comm);
    const double        divide = since(start);
    DistributedControls controls;
    controls.residual_target = prm.residual_target;
    controls.max_sweeps      = prm.max_iterations;
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
    const DistributedReport done = sweeps->solve(problem, law, controls, theta_h);
    start                        = std::chrono::steady_clock::now();

    // Each owned contact's impulse and each owned grain's velocity, to every rank.
    std::vector<ImpulseRecord> impulses(problem.contacts.size());
    for (std::size_t i = 0; i < impulses.size(); ++i)
      impulses[i] = {problem.serial_contact[i], {problem.contacts[i].r[0], problem.contacts[i].r[1]}};
    for (const ImpulseRecord &record : all_gathered(impulses, comm))
      contacts[record.contact].r = {record.r[0], record.r[1]};

    std::vector<VelocityRecord> velocities(problem.n_owned);
    for (unsigned int l = 0; l < problem.n_owned; ++l)
      {
        const Eigen::Vector3d &v = problem.state.velocity[l];
        velocities[l]            = {problem.serial_body[l], {v[0], v[1], v[2]}};
      }
    for (const VelocityRecord &record : all_gathered(velocities, comm))
      state.velocity[record.body] = {record.v[0], record.v[1], record.v[2]};

    // The walls: the sums over the ranks may differ in their last bits from rank to rank.
    std::vector<double> walls;
    for (unsigned int l = problem.n_owned + problem.n_ghost; l < problem.serial_body.size(); ++l)
      walls.insert(walls.end(), problem.state.velocity[l].data(), problem.state.velocity[l].data() + 3);
    MPI_Bcast(walls.data(), int(walls.size()), MPI_DOUBLE, 0, comm);
    for (unsigned int l = problem.n_owned + problem.n_ghost, k = 0; l < problem.serial_body.size(); ++l, k += 3)
      state.velocity[problem.serial_body[l]] = {walls[k], walls[k + 1], walls[k + 2]};

    // The boundary bodies' nodes: the top band's rank moved them.
    if (state.node_velocity.size() > 0)
      {
        if (dealii::Utilities::MPI::this_mpi_process(comm) == ranks - 1)
          state.node_velocity = problem.state.node_velocity;
        MPI_Bcast(state.node_velocity.data(), int(state.node_velocity.size()), MPI_DOUBLE, int(ranks - 1), comm);
      }

    SolveReport report;
    report.time_exchange = divide + done.time_communication + since(start);
    report.iterations    = done.sweeps;
    report.check_passes  = done.checks;
    report.law_residual   = done.law_residual;
    // APGS's sweeps end with the law residual over all ranks of the answer they return
    // (DistributedApgs); NLGS's stop by NLGS's own norm.
    report.law_assessed   = !nlgs;
    report.residual       = nlgs ? done.nlgs_residual : done.law_residual;
    report.solved_by_nlgs = nlgs;
    report.gap_violation = done.gap_violation;
    report.converged     = done.converged;
    report.concurrent    = true;
    return report;
  }
} // namespace tribo::dem::parallel
