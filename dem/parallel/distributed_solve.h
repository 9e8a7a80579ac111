#pragma once
/// @file What the distributed contact solves share (dem/parallel/README.md): their controls and
/// report, the exchange of the grains' velocities between ranks after a sweep, and the law
/// residual over all ranks.

#include "dem/laws/contact_law.h"
#include "dem/parallel/rank_problem.h"
#include "dem/solvers/contact_solver.h"

#include <mpi.h>

#include <chrono>
#include <cstdint>
#include <memory>
#include <vector>

namespace tribo::dem::parallel
{
  struct DistributedControls
  {
    double       residual_target = 1e-4;  ///< stop below this global relative law residual
    /// DistributedApgs with IQS: and with every contact's gap violation theta h max(0, -u~_n)
    /// at most this (m; 0: not checked), as the serial APGS aims at SolverParameters::gap_target.
    double       gap_target = 0;
    unsigned int max_sweeps      = 10000; ///< then stop, not converged
    unsigned int check_interval  = 10;    ///< sweeps between law-residual checks
    /// Nesterov's momentum on the sweeps with the gradient restart, as APGS (dem/solvers/apgs.h)
    /// puts it on its own: without friction in both forms; with friction in DistributedApgs
    /// only, under APGS's safeguard (the Gauss-Seidel form then sweeps plainly: the law is not
    /// associated). Off: the plain sweep.
    bool momentum = true;
    /// With momentum, the relaxation omega (r <- omega r_law + (1 - omega) r) of the contacts
    /// that touch a grain other ranks' contacts touch too. Their sweeps are Jacobi steps across
    /// the ranks, and with omega = 1 the momentum amplifies their overshoot until the solve
    /// diverges (the established code's sample on two ranks); 0.5 halves what two ranks
    /// put on one grain at once, and the sweeps are then the one-rank count (docs/scaling.md).
    double interface_relaxation = 0.5;
    /// DistributedApgs: APGS's local polish after a check that fails (dem/solvers/apgs.h),
    /// on each rank's own contacts above the target, then an exchange and the map again;
    /// polishes go on until polish_patience in a row have not lowered the map (at most
    /// max_polishes). Off: blocks of sweeps only.
    bool                          polish          = true;
    static constexpr unsigned int polish_patience = 8;
    static constexpr unsigned int max_polishes    = 256;
    /// DistributedGaussSeidel without momentum: stop as NLGS does (dem/solvers/nlgs.h), by the
    /// established code's norm @p nlgs_norm at Tolerance nlgs_tolerance over every rank's
    /// contacts (one check pass, then two reductions), and the gap violation at most
    /// nlgs_gap_tolerance (m; 0: not checked); residual_target is then unused. Every contact is
    /// relaxed by nlgs_relaxation (NLGS's Relaxation). False: the law residual stops it.
    bool                   nlgs_stop          = false;
    SolverParameters::Norm nlgs_norm          = SolverParameters::Norm::quad;
    double                 nlgs_tolerance     = 1e-4;
    double                 nlgs_gap_tolerance = 0;
    double                 nlgs_relaxation    = 1;
  };

  /// What a distributed solve achieved; the same on every rank.
  struct DistributedReport
  {
    unsigned int sweeps        = 0;
    /// With DistributedControls::nlgs_stop: NLGS's criterion times its tolerance at the last
    /// check (SolveReport::residual).
    double       nlgs_residual = 0;
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
    /// Wall time this rank spent in the exchanges and the sums over the ranks, waits for the
    /// other ranks included, s.
    double time_communication = 0;
  };

  /// Adds the wall time from its construction to its destruction to
  /// DistributedReport::time_communication: put around an exchange or a sum over the ranks.
  class CommunicationTime
  {
  public:
    explicit CommunicationTime(DistributedReport &report)
      : report(report)
      , start(std::chrono::steady_clock::now())
    {}
    ~CommunicationTime()
    {
      report.time_communication += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    CommunicationTime(const CommunicationTime &)            = delete;
    CommunicationTime &operator=(const CommunicationTime &) = delete;

  private:
    DistributedReport                    &report;
    std::chrono::steady_clock::time_point start;
  };

  /// The exchange of a RankProblem's shared bodies' velocities after local changes:
  /// - the velocity changes this rank made to ghost grains go to their owners, which add them
  ///   (ghost-to-owner sums: deal.II's LinearAlgebra::distributed::Vector::compress(add));
  /// - the owners' velocities go to the ghosts (owner-to-ghost: update_ghost_values());
  /// - the changes every rank made to the replicated bodies (the walls) are summed over the
  ///   ranks (one reduction of 3 values per replicated body).
  /// Only the exported grains' entries (owned grains that are ghosts elsewhere) are touched.
  class GrainExchange
  {
  public:
    /// The exchange pattern of @p problem's owned and ghost grains (collective on @p comm).
    GrainExchange(const RankProblem &problem, MPI_Comm comm);
    ~GrainExchange();

    /// Local numbers of the exported grains: owned here, ghosts on another rank.
    const std::vector<unsigned int> &exported() const;
    /// Ranks this one exchanges with.
    unsigned int neighbours() const;
    /// Remember @p state's velocities of the ghost and replicated bodies: local changes are
    /// counted from here.
    void remember(const BodyState &state);
    /// Collective: after local changes to @p state since remember(), exchange them (above);
    /// @p state's shared bodies then hold every rank's changes. Counts the traffic in @p report.
    void exchange(BodyState &state, DistributedReport &report);

  private:
    struct Vector;
    std::unique_ptr<Vector>      vector;
    MPI_Comm                     comm;
    unsigned int                 n_owned, n_ghost, n_local;
    std::vector<Eigen::Vector3d> before;
    std::vector<double>          wall_change, wall_sum;
    unsigned int                 peers = 0;
  };

  /// A contact solve across ranks: a rank's sweeps over its own contacts, coupled to the
  /// other ranks' through the GrainExchange of its problem.
  class DistributedSolver
  {
  public:
    /// The exchange pattern of @p problem's owned and ghost grains (collective on @p comm).
    DistributedSolver(const RankProblem &problem, MPI_Comm comm)
      : exchange(problem, comm)
      , comm(comm)
      , warm_from_others(problem.serial_body.size(), Eigen::Vector3d::Zero())
    {}
    virtual ~DistributedSolver() = default;
    /// Solve @p problem's contacts (warm-started from their impulses, put on its state by
    /// add_impulses(); a cold start needs none) under @p law; @p theta_h turns velocity violations into gap violations.
    /// Collective; every rank returns the same report, and its owned and ghost velocities
    /// agree with their owners' after the last exchange.
    virtual DistributedReport solve(RankProblem &problem, const ContactLaw &law, const DistributedControls &controls,
                                    double theta_h) = 0;
    /// Collective: from a state of free velocities on every rank, @p problem's state with
    /// every rank's contact impulses (a warm start) on it, as solve() wants: each rank puts
    /// its own contacts' impulses on its bodies, then one exchange. What that exchange
    /// brought, the other ranks' warm-start impulses' velocity changes on the shared bodies
    /// (zero on the others), is kept in warm_from_others.
    void add_impulses(RankProblem &problem, DistributedReport &report);

  protected:
    GrainExchange                exchange;
    MPI_Comm                     comm;
    std::vector<Eigen::Vector3d> warm_from_others; ///< per local body, m/s and rad/s
  };

  /// Collective: the law residual (dem/laws/law_residual.h) over every rank's contacts of
  /// @p problem, max |phi| over the mean loaded impulse, and the gap violation, into
  /// @p report (two reductions); true when below @p target.
  bool global_law_residual(const RankProblem &problem, const ContactLaw &law, double theta_h, double target,
                           MPI_Comm comm, DistributedReport &report);
} // namespace tribo::dem::parallel
