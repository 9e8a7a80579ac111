#pragma once
/// @file The global methods (active set, MPRGP, APGD, APGS, interior point): what they share
/// around their own solve of the step's problem. solve() runs, in order:
/// - with Coulomb friction and a method that does not solve it (solves_friction()): NLGS
///   with the same controls solves the step instead (SolveReport::solved_by_nlgs);
/// - SolverParameters::predictor_sweeps NLGS sweeps, counted in the report's iterations;
/// - the method's solve_problem();
/// - if that is not converged and the method falls back (the active set): NLGS from where
///   the method left the impulses (SolveReport::fell_back).

#include "dem/solvers/nlgs.h"

namespace tribo::dem
{
  class GlobalSolver : public ContactSolver
  {
  public:
    explicit GlobalSolver(const SolverParameters &p);
    SolveReport solve(std::vector<Contact> &contacts, BodyState &state, const ContactLaw &law,
                      double theta_h = 0) final;
    /// The random state of the NLGS that solves the frictional steps or the fallbacks.
    std::string random_state() const final { return nlgs.random_state(); }
    void        set_random_state(const std::string &state) final { nlgs.set_random_state(state); }

    bool solves_friction() const override { return false; }

  protected:
    /// Whether a step the method does not converge is then solved by NLGS (the active set).
    virtual bool falls_back_to_nlgs() const { return false; }
    /// Solve the problem of @p contacts (not empty) under @p law. What the report counts:
    /// each method says.
    virtual SolveReport solve_problem(std::vector<Contact> &contacts, BodyState &state,
                                      const ContactLaw &law) = 0;
    /// theta h of the step being solved (s): a closing velocity times it is a gap violation (m).
    double step_theta_h = 0;

  private:
    NlgsSolver nlgs;      ///< the frictional steps and the fallbacks
    NlgsSolver predictor; ///< SolverParameters::predictor_sweeps sweeps, no convergence test
  };
} // namespace tribo::dem
