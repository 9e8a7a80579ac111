#pragma once
/// @file The contact solver of a case run on several MPI ranks (`mpirun -np N tribo run`):
/// each rank advances the grains of its band (MoreauJean with a BandSplit,
/// dem/parallel/band_split.h, its state split by GrainOwnership); each detects and solves only
/// the contacts of its band, by
/// DistributedApgs (dem/parallel/distributed_apgs.h) or, for Solver/Method = nlgs, by
/// DistributedGaussSeidel's plain sweeps stopped by NLGS's own test.

#include "dem/engine/particle_system.h"
#include "dem/parallel/band_split.h"
#include "dem/solvers/contact_solver.h"

#include <memory>

namespace tribo::dem::parallel
{
  /// A ContactSolver for MoreauJean::use_solver on each rank, beside MoreauJean::use_split(@p
  /// split). A step held in shares (BandSplit::holds_share()): the contacts given are this
  /// rank's, the state's velocities the free ones;
  /// - its RankProblem (share_of under the split's bands), every rank's warm-start impulses
  ///   put on it (DistributedSolver::add_impulses), and DistributedApgs's sweeps, stopped at
  ///   SolverParameters::residual_target of the law residual over all ranks, or after
  ///   max_iterations sweeps (with Method = nlgs: Gauss-Seidel sweeps inside each rank,
  ///   relaxed by Relaxation, stopped by the established code's Norm at Tolerance over all
  ///   ranks and by the Gap tolerance, checked every Check interval sweeps);
  /// - the contacts' impulses are written back; the bodies' velocities are not: MoreauJean
  ///   takes them from the contact forces summed over the ranks. The top band's rank, which
  ///   holds the half-disc contacts, writes the deformable bodies' node velocities. Every rank
  ///   updates such a body itself, so a step starts by checking that the ranks' node
  ///   velocities agree bit for bit (RunError naming the cause otherwise).
  /// The report's law residual is over every rank's contacts (SolveReport::law_assessed).
  /// A step held whole (too few contacts) is solved whole by the method (APGS or NLGS) on
  /// every rank, the same bits everywhere.
  class SolveAcrossRanks : public ContactSolver
  {
  public:
    /// @p system must outlive the solver; every rank of the split's communicator constructs one.
    SolveAcrossRanks(const SolverParameters &p, const ParticleSystem &system, std::shared_ptr<const BandSplit> split);
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

    const ParticleSystem            &system;
    std::shared_ptr<const BandSplit> split;
    MPI_Comm                         comm;
    std::unique_ptr<ContactSolver>   whole; ///< the method whole, for the steps with few contacts
  };
} // namespace tribo::dem::parallel
