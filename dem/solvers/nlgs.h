#pragma once
/// @file Nonlinear Gauss-Seidel on the Delassus operator, in the
/// "exchange local/global" form: body velocities are kept up to date and each
/// local solve reads its contact's velocity from them (no off-diagonal W stored).
///
/// Convergence is checked every `check_interval` sweeps with the norms of the
/// established NSCD code (LMGC90, see ../shared/notes/nscd-reference.md), in a check
/// pass that solves every contact's local problem against the current state and applies
/// nothing, over the N contacts with a non-zero mean impulse, with W the contact's own
/// 2x2 Delassus block, r its impulse and r_after the check's solution:
/// dV = W (r_after - r), the change of velocity the contact still wants (m/s),
/// r_bar = (r + r_after)/2, WR = W r (m/s), WRR = (W r.r before + after)/2.
/// (dV is neither the change of u since the previous sweep, blind to a closed IQS
/// contact whose impulse still moves, nor a sweep's own change, which carries what the
/// contacts before it in the sweep just did: docs/laws.md.)
/// - QuadWR = sqrt(sum (|WR_before|^2 + |WR_after|^2)/2 / N), MeanWRR = sum WRR / N;
/// - QuadDV = sqrt(sum |dV|^2 / N) / (QuadWR tol), MaxmDV with max |dV|^2;
/// - QuadDVR = sqrt(sum |dV|^2 |r_bar|^2 / N) / (MeanWRR tol), MaxmDVR with the max;
/// - MeanDVoR = sum r_bar.dV / (sum WRR tol).
/// "Quad" has converged when |MeanDVoR|, QuadDV and QuadDVR are all below 1,
/// "Maxm" when |MeanDVoR|, MaxmDV and MaxmDVR are.

#include "dem/solvers/contact_solver.h"

#include <random>
#include <string>
#include <vector>

namespace tribo::dem
{
  /// One local solve of the Gauss-Seidel sweep: contact @p c's impulse from its law against
  /// the current velocities of @p state (u_other = u - W r), relaxed, r <- omega r_law +
  /// (1 - omega) r, and its change applied to @p state (v += M^-1 H dr).
  inline void gauss_seidel_update(Contact &c, BodyState &state, const ContactLaw &law, double omega)
  {
    const Eigen::Vector2d   u_other = state.local_velocity(c) - c.W * c.r;
    const ContactLaw::Terms terms{c.cohesion_impulse, c.shift, c.compliance};
    Eigen::Vector2d         r_new = law.solve(c.W, u_other, terms);
    if (omega != 1.0)
      r_new = omega * r_new + (1 - omega) * c.r;
    const Eigen::Vector2d dr = r_new - c.r;
    if (dr.x() != 0 || dr.y() != 0)
      state.apply_impulse(c, dr);
    c.r = r_new;
  }

  /// The established code's convergence sums over one check pass (the file comment's norms),
  /// fed with each contact's impulse before and after its local solve; merged over the bands
  /// of a sweep, or summed over MPI ranks (dem/parallel/distributed_gauss_seidel.h).
  struct NlgsCheckSums
  {
    double       wrwr = 0, wrr = 0, dvdv = 0, dvdvrr = 0, dvor = 0;
    double       max_dvdv = 0, max_dvdvrr = 0;
    unsigned int active = 0; ///< contacts with a non-zero mean impulse

    void add(const Eigen::Matrix2d &W, const Eigen::Vector2d &r_old, const Eigen::Vector2d &r_new);
    /// Contact @p c's check: its local solve against @p state, nothing applied, added; returns
    /// its closing rate -(u_n + b) (m/s; the gap violation's, for IQS).
    double check(const Contact &c, const BodyState &state, const ContactLaw &law);
    void   merge(const NlgsCheckSums &o);
    /// max(|MeanDVoR|, QuadDV, QuadDVR) (or the Maxm ones), relative to @p tol: below 1 is
    /// converged.
    double criterion(SolverParameters::Norm norm, double tol) const;
  };

  /// The solver; it keeps its random generator across steps (reproducible from the seed).
  class NlgsSolver : public ContactSolver
  {
  public:
    explicit NlgsSolver(const SolverParameters &p);
    /// @p theta_h turns velocity violations into gap violations for
    /// SolverParameters::gap_tolerance. The report is solved_by_nlgs.
    SolveReport solve(std::vector<Contact> &contacts, BodyState &state, const ContactLaw &law,
                      double theta_h = 0) override;
    bool        solves_friction() const override { return true; }
    std::string random_state() const override;
    void        set_random_state(const std::string &state) override;

    /// NLGS's own entries (Tolerance, Norm, Relaxation, Check interval, Contact order, Seed,
    /// Streams, Gap tolerance), declared in the current subsection, and read into @p prm
    /// (whose common entries are already read).
    static void declare(dealii::ParameterHandler &prm);
    static void parse(const ParameterFile &file, SolverParameters &prm);

  private:
    std::mt19937              rng;
    std::vector<unsigned int> order;
  };
} // namespace tribo::dem
