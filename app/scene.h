#pragma once
/// @file The NSCD family's scenes (collision, shear): a SceneOf<NscdWorld> (app/scene_of.h)
/// that builds rigid discs, which Moreau-Jean steps (app/nscd_simulation.h), plus what
/// only this family has: the bodies it builds and couples, its time step, where a run
/// starts, its sample files and its plot.

#include "app/case_parameters.h"
#include "app/scene_of.h"
#include "dem/engine/moreau_jean.h"
#include "dem/engine/particle_system.h"

#include <string>
#include <vector>

namespace tribo::app
{
  /// What the NSCD family's hooks see: the discs and, after a step, the integrator and
  /// its report.
  struct NscdWorld
  {
    dem::ParticleSystem     &system;
    const dem::MoreauJean   *integrator = nullptr; ///< null until built
    dem::StepReport          report{};             ///< of the last step
    unsigned long            step = 0;             ///< before_step(): the step about to run
  };

  class Scene : public SceneOf<NscdWorld>
  {
  public:
    /// Create the bodies.
    virtual void build(dem::ParticleSystem &system) = 0;
    /// Couple bodies that are not rigid discs (a BoundaryBody) to the integrator;
    /// called once, after build() and before the first step.
    virtual void attach(dem::MoreauJean &) {}
    /// Write the scene's own fields (e.g. a deformable body) for snapshot @p index into
    /// directory @p dir; returns the file names written (relative to dir).
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
    /// A line for the log after summarize(): which window its means cover; "" for none.
    virtual std::string averaging_note() const { return ""; }
    /// The script in scripts/ that plots a run of the scene (with Output/Plots), "" for none.
    virtual std::string plot_script() const { return ""; }
    /// The state as a sample file (app/sample_file.h), written with every snapshot as
    /// fields/sample_NNNNN.csv and at the end as sample_final.csv; "" when the scene has
    /// none.
    virtual std::string sample(const dem::ParticleSystem &) const { return ""; }

  protected:
    explicit Scene(const CaseParameters &p) : prm(p) {}
    CaseParameters prm;
  };
} // namespace tribo::app
