#pragma once
/// @file The one scene interface, SceneOf<World>: what a scene adds to its family's time
/// loop, whatever the family. Each family's integrator advances its World and calls these
/// hooks, and the family's Simulation runs it for the driver (app/driver.h):
/// - NSCD (collision, shear): Moreau-Jean steps of rigid discs, World = NscdWorld
///   (app/scene.h);
/// - SPH (sph_slider, sph_plate): the solver's adaptive steps, World = SphWorld<dim>
///   (app/scenes/sph_family.h);
/// - MLP (mlp_ordering, mlp_compression, mlp_beams): Langevin steps, World = MlpWorld
///   (app/scenes/mlp_family.h).
/// A family's interface adds only what its World needs to be built (NSCD: the discs, the
/// boundary body, the time step, samples; SPH: a step limit; MLP: the particles, their
/// preparation, the loads).

#include "app/driver.h"
#include "core/checkpoint.h"
#include "core/output.h"

#include <map>
#include <string>

namespace tribo::app
{
  template <typename World>
  class SceneOf
  {
  public:
    virtual ~SceneOf() = default;
    /// Before each step, on the World at the step's start (loads, imposed motions).
    virtual void before_step(World &) {}
    /// After each step, on the World at its end: per-step updates and running sums.
    virtual void after_step(World &) {}
    /// The scene's columns of a statistics row as (name, value) pairs. The NSCD family
    /// asks after every step (it averages the power columns over the interval), the SPH
    /// and MLP families when a row is due.
    virtual void measure(const World &, Row &) = 0;
    /// True when the scene's own event is over (the run stops, complete).
    virtual bool finished() const { return false; }
    /// Results for summary.json "results", from the final World and the statistics.
    virtual void summarize(const World &, const TimeSeries &stats, JsonObject &results) = 0;
    /// Extra tables, written as NAME.csv and as the HDF5 group NAME (after summarize()).
    virtual std::map<std::string, TimeSeries> tables() const { return {}; }
    /// Checkpoint: what the scene carries from step to step; what it builds is rebuilt
    /// with it.
    virtual void save(CheckpointOut &) const {}
    virtual void load(CheckpointIn &) {}
  };
} // namespace tribo::app
