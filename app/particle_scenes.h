#pragma once
/// @file Scenes of the explicit particle modules (sph/, mlp/), one file each in
/// app/scenes/, built as a Simulation that the driver (app/driver.h) runs like the NSCD
/// scenes; their rows of the scene table (app/scenes.cc) name these functions. For each
/// scene: declare_..._parameters declares its own subsection; check_... reads and checks
/// its entries without running it (an InputError naming the entry otherwise: `tribo
/// check`, and `tribo run` before it writes anything); make_... builds it (what it built
/// goes to the log). run_case() has prepared the output directory, written original.prm,
/// parameters.prm and a "running" summary.json, opened the log, and for --resume checked
/// the checkpoint's parameters against the case.

#include "app/driver.h"
#include "core/output.h"
#include "core/parameter_file.h"

#include <deal.II/base/parameter_handler.h>

#include <memory>

namespace tribo::app
{
  struct CaseParameters; // app/case_parameters.h

#ifdef TRIBO_WITH_SPH_SCENES
  // app/scenes/sph_slider.cc: the slider on a substrate, subsection "SPH slider".
  void                        declare_sph_slider_parameters(dealii::ParameterHandler &prm);
  void                        check_sph_slider(const ParameterFile &file);
  std::unique_ptr<Simulation> make_sph_slider(const ParameterFile &file, const CaseParameters &, Log &log);

  // app/scenes/sph_plate.cc: the cantilever plate, subsection "SPH plate".
  void                        declare_sph_plate_parameters(dealii::ParameterHandler &prm);
  void                        check_sph_plate(const ParameterFile &file);
  std::unique_ptr<Simulation> make_sph_plate(const ParameterFile &file, const CaseParameters &, Log &log);
#endif

#ifdef TRIBO_WITH_MLP_SCENES
  /// Declare the subsection "MLP" that every MLP scene reads (app/scenes/mlp_family.cc).
  void declare_mlp_parameters(dealii::ParameterHandler &prm);

  // app/scenes/mlp_ordering.cc, subsection "MLP ordering"; the check includes the time step.
  void                        declare_mlp_ordering_parameters(dealii::ParameterHandler &prm);
  void                        check_mlp_ordering(const ParameterFile &file);
  std::unique_ptr<Simulation> make_mlp_ordering(const ParameterFile &file, const CaseParameters &, Log &log);

  // app/scenes/mlp_compression.cc, subsection "MLP compression".
  void                        declare_mlp_compression_parameters(dealii::ParameterHandler &prm);
  void                        check_mlp_compression(const ParameterFile &file);
  std::unique_ptr<Simulation> make_mlp_compression(const ParameterFile &file, const CaseParameters &, Log &log);

  // app/scenes/mlp_beams.cc, subsection "MLP beams".
  void                        declare_mlp_beams_parameters(dealii::ParameterHandler &prm);
  void                        check_mlp_beams(const ParameterFile &file);
  std::unique_ptr<Simulation> make_mlp_beams(const ParameterFile &file, const CaseParameters &, Log &log);
#endif
} // namespace tribo::app
