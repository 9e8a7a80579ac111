#pragma once
/// @file The scenes of rigid discs (collision, shear): an app::Scene stepped by the
/// Moreau-Jean integrator, as the driver (app/driver.h) runs it.

#include "app/case_parameters.h"
#include "app/driver.h"
#include "app/scene.h"

#include <memory>

namespace tribo::app
{
  /// The NSCD simulation of @p scene in the case @p p (its Simulation, Contact law, Solver
  /// and Output): builds the scene's bodies and the integrator, and logs what was built
  /// and what it cost.
  std::unique_ptr<Simulation> make_nscd_simulation(const CaseParameters &p, std::unique_ptr<Scene> scene, Log &log);
} // namespace tribo::app
