#pragma once
/// @file Every scene's hooks, one function per scene file in app/scenes/: each gives its
/// row of the scene table (app/scenes.h, app/scenes.cc) its hooks (SceneHooks): the declaration of
/// its own subsection, the check of its entries without running it (an InputError naming
/// the entry otherwise: `tribo check`, and `tribo run` before it writes anything) and its
/// factory of the Simulation that the driver (app/driver.h) runs (what it built goes to
/// the log). run_case() has prepared the output directory, written original.prm,
/// parameters.prm and a "running" summary.json, opened the log, and for --resume checked
/// the checkpoint's parameters against the case.

#include "app/driver.h"
#include "app/scene.h"
#include "core/output.h"
#include "core/parameter_file.h"

#include <deal.II/base/parameter_handler.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace tribo::app
{
  struct CaseParameters; // app/case_parameters.h

  /// A case of a study as a scene's compaction_of() hook sees it (app/study.cc).
  struct StudyCase
  {
    std::vector<std::string> overrides; ///< "Subsection/Entry=value", over the study's base case
    std::vector<std::string> entries;   ///< the entry of each override
    /// The value of entry @p entry of the base case with the overrides @p overrides.
    std::function<std::string(const std::vector<std::string> &overrides, const std::string &entry)> value;
  };

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
    /// A study's shared compaction: the overrides of the compaction-only run that the case
    /// @p c can start from (its overrides that act before the shear, less the study's
    /// @p shear_phase entries, and the run's end), or none when it cannot start from one
    /// (a state of its own, no compaction, a body the state cannot hold). nullptr: the
    /// scene has no compaction to share.
    std::vector<std::string> (*compaction_of)(const StudyCase &c, const std::vector<std::string> &shear_phase) =
      nullptr;
  };

  SceneHooks collision_hooks(); ///< app/scenes/collision.cc, subsection "Collision"
  SceneHooks shear_hooks();     ///< app/scenes/shear.cc, subsection "Shear cell"
  /// The shear scene of the case @p p read from @p file, on its own, for the benchmarks
  /// and tests that step it without the driver.
  std::unique_ptr<Scene> make_shear_scene(const ParameterFile &file, const CaseParameters &p);
#ifdef TRIBO_WITH_SPH_SCENES
  SceneHooks sph_slider_hooks(); ///< app/scenes/sph_slider.cc, subsection "SPH slider"
  SceneHooks sph_plate_hooks();  ///< app/scenes/sph_plate.cc, subsection "SPH plate"
#endif
#ifdef TRIBO_WITH_MLP_SCENES
  // Each with the subsection "MLP" that every MLP scene reads (app/scenes/mlp_family.cc).
  SceneHooks mlp_ordering_hooks();    ///< app/scenes/mlp_ordering.cc, subsection "MLP ordering"
  SceneHooks mlp_compression_hooks(); ///< app/scenes/mlp_compression.cc, "MLP compression"
  SceneHooks mlp_beams_hooks();       ///< app/scenes/mlp_beams.cc, "MLP beams"
#endif
} // namespace tribo::app
