#pragma once
/// @file The primal-dual active-set method (a semismooth Newton method) for the
/// frictionless contact problem, on the sparse Delassus operator (dem/delassus.h).
///
/// With x = r~ = r_n + gamma h the shifted normal impulses (N s/m) and
///     w = A x + b,  A = W_nn + C,  b = u_free,n + shift - W_nn (gamma h)
/// the law's normal velocities (C the ELAS compliances, 0 for IQS; shift the law's gap
/// term, dem/contact_law.h), both laws are the linear complementarity problem
///     0 <= x  _|_  w >= 0.
/// Given an active set S (contacts that carry load), one Newton step sets x_I = 0 on the
/// others and solves A_SS x_S = -b_S; the next set takes the loaded contacts of S whose
/// impulse stayed >= 0 and the contacts of I whose velocity turned < 0 (the block
/// principal pivoting of Judice and Pires 1994, the semismooth Newton step on the natural
/// map min(x, w) with unit scaling). It stops when no contact is infeasible: the
/// solution is then exact up to the factorisation's round-off and the regularisation.
///
/// Globalisation: while the number of infeasible contacts keeps decreasing, all of
/// them change side at once; after three iterations without a new minimum only the last
/// infeasible contact in the order changes side (Murty's rule), which terminates for a
/// positive definite A. After SolverParameters::max_factorizations it gives up and leaves
/// the warm start untouched (the caller then solves with NLGS).
///
/// Regularisation: redundant contacts (a hyperstatic packing, more loaded contacts than
/// the bodies' degrees of freedom can distinguish) make A_SS singular; A_SS + delta
/// diag(A_SS) is factorised, which leaves loaded contacts a gap rate of -delta A_ii x_i
/// (docs/laws.md measures its effect).
///
/// Warm start: the previous step's impulses give x_0 and S_0 = {x_0 - w_0 / A_ii > 0}.
/// Cost per step: one assembly, one symbolic analysis (CHOLMOD, on the pattern of all
/// detected contacts; the inactive ones are decoupled in the values, so the pattern
/// holds within the step), then one numeric factorisation per Newton iteration.

#include "dem/contact.h"
#include "dem/contact_law.h"
#include "dem/nlgs.h"

#include <vector>

namespace tribo::dem
{
  class ActiveSetSolver
  {
  public:
    explicit ActiveSetSolver(const SolverParameters &p = {});
    /// Solve the frictionless problem of @p contacts (warm-started from their r, whose
    /// effect must already be in @p state), updating their impulses and @p state.
    /// Throws RunError if @p law has friction. The report counts factorizations; it is
    /// converged when no contact is infeasible.
    SolveReport solve(std::vector<Contact> &contacts, BodyState &state, const ContactLaw &law);

  private:
    SolverParameters prm;
  };
} // namespace tribo::dem
