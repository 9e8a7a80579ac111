#include "app/case_parameters.h"

#include "app/scenes.h"
#include "app/sample_file.h"
#include "core/errors.h"
#include "coupling/first_body.h"

#include <boost/property_tree/json_parser.hpp>
#include <boost/property_tree/ptree.hpp>

#include <cmath>
#include <filesystem>

namespace tribo::app
{
  using dealii::Patterns::Anything;
  using dealii::Patterns::Bool;
  using dealii::Patterns::Double;
  using dealii::Patterns::Integer;
  using dealii::Patterns::Selection;

  namespace
  {
    /// Shear cell/Initial state = @p given: the final sample and time of a completed
    /// shear run, checked against the case @p p (its Length, time step and End
    /// time) into p.shear.initial_state, p.shear.sample and p.start_time.
    void read_initial_state(const ParameterFile &f, const std::string &given, CaseParameters &p)
    {
      namespace fs         = std::filesystem;
      const std::string E  = "Shear cell/Initial state";
      auto             &sc = p.shear;
      if (!sc.sample_file.empty())
        f.fail(E, "no initial state together with a Shear cell/Sample file (each gives the discs)");
      const fs::path dir = fs::absolute(fs::path(given).is_absolute()
                                          ? fs::path(given)
                                          : fs::path(f.filename()).parent_path() / given)
                             .lexically_normal();
      sc.initial_state = dir.string();
      const RunRecord run = read_run_record(dir.string());
      if (run.status != "complete" || run.scene != "shear" || !fs::is_regular_file(dir / "sample_final.csv"))
        f.fail(E, "the directory of a completed shear run (" + dir.string() +
                    (run.status.empty() ? " has no readable summary.json"
                                        : " has status '" + run.status + "', scene '" + run.scene + "'" +
                                            (fs::is_regular_file(dir / "sample_final.csv") ? ""
                                                                                           : ", no sample_final.csv")) +
                    ")");
      if (std::abs(run.length - sc.length) > 1e-12 * sc.length)
        f.fail(E, "a run of this case's Shear cell/Length = " + to_text(sc.length) + " m (" + dir.string() +
                    " has " + to_text(run.length) + " m)");
      const double steps = run.simulated_time / p.time_step;
      if (std::abs(steps - std::round(steps)) > 1e-6 * std::max(1.0, steps))
        f.fail(E, "a state at a whole number of time steps (" + dir.string() + " ends at t0 = " +
                    to_text(run.simulated_time) + " s, " + to_text(steps) + " steps of Simulation/Time step = " +
                    to_text(p.time_step) + " s)");
      if (p.end_time <= run.simulated_time)
        f.fail(E, "a state before Simulation/End time = " + to_text(p.end_time) + " s (" + dir.string() +
                    " ends at t0 = " + to_text(run.simulated_time) + " s)");
      p.start_time = std::round(steps) * p.time_step;
      sc.sample    = read_sample((dir / "sample_final.csv").string(), sc.length);
    }

    /// The upper first body of the shear cell @p p: its own entries, read by coupling,
    /// and the cell's geometry, load and time step; checked as a whole.
    coupling::FirstBodyParameters upper_body_parameters(const ParameterFile &f, const CaseParameters &p)
    {
      const auto                   &sc = p.shear;
      coupling::FirstBodyParameters b  = coupling::FirstBodyParameters::parse(f, "Shear cell");
      b.length             = sc.length;
      b.density            = sc.density;
      if (b.resolution == 0)
        b.resolution = sc.mean_diameter * (1 - sc.diameter_spread);
      b.theta              = p.theta;
      b.time_step          = p.time_step;
      b.pressure           = sc.pressure;
      b.pressure_ramp_time = sc.ramp_time;
      if (sc.shear_start == 0)
        b.compaction_damping = 0; // no compaction phase
      try
        {
          coupling::check_first_body(b);
        }
      catch (const InputError &e)
        {
          throw InputError(f.filename() + ": " + e.what());
        }
      return b;
    }
  } // namespace

  void declare_case_parameters(dealii::ParameterHandler &prm)
  {
declare_scene_subsections(prm);
    prm.enter_subsection("Simulation");
    declare_scene_entry(prm);
    prm.declare_entry("Time step", "1e-9", Double(), "Time step h, s (> 0).");
    prm.declare_entry("End time", "1e-6", Double(), "Simulated time, s (> 0).");
    prm.declare_entry("Theta", "0.5", Double(0.5, 1.0),
                      "Moreau-Jean theta, in [0.5, 1]: 0.5 is the midpoint rule, 1 is implicit Euler.");
    prm.leave_subsection();

    prm.enter_subsection("Contact law");
    dem::ContactLaw::declare(prm);
    prm.leave_subsection();

    prm.enter_subsection("Solver");
    dem::SolverParameters::declare(prm);
    prm.leave_subsection();

    prm.enter_subsection("Output");
    prm.declare_entry("Statistics interval", "1", Integer(1), "Steps between rows of statistics.csv, >= 1.");
    prm.declare_entry("Field interval", "0", Integer(0),
                      "Steps between VTU snapshots in fields/; 0 writes only the first and the last.");
    prm.declare_entry("Checkpoint interval", "600", Double(0),
                      "Wall-clock seconds between checkpoints (checkpoint.bin in the output directory, "
                      "for `tribo run CASE.prm --resume DIR`); 0: none on a timer. An interrupted run "
                      "(SIGINT, SIGTERM) also writes one.");
    prm.declare_entry("Checkpoint step interval", "0", Integer(0),
                      "Steps between checkpoints, in addition to the timer; 0: none.");
    prm.declare_entry("Plots", "true", Bool(),
                      "Write PNG plots (mu.png, power.png, profiles.png) of a shear run with "
                      "scripts/plot_run.py (Debian's python3-matplotlib).");
    prm.leave_subsection();

    prm.enter_subsection("Collision");
    prm.declare_entry("Diameter", "1.2e-6", Double(), "Diameter of both discs, m (> 0).");
    prm.declare_entry("Density", "7800", Double(), "Density, kg/m^3 (> 0).");
    prm.declare_entry("Impact velocity", "2", Double(),
                      "Relative normal velocity at t = 0, m/s: > 0 approaching, < 0 separating, not 0.");
    prm.declare_entry("Initial gap", "1e-10", Double(), "Gap between the discs at t = 0, m (> -diameter/2).");
    prm.declare_entry("Time step ratio", "0", Double(),
                      "dt*/dt with dt* = sqrt(m_eff/k), >= 0; if > 0 it sets the time step and "
                      "Simulation/Time step is ignored.");
    prm.declare_entry("Stop when separated", "true", Bool(),
                      "End the run once the discs have touched and are farther apart than the "
                      "detection distance.");
    prm.leave_subsection();


    prm.enter_subsection("Shear cell");
    prm.declare_entry("Number of discs", "3820", Integer(1), "Third-body discs, >= 1 (paper: 3820).");
    prm.declare_entry("Mean diameter", "1.2e-6", Double(), "Mean disc diameter d, m (> 0; paper: 1.2e-6).");
    prm.declare_entry("Diameter spread", "0.2", Double(0, 0.99),
                      "Relative half-width s of the uniform diameter distribution [d(1-s), d(1+s)] (paper: 0.2).");
    prm.declare_entry("Density", "7800", Double(), "Density of discs, walls and first bodies, kg/m^3 (> 0).");
    prm.declare_entry("Length", "1e-4", Double(), "Period L along x, m (> 0; paper: 1e-4).");
    prm.declare_entry("Wall discs", "72", Integer(0),
                      "Discs in each rough wall, spread evenly along L (paper: 72); 0 gives about L/d "
                      "(d: Wall disc diameter if given, else the mean diameter).");
    prm.declare_entry("Wall disc diameter", "0", Double(0),
                      "Diameter of every wall disc, m (>= 0); 0: drawn from the grains' distribution "
                      "(the paper's walls).");
    prm.declare_entry("Pressure", "1e8", Double(), "Pressure P on the upper wall, Pa (> 0); force P L per unit depth.");
    prm.declare_entry("Pressure ramp time", "2e-6", Double(), "Time over which P rises linearly from 0, s (>= 0).");
    prm.declare_entry("Sliding velocity", "5", Double(), "Velocity V of the lower wall along x once shearing starts, m/s.");
    prm.declare_entry("Shear start", "1e-5", Double(),
                      "Time at which the lower wall starts sliding, s (>= 0): compaction before; at or after "
                      "Simulation/End time the run only compacts.");
    prm.declare_entry("Profile samples", "500", Integer(1),
                      "Profile samples: the shearing phase is cut into this many blocks of consecutive steps, "
                      "each sample the mean over every step of its block (no snapshot that could alias a "
                      "periodic motion); profiles.csv averages the samples of the steady state (paper: 500 "
                      "snapshots).");
    prm.declare_entry("Layer thickness", "0", Double(),
                      "Thickness of the profile layers, m (>= 0); 0: one mean diameter.");
    prm.declare_entry("Seed", "1", Integer(0), "Seed of the disc sizes.");
    prm.declare_entry("Sample file", "", Anything(),
                      "A CSV file of discs to start from instead of generated grains: header "
                      "'x,y,r,body' (optionally ',vx,vy,spin'), SI units, body = grain, lower_wall or "
                      "upper_wall (each wall one rigid body; without wall rows both walls are "
                      "generated). A relative path is relative to the case file. Number of discs, "
                      "Mean diameter, Diameter spread and Seed then do not act on the grains; "
                      "with a deformable Upper body model, the body's surface stands where the upper wall's "
                      "would (docs/outputs.md, 'Sample files').");
    prm.declare_entry("Initial state", "", Anything(),
                      "The directory of a completed shear run (e.g. a compaction-only run, "
                      "Shear start >= End time) to go on from: the case starts at that run's final time "
                      "t0 from its sample_final.csv (grains, walls, their velocities; not the contact "
                      "impulses), with this case's parameters from t0 on; the steps before t0 are not "
                      "run. t0 must be a whole number of time steps and before End time; the Length "
                      "must be the run's. A relative path is relative to the case file. Not with "
                      "Sample file. A deformable Upper body model takes the upper wall's place, unloaded, and "
                      "takes the load over Pressure ramp time from t0 (docs/outputs.md, 'Initial states').");
    coupling::FirstBodyParameters::declare(prm);
    prm.leave_subsection();
  }

  CaseParameters read_case_parameters(const ParameterFile &f)
  {

    CaseParameters p;
    p.scene     = f.get("Simulation/Scene");
    p.time_step = f.get_checked("Simulation/Time step", is_positive, "a positive time step in s");
    p.end_time  = f.get_checked("Simulation/End time", is_positive, "a positive end time in s");
    p.theta     = f.get_double("Simulation/Theta");

    p.law    = dem::ContactLaw::parse(f, "Contact law");
    p.solver = dem::SolverParameters::parse(f, "Solver");

    p.statistics_interval = f.get_integer("Output/Statistics interval");
    p.field_interval      = f.get_integer("Output/Field interval");
    p.plots               = f.get_bool("Output/Plots");
    p.checkpoint_interval      = f.get_double("Output/Checkpoint interval");
    p.checkpoint_step_interval = f.get_integer("Output/Checkpoint step interval");

    auto &c = p.collision;
    if (p.scene == "collision")
      {
        c.diameter = f.get_checked("Collision/Diameter", is_positive, "a positive diameter in m");
        c.density  = f.get_checked("Collision/Density", is_positive, "a positive density in kg/m^3");
        c.impact_velocity = f.get_checked("Collision/Impact velocity",
                                          [](double v) { return v != 0 && std::isfinite(v); },
                                          "a non-zero velocity in m/s");
        c.initial_gap = f.get_checked("Collision/Initial gap",
                                      [&](double v) { return v > -0.5 * c.diameter; },
                                      "a gap in m larger than minus half the diameter");
        c.time_step_ratio = f.get_checked("Collision/Time step ratio", is_non_negative, "a ratio >= 0");
        c.stop_when_separated = f.get_bool("Collision/Stop when separated");
      }

    auto &sc = p.shear;
    if (p.scene == "shear")
      {
        const std::string S = "Shear cell/";
        sc.n_discs         = f.get_integer(S + "Number of discs");
        sc.mean_diameter   = f.get_checked(S + "Mean diameter", is_positive, "a positive diameter in m");
        sc.diameter_spread = f.get_double(S + "Diameter spread");
        sc.density         = f.get_checked(S + "Density", is_positive, "a positive density in kg/m^3");
        sc.length          = f.get_checked(S + "Length", is_positive, "a positive length in m");
        const double d_max = sc.mean_diameter * (1 + sc.diameter_spread);
        if (sc.length < 8 * d_max)
          f.fail(S + "Length", "a length of at least 8 largest diameters (" + to_text(8 * d_max) + " m)");
        sc.wall_discs         = f.get_integer(S + "Wall discs");
        sc.wall_disc_diameter = f.get_double(S + "Wall disc diameter");
        if (sc.wall_disc_diameter > sc.length / 8)
          f.fail(S + "Wall disc diameter", "a diameter of at most L/8 = " + to_text(sc.length / 8) +
                                             " m (a wall of at least 8 discs), or 0");
        const double d_wall   = sc.wall_disc_diameter > 0 ? sc.wall_disc_diameter
                                                          : sc.mean_diameter * (1 - sc.diameter_spread);
        if (sc.wall_discs > 0 && sc.wall_discs * d_wall > sc.length * (1 + 1e-12))
          f.fail(S + "Wall discs", "at most " + std::to_string(int(sc.length / d_wall * (1 + 1e-12))) +
                                     " discs, so that they fit along the length without overlapping");
        sc.pressure  = f.get_checked(S + "Pressure", is_positive, "a positive pressure in Pa");
        sc.ramp_time = f.get_checked(S + "Pressure ramp time", is_non_negative, "a time >= 0 in s");
        sc.sliding_velocity = f.get_checked(S + "Sliding velocity", [](double v) { return std::isfinite(v); }, "a velocity in m/s");
        sc.shear_start = f.get_checked(S + "Shear start", is_non_negative, "a time >= 0 in s");
        sc.profile_samples = f.get_integer(S + "Profile samples");
        sc.layer_thickness = f.get_checked(S + "Layer thickness", is_non_negative, "a thickness >= 0 in m");
        sc.seed = f.get_integer(S + "Seed");
        if (const std::string sample = f.get(S + "Sample file"); !sample.empty())
          {
            const std::filesystem::path given(sample);
            sc.sample_file = std::filesystem::absolute(
              given.is_absolute() ? given : std::filesystem::path(f.filename()).parent_path() / given)
                               .lexically_normal()
                               .string();
            sc.sample = read_sample(sc.sample_file, sc.length);
          }
        if (const std::string state = f.get(S + "Initial state"); !state.empty())
          read_initial_state(f, state, p);
        sc.upper_body = upper_body_parameters(f, p);
      }
    return p;
  }

  RunRecord read_run_record(const std::string &dir)
  {
    namespace fs = std::filesystem;
    RunRecord r;
    try
      {
        boost::property_tree::ptree tree;
        boost::property_tree::read_json((fs::path(dir) / "summary.json").string(), tree);
        r.status         = tree.get<std::string>("status", "");
        r.scene          = tree.get<std::string>("scene", "");
        r.simulated_time = tree.get<double>("simulated_time", 0.0);
      }
    catch (const std::exception &)
      {} // status "": no readable summary
    try
      {
        dealii::ParameterHandler prm;
        declare_case_parameters(prm);
        ParameterFile parameters(prm);
        parameters.parse((fs::path(dir) / "parameters.prm").string());
        r.length = parameters.get_double("Shear cell/Length");
      }
    catch (const std::exception &)
      {} // length 0: no readable parameters
    return r;
  }
} // namespace tribo::app
