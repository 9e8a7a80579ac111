#pragma once
/// @file The contact solver of a case run on several MPI ranks (`mpirun -np N tribo run`):
/// every rank holds the whole particle system and detects and updates it whole; the
/// contact solve of each step is split into horizontal bands, one per rank, and solved by
/// DistributedApgs (dem/parallel/distributed_apgs.h) or, for Solver/Method = nlgs, by
/// DistributedGaussSeidel's plain sweeps stopped by NLGS's own test; its result is then
/// gathered, so that every rank goes on with the same impulses and velocities.

#include "dem/engine/particle_system.h"
#include "dem/solvers/contact_solver.h"

#include <mpi.h>

namespace tribo::dem::parallel
{
  /// A ContactSolver for MoreauJean::use_solver on each rank of @p comm. A step's solve:
  /// - bands of equal contact counts over the step's contacts (contact_bands), this rank's
  ///   share of them (share_of) and DistributedApgs's sweeps, stopped at
  ///   SolverParameters::residual_target of the law residual over all ranks, or after
  ///   max_iterations sweeps (with Method = nlgs: Gauss-Seidel sweeps inside each rank,
  ///   relaxed by Relaxation, stopped by the established code's Norm at Tolerance over all
  ///   ranks and by the Gap tolerance, checked every Check interval sweeps);
  /// - then every contact's impulse r (from its owner) and every grain's velocity (from its
  ///   owner) gathered on every rank (MPI_Allgatherv), and the walls' velocities taken from
  ///   rank 0, so that the ranks' states stay identical bit for bit: each then detects the
  ///   same contacts in the next step.
  ///   With deformable first bodies (half-disc contacts, all solved by the top band's rank),
  ///   their nodes' velocities come from that rank. Every rank updates such a body itself,
  ///   so a step starts by checking that the ranks' node velocities agree bit for bit
  ///   (RunError naming the step's cause otherwise).
  /// With fewer than min_contacts_per_rank contacts per rank the step is solved whole by
  /// the method (APGS or NLGS) on every rank (the same bits everywhere).
  ///
  /// Memory and the detection and update are not divided by the ranks (docs/scaling.md).
  class SolveAcrossRanks : public ContactSolver
  {
  public:
    static constexpr unsigned int min_contacts_per_rank = 64;

    /// @p system must outlive the solver; every rank of @p comm constructs one.
    SolveAcrossRanks(const SolverParameters &p, const ParticleSystem &system, MPI_Comm comm);
    ~SolveAcrossRanks() override;

    /// Collective on the communicator. iterations counts the sweeps, check_passes the checks.
    SolveReport solve(std::vector<Contact> &contacts, BodyState &state, const ContactLaw &law,
                      double theta_h = 0) override;
    bool        solves_friction() const override { return true; }
    std::string random_state() const override { return ""; }
    void        set_random_state(const std::string &) override {}

  private:
    /// RunError unless @p state's boundary node velocities are the same bits on every rank.
    void check_same_nodes(const BodyState &state) const;

    const ParticleSystem          &system;
    MPI_Comm                       comm;
    std::unique_ptr<ContactSolver> whole; ///< the method whole, for the steps with few contacts
  };
} // namespace tribo::dem::parallel
