#pragma once
/// @file Every scene's hooks, one function per scene file in app/scenes/: each gives its
/// row of the scene table (app/scenes.cc) its hooks (app/scenes.h): the declaration of
/// its own subsection, the check of its entries without running it (an InputError naming
/// the entry otherwise: `tribo check`, and `tribo run` before it writes anything) and its
/// factory of the Simulation that the driver (app/driver.h) runs (what it built goes to
/// the log). run_case() has prepared the output directory, written original.prm,
/// parameters.prm and a "running" summary.json, opened the log, and for --resume checked
/// the checkpoint's parameters against the case.

#include "app/scene.h"
#include "app/scenes.h"
#include "core/output.h"
#include "core/parameter_file.h"

#include <memory>

namespace tribo::app
{
  struct CaseParameters; // app/case_parameters.h

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
