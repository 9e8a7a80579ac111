#pragma once
/// @file A scene builds the bodies of a case, drives them over time, and adds
/// its own columns to statistics.csv and entries to summary.json.

#include "app/case_parameters.h"
#include "app/driver.h"
#include "core/output.h"
#include "dem/engine/moreau_jean.h"
#include "dem/engine/particle_system.h"

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace tribo::app
{
  class Scene
  {
  public:
    virtual ~Scene() = default;
    /// Create the bodies.
    virtual void build(dem::ParticleSystem &system) = 0;
    /// Couple bodies that are not rigid discs (a BoundaryBody) to the integrator;
    /// called once, after build() and before the first step.
    virtual void attach(dem::MoreauJean &) {}
    /// Write the scene's own fields (e.g. a deformable body) for snapshot @p index at
    /// time @p t into directory @p dir; returns the file names written (relative to dir).
    virtual std::vector<std::string> write_fields(const std::string & /*dir*/, unsigned int /*index*/) const
    {
      return {};
    }
    /// Extra lines for the log after build() (e.g. a deformable body's size); "" for none.
    virtual std::string description() const { return ""; }
    /// The time step to use (the case's, unless the scene derives it).
    virtual double time_step(const dem::ParticleSystem &) const { return prm.time_step; }
    /// The time the run starts at, s: 0 unless the scene goes on from a state (a whole
    /// number of time steps; the steps before are not run).
    virtual double start_time() const { return 0; }
    /// Where a run with start_time() > 0 starts from, for the log.
    virtual std::string start_state() const { return ""; }
    /// Adjust loads before step @p step (e.g. a pressure ramp).
    virtual void before_step(dem::ParticleSystem &, unsigned long /*step*/) {}
    /// Measure after every step (the scene's running sums and samples) and add the
    /// scene's own columns of statistics.csv, as (name, value) pairs, to @p row.
    virtual void measure(const dem::ParticleSystem &, const dem::MoreauJean &, const dem::StepReport &,
                         Row & /*row*/) {}
    /// True when the scene's event is over (the run then ends before End time).
    virtual bool finished() const { return false; }
    /// Scene results for summary.json, from the state and the statistics.
    virtual void summarize(const dem::ParticleSystem &, const TimeSeries &, JsonObject &) {}
    /// A line for the log after summarize(): which window its means cover; "" for none.
    virtual std::string averaging_note() const { return ""; }
    /// Extra tables, written as NAME.csv and as the HDF5 group NAME (after summarize()).
    virtual std::map<std::string, TimeSeries> tables() const { return {}; }
    /// The script in scripts/ that plots a run of the scene (with Output/Plots), "" for none.
    virtual std::string plot_script() const { return ""; }
    /// The state as a sample file (app/sample_file.h), written with every snapshot as
    /// fields/sample_NNNNN.csv and at the end as sample_final.csv; "" when the scene has
    /// none.
    virtual std::string sample(const dem::ParticleSystem &) const { return ""; }
    /// Checkpoint: the state the scene carries between steps (counters, phase, samples,
    /// a deformable body), after build() and attach() have rebuilt the rest.
    virtual void save(CheckpointOut &) const {}
    virtual void load(CheckpointIn &) {}

  protected:
    explicit Scene(const CaseParameters &p) : prm(p) {}
    CaseParameters prm;
  };
} // namespace tribo::app
