#pragma once
/// @file Scenes of the explicit particle modules (sph/, mlp/), one file each in
/// app/scenes/, built as a Simulation that the driver (app/driver.h) runs like the NSCD
/// scenes. Each scene file gives its row of the scene table (app/scenes.cc) its hooks
/// (app/scenes.h): the declaration of its own subsection, the check of its entries
/// without running it (an InputError naming the entry otherwise: `tribo check`, and
/// `tribo run` before it writes anything) and its factory (what it built goes to the
/// log). run_case() has prepared the output directory, written original.prm,
/// parameters.prm and a "running" summary.json, opened the log, and for --resume checked
/// the checkpoint's parameters against the case.

#include "app/scenes.h"
#include "core/output.h"
#include "core/parameter_file.h"

#include <memory>

namespace tribo::app
{
  struct CaseParameters; // app/case_parameters.h

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
