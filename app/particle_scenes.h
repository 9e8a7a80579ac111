#pragma once
/// @file Scenes of the explicit particle modules (sph/, mlp/), built as a Simulation that
/// the driver (app/driver.h) runs like the NSCD scenes. run_case() has prepared the
/// output directory, written original.prm, parameters.prm and a "running" summary.json,
/// opened the log, and for --resume checked the checkpoint's parameters against the case.

#include "app/driver.h"
#include "app/run.h"
#include "core/output.h"
#include "core/parameter_file.h"

#include <deal.II/base/parameter_handler.h>

#include <memory>
#include <string>

namespace tribo::app
{
#ifdef TRIBO_WITH_SPH_SCENES
  /// Declare the subsections of the SPH scenes (app/scene_sph_slider.cc).
  void declare_sph_scene_parameters(dealii::ParameterHandler &prm);
  /// Read and check an SPH scene's entries without running it (an InputError naming the
  /// entry otherwise): `tribo check`, and `tribo run` before it writes anything.
  void check_sph_scene(const ParameterFile &file);
  /// The SPH scene of the case @p file, built (what it built goes to @p log).
  std::unique_ptr<Simulation> make_sph_simulation(const ParameterFile &file, Log &log);
#endif

#ifdef TRIBO_WITH_MLP_SCENES
  /// Declare the subsections of the MLP scenes (app/scene_mlp.cc).
  void declare_mlp_scene_parameters(dealii::ParameterHandler &prm);
  /// Read and check an MLP scene's entries and its time step without running it (an
  /// InputError naming the entry otherwise): `tribo check`, and `tribo run` before it
  /// writes anything.
  void check_mlp_scene(const ParameterFile &file);
  /// The MLP scene of the case @p file, built (what it built goes to @p log).
  std::unique_ptr<Simulation> make_mlp_simulation(const ParameterFile &file, Log &log);
#endif
} // namespace tribo::app
