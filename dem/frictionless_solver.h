#pragma once
/// @file The interface of the global methods on the frictionless contact problem
/// (dem/frictionless_problem.h): the active set (dem/active_set.h), MPRGP (dem/mprgp.h)
/// and the interior point (dem/interior_point.h), chosen by SolverParameters::method.

#include "dem/contact.h"
#include "dem/contact_law.h"
#include "dem/nlgs.h"

#include <vector>

namespace tribo::dem
{
  class FrictionlessSolver
  {
  public:
    explicit FrictionlessSolver(const SolverParameters &p = {}) : prm(p) {}
    virtual ~FrictionlessSolver() = default;
    /// Solve the contact problem of @p contacts (warm-started from their r, whose
    /// effect must already be in @p state), updating their impulses and @p state: an
    /// empty report without contacts, else solve_problem(). Throws RunError naming the
    /// method if @p law has friction and the method does not solve it
    /// (solves_friction()). What the report counts: each method says.
    SolveReport solve(std::vector<Contact> &contacts, BodyState &state, const ContactLaw &law);

  protected:
    /// The method's name in messages ("MPRGP").
    virtual const char *name() const = 0;
    /// Whether the method solves the law with Coulomb friction (APGS) or only without.
    virtual bool solves_friction() const { return false; }
    /// Solve the problem of @p contacts (not empty) under @p law.
    virtual SolveReport solve_problem(std::vector<Contact> &contacts, BodyState &state,
                                      const ContactLaw &law) = 0;

    SolverParameters prm;
  };
} // namespace tribo::dem
