#pragma once
/// @file The scenes of `tribo run` (Simulation/Scene): one table, in app/scenes.cc, of every
/// scene's name, description, parameter declarations, check and factory. The Selection of
/// Simulation/Scene, its documentation in `tribo params` and run_case()'s choice of what
/// to build all come from it; a scene whose module the build left out keeps its row, so
/// that a case naming it is refused with the build option it needs.

#include "app/scene_hooks.h"

#include <deal.II/base/parameter_handler.h>

#include <memory>
#include <string>
#include <vector>

namespace tribo::app
{
  struct SceneEntry
  {
    std::string name;        ///< the value of Simulation/Scene
    std::string description; ///< for Simulation/Scene's documentation
    /// The CMake option that builds the scene's module, "" for the NSCD scenes (always
    /// built).
    std::string build_option;
    SceneHooks  hooks; ///< make == nullptr: the scene is not in this build
  };

  /// Every scene of the program, built or not, in the order of Simulation/Scene's
  /// Selection.
  const std::vector<SceneEntry> &scenes();

  /// The scene @p name (a value Simulation/Scene's Selection allowed).
  const SceneEntry &scene_named(const std::string &name);

  /// Declare every entry of a case file: the common ones (app/case_parameters.h) and every
  /// built scene's own subsections (each module's once).
  void declare_case_parameters(dealii::ParameterHandler &prm);

  /// What a finished run directory says of itself (its summary.json and parameters.prm),
  /// for a case that goes on from it (Shear cell/Initial state) or exports its snapshots.
  struct RunRecord
  {
    std::string status;             ///< summary.json "status" ("" if unreadable)
    std::string scene;              ///< summary.json "scene"
    double      simulated_time = 0; ///< s, summary.json "simulated_time"
    double      length         = 0; ///< m, parameters.prm Shear cell/Length
  };
  RunRecord read_run_record(const std::string &dir);

  /// Declare every entry of a case file.
  void declare_case_parameters(dealii::ParameterHandler &prm);
} // namespace tribo::app
