#pragma once
/// @file The table of the contact solver methods, one row per method, and with it (methods.cc)
/// the Solver subsection's entries and make_contact_solver(). Adding a method is its files in
/// dem/solvers/, its value of SolverParameters::Method and its row in methods.cc.

#include "dem/solvers/contact_solver.h"

#include <memory>
#include <vector>

namespace tribo
{
  class ParameterFile;
}

namespace tribo::dem
{
  /// One method: its Method value, its name in the Method entry, what its
  /// SolveReport::iterations count (the run's log), its own entries (declared in the current subsection; read into the
  /// controls, after the common ones; null without), and its constructor.
  struct SolverMethod
  {
    SolverParameters::Method method;
    const char              *name;
    const char              *iterations;
    void (*declare)(dealii::ParameterHandler &prm);
    void (*parse)(const ParameterFile &file, SolverParameters &prm);
    std::unique_ptr<ContactSolver> (*make)(const SolverParameters &prm);
  };

  /// The rows, in the order the Method entry lists them.
  const std::vector<SolverMethod> &solver_methods();
  /// The row of @p method.
  const SolverMethod &solver_method(SolverParameters::Method method);
} // namespace tribo::dem
