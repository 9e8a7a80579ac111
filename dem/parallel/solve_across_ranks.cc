#include "dem/parallel/solve_across_ranks.h"

#include "dem/parallel/distributed_apgs.h"
#include "dem/parallel/rank_problem.h"

#include <deal.II/base/mpi.h>

namespace tribo::dem::parallel
{
  namespace
  {
    /// Every rank's @p mine concatenated in rank order, on every rank (MPI_Allgatherv).
    std::vector<double> gathered(const std::vector<double> &mine, MPI_Comm comm)
    {
      const int        size  = static_cast<int>(mine.size());
      std::vector<int> sizes = dealii::Utilities::MPI::all_gather(comm, size);
      std::vector<int> offsets(sizes.size() + 1, 0);
      for (std::size_t k = 0; k < sizes.size(); ++k)
        offsets[k + 1] = offsets[k] + sizes[k];
      std::vector<double> all(offsets.back());
      MPI_Allgatherv(mine.data(), size, MPI_DOUBLE, all.data(), sizes.data(), offsets.data(), MPI_DOUBLE, comm);
      return all;
    }
  } // namespace

  SolveAcrossRanks::SolveAcrossRanks(const SolverParameters &p, const ParticleSystem &system, MPI_Comm comm)
    : ContactSolver(p)
    , system(system)
    , comm(comm)
  {
    SolverParameters apgs = p;
    apgs.method           = SolverParameters::Method::apgs;
    whole                 = make_contact_solver(apgs);
  }

  SolveAcrossRanks::~SolveAcrossRanks() = default;

  SolveReport SolveAcrossRanks::solve(std::vector<Contact> &contacts, BodyState &state, const ContactLaw &law,
                                      double theta_h)
  {
    const unsigned int ranks = dealii::Utilities::MPI::n_mpi_processes(comm);
    if (contacts.size() < std::size_t(min_contacts_per_rank) * ranks)
      return whole->solve(contacts, state, law, theta_h);

    RankProblem problem = share_of(system, contacts, state, contact_bands(system, contacts, ranks),
                                   dealii::Utilities::MPI::this_mpi_process(comm));
    DistributedControls controls;
    controls.residual_target = prm.residual_target;
    controls.max_sweeps      = prm.max_iterations;
    const DistributedReport done = DistributedApgs(problem, comm).solve(problem, law, controls, theta_h);

    // Each owned contact's impulse and each owned grain's velocity, as records
    // (serial index, values), to every rank.
    std::vector<double> mine;
    mine.reserve(3 * problem.contacts.size());
    for (std::size_t i = 0; i < problem.contacts.size(); ++i)
      mine.insert(mine.end(), {double(problem.serial_contact[i]), problem.contacts[i].r[0], problem.contacts[i].r[1]});
    const std::vector<double> impulses = gathered(mine, comm);
    for (std::size_t k = 0; k < impulses.size(); k += 3)
      contacts[std::size_t(impulses[k])].r = {impulses[k + 1], impulses[k + 2]};

    mine.clear();
    for (unsigned int l = 0; l < problem.n_owned; ++l)
      {
        const Eigen::Vector3d &v = problem.state.velocity[l];
        mine.insert(mine.end(), {double(problem.serial_body[l]), v[0], v[1], v[2]});
      }
    const std::vector<double> velocities = gathered(mine, comm);
    for (std::size_t k = 0; k < velocities.size(); k += 4)
      state.velocity[std::size_t(velocities[k])] = {velocities[k + 1], velocities[k + 2], velocities[k + 3]};

    // The walls: the sums over the ranks may differ in their last bits from rank to rank.
    std::vector<double> walls;
    for (unsigned int l = problem.n_owned + problem.n_ghost; l < problem.serial_body.size(); ++l)
      walls.insert(walls.end(), problem.state.velocity[l].data(), problem.state.velocity[l].data() + 3);
    MPI_Bcast(walls.data(), int(walls.size()), MPI_DOUBLE, 0, comm);
    for (unsigned int l = problem.n_owned + problem.n_ghost, k = 0; l < problem.serial_body.size(); ++l, k += 3)
      state.velocity[problem.serial_body[l]] = {walls[k], walls[k + 1], walls[k + 2]};

    SolveReport report;
    report.iterations    = done.sweeps;
    report.check_passes  = done.checks;
    report.law_residual  = done.law_residual;
    report.residual      = done.law_residual;
    report.gap_violation = done.gap_violation;
    report.converged     = done.converged;
    report.concurrent    = true;
    return report;
  }
} // namespace tribo::dem::parallel
