#pragma once
/// @file The scenes of `tribo run` (Simulation/Scene): one table, in app/scenes.cc, of every
/// scene's name, description, parameter declarations, check and factory. The Selection of
/// Simulation/Scene, its documentation in `tribo params` and run_case()'s choice of what
/// to build all come from it; a scene whose module the build left out keeps its row, so
/// that a case naming it is refused with the build option it needs.

#include "app/driver.h"

#include <deal.II/base/parameter_handler.h>

#include <memory>
#include <string>
#include <vector>

namespace tribo
{
  class ParameterFile; // core/parameter_file.h
}

namespace tribo::app
{
  struct CaseParameters; // app/case_parameters.h

  /// What a scene of this build gives the table: its subsections, its check, its factory.
  struct SceneHooks
  {
    /// Declare the scene's subsections, each function one subsection (a subsection that
    /// scenes share, such as "MLP", is the same function in their rows and is declared
    /// once); empty: none beyond the NSCD subsections.
    std::vector<void (*)(dealii::ParameterHandler &)> declare;
    /// Reads and checks the scene's own entries without building it (InputError naming
    /// the entry), before anything is written; nullptr: it has none.
    void (*check)(const ParameterFile &) = nullptr;
    /// Builds the scene (what it built goes to the log); nullptr: not in this build.
    std::unique_ptr<Simulation> (*make)(const ParameterFile &, const CaseParameters &, Log &) = nullptr;
    /// Rewrites the entries whose meaning depends on where the case file is (a relative
    /// path, as an absolute one), so that parameters.prm means the same from any
    /// directory (a resumed run, a run started from it elsewhere); nullptr: none.
    void (*resolve)(ParameterFile &) = nullptr;
  };

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

  /// Declare the entry Scene (Selection and documentation from scenes()) in the current
  /// subsection (Simulation).
  void declare_scene_entry(dealii::ParameterHandler &prm);

  /// Declare every built scene's own subsections (each module's once).
  void declare_scene_subsections(dealii::ParameterHandler &prm);
} // namespace tribo::app
