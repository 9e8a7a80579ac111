#pragma once
/// @file The parameters of a case: declaration (with patterns, defaults and
/// units) and validated reading into plain structs.

#include "app/sample_file.h"
#include "core/parameter_file.h"
#include "coupling/first_body.h"
#include "dem/contact_law.h"
#include "dem/solvers/contact_solver.h"

#include <deal.II/base/parameter_handler.h>

#include <string>

namespace tribo::app
{
  /// Two discs colliding head-on (Cao et al. 2011, Fig. 8).
  struct CollisionParameters
  {
    double diameter;         ///< m, both discs
    double density;          ///< kg/m^3
    double impact_velocity;  ///< relative normal velocity at t = 0, m/s (> 0 approaching)
    double initial_gap;      ///< m
    double time_step_ratio;  ///< dt*/dt with dt* = sqrt(m_eff/k); 0: use Simulation/Time step
    bool   stop_when_separated;
  };

  /// The third-body shear cell of Cao et al. 2011: a periodic layer of discs
  /// between a rough lower wall driven at V and a rough upper wall under P.
  struct ShearCellParameters
  {
    unsigned int n_discs;
    double       mean_diameter;        ///< d, m
    double       diameter_spread;      ///< relative half-width: d in [d(1-s), d(1+s)]
    double       density;              ///< kg/m^3
    double       length;               ///< period L along x, m
    unsigned int wall_discs;           ///< discs per wall (0: L/d)
    double       wall_disc_diameter;   ///< m; 0: drawn like the grains' diameters
    double       pressure;             ///< P, Pa; force P L (N/m) on the upper wall
    double       ramp_time;            ///< s over which P rises linearly from 0
    double       sliding_velocity;     ///< V of the lower wall along x, m/s
    double       shear_start;          ///< s: compaction before, shearing after
    unsigned int profile_samples;      ///< profile samples over the shearing phase
    double       layer_thickness;      ///< profile layer thickness, m (0: d)
    unsigned int seed;
    /// Shear cell/Sample file as an absolute path ("" for generated grains), and its
    /// discs (app/sample_file.h), read and checked with the parameters.
    std::string             sample_file;
    std::vector<SampleDisc> sample;
    /// Shear cell/Initial state as an absolute directory ("" for none): its
    /// sample_final.csv is in @c sample, its final time in CaseParameters::start_time.
    std::string             initial_state;
    /// The upper first body, a model of coupling's table (coupling/first_body.h). Its
    /// entries are read by coupling (FirstBodyParameters::parse()); the shear cell's fill
    /// the rest (Length, Density, Pressure, ramp, the Simulation's theta and time step; a
    /// cell size of 0 becomes d(1-s), and no compaction damping without a compaction
    /// phase), checked as a whole by coupling::check_first_body(). The scene places it.
    coupling::FirstBodyParameters upper_body;
  };

  struct CaseParameters
  {
    std::string scene;
    double      time_step;
    double      end_time;
    /// s: the time the run starts at, 0 unless Shear cell/Initial state gives a later one
    /// (a whole number of time steps; the steps before are not run).
    double      start_time = 0;
    double      theta;
    dem::ContactLaw     law;
    dem::SolverParameters solver;
    unsigned int statistics_interval; ///< steps between rows of statistics.csv
    unsigned int field_interval;      ///< steps between VTU snapshots (0: first and last)
    bool         plots;               ///< PNG plots of a shear run (scripts/plot_run.py)
    double       checkpoint_interval;      ///< wall-clock seconds between checkpoints (0: none)
    unsigned int checkpoint_step_interval; ///< steps between checkpoints (0: none)
    CollisionParameters  collision;
    ShearCellParameters  shear;
  };

  /// What a finished run directory says of itself (its summary.json and parameters.prm),
  /// for a case that goes on from it (Shear cell/Initial state) or exports its snapshots.
  struct RunRecord
  {
    std::string status;             ///< summary.json "status" ("" if unreadable)
    std::string scene;              ///< summary.json "scene"
    double      simulated_time = 0; ///< s, summary.json "simulated_time"
    double      length         = 0; ///< m, parameters.prm Shear cell/Length
  };
  RunRecord read_run_record(const std::string &dir);

  /// Declare every entry of a case file.
  void declare_case_parameters(dealii::ParameterHandler &prm);

  /// Read and check a parsed case; InputError names the entry and what was expected.
  CaseParameters read_case_parameters(const ParameterFile &file);
} // namespace tribo::app
