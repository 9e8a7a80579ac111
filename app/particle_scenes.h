#pragma once
/// @file Scenes of the explicit particle modules (sph/, mlp/). They do not use the NSCD
/// time loop of run_case(): each runs its own loop and writes the same kind of outputs
/// (statistics.csv, summary.json, results.h5, fields/ with a .pvd index, log.txt).
/// run_case() has prepared the output directory, written original.prm, parameters.prm
/// and a "running" summary.json, opened the log, and for --resume checked the checkpoint's
/// parameters against the case, before it hands over. Each loop writes its checkpoints and
/// resumes from one through the RunCheckpoint it is given (app/run.h), as run_case() does.

#include "app/run.h"
#include "core/output.h"
#include "core/parameter_file.h"

#include <deal.II/base/parameter_handler.h>

#include <string>

namespace tribo::app
{
  /// Scene names of the SPH module (Simulation/Scene).
  bool is_sph_scene(const std::string &scene);
  /// Scene names of the MLP module.
  bool is_mlp_scene(const std::string &scene);

#ifdef TRIBO_WITH_SPH_SCENES
  /// Declare the subsections of the SPH scenes (app/scene_sph_slider.cc).
  void declare_sph_scene_parameters(dealii::ParameterHandler &prm);
  /// Read and check an SPH scene's entries without running it (an InputError naming the
  /// entry otherwise): `tribo check`, and `tribo run` before it writes anything.
  void check_sph_scene(const ParameterFile &file);
  /// Run an SPH scene into @p dir; returns the exit code (as run_case()).
  int run_sph_scene(const ParameterFile &file, const std::string &dir, Log &log, const RunOptions &o,
                    RunCheckpoint &checkpoint);
#endif

#ifdef TRIBO_WITH_MLP_SCENES
  /// Declare the subsections of the MLP scenes (app/scene_mlp.cc).
  void declare_mlp_scene_parameters(dealii::ParameterHandler &prm);
  /// Read and check an MLP scene's entries and its time step without running it (an
  /// InputError naming the entry otherwise): `tribo check`, and `tribo run` before it
  /// writes anything.
  void check_mlp_scene(const ParameterFile &file);
  /// Run an MLP scene into @p dir; returns the exit code (as run_case()).
  int run_mlp_scene(const ParameterFile &file, const std::string &dir, Log &log, const RunOptions &o,
                    RunCheckpoint &checkpoint);
#endif
} // namespace tribo::app
