#pragma once
// A shear case as the benchmarks run it: the command line's case file and --set overrides,
// the scene built, the time step and the Moreau-Jean integrator of the case's law and solver.
#include "app/case_parameters.h"
#include "app/scene_hooks.h"
#include "app/scenes.h"
#include "core/parameter_file.h"
#include "dem/engine/moreau_jean.h"

#include <memory>
#include <string>
#include <vector>

namespace tribo::bench
{
  struct BenchCase
  {
    /// Positional arguments (after the program name); --set "Section/Entry=value" pairs are
    /// the overrides.
    std::vector<std::string> positional, overrides;
    dealii::ParameterHandler prm;
    ParameterFile            file{prm};
    app::CaseParameters      parameters;
    std::unique_ptr<app::Scene> scene;
    dem::ParticleSystem      system;
    double                   h = 0;
    std::unique_ptr<dem::MoreauJean> integrator;

    /// The case of positional argument 0 (or @p default_case), its scene built.
    BenchCase(int argc, char **argv, const std::string &default_case)
    {
      for (int i = 1; i < argc; ++i)
        if (std::string(argv[i]) == "--set" && i + 1 < argc)
          overrides.push_back(argv[++i]);
        else
          positional.push_back(argv[i]);
      app::declare_case_parameters(prm);
      file.parse(positional.empty() ? default_case : positional[0]);
      for (const auto &o : overrides)
        file.set(o);
      parameters = app::read_case_parameters(file);
      scene      = app::make_shear_scene(file, parameters);
      scene->build(system);
      h = scene->time_step(system);
      const auto &p = parameters;
      integrator    = std::make_unique<dem::MoreauJean>(
        p.theta, p.law, p.solver, p.law.detection_distance > 0 ? p.law.detection_distance : 0.1 * system.min_radius());
    }
    /// Positional argument @p i as a count, or @p fallback.
    unsigned long count(std::size_t i, unsigned long fallback) const
    {
      return positional.size() > i ? std::stoul(positional[i]) : fallback;
    }
    std::string case_file(const std::string &default_case) const
    {
      return positional.empty() ? default_case : positional[0];
    }
  };
} // namespace tribo::bench
