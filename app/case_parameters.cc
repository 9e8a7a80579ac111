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
    prm.declare_entry("Law", "IQS", Selection("IQS|ELAS"),
                      "IQS: cohesive unilateral (inelastic quasi-shock), r_N + gamma >= 0, g >= 0, "
                      "(r_N + gamma) g = 0. ELAS: cohesive elastic, r_N + gamma = max(0, -k g). "
                      "r_N > 0 is compressive; see docs/laws.md.");
    prm.declare_entry("Cohesion", "0", Double(), "Cohesion gamma, N/m (force per unit depth), >= 0.");
    prm.declare_entry("Cohesion range", "0", Double(),
                      "Distance d_w over which the cohesion acts, m, >= 0 (needed if Cohesion > 0).");
    prm.declare_entry("Stiffness", "1e10", Double(),
                      "ELAS normal stiffness k, N/m^2 (force per unit depth per metre of overlap), > 0.");
    prm.declare_entry("Friction coefficient", "0", Double(),
                      "Coulomb friction coefficient between discs, >= 0 (0: frictionless, as in the paper).");
    prm.declare_entry("Overlap recovery", "0", Double(0, 1),
                      "IQS only: fraction in [0, 1] of an existing overlap pushed out per step. 0 freezes "
                      "overlaps as the paper's law does; under high pressure the NLGS's small velocity "
                      "errors then accumulate into overlaps step after step (docs/laws.md); 0.1 keeps "
                      "them at the size of one step's error.");
    prm.declare_entry("Detection distance", "0", Double(),
                      "Pairs closer than this gap (m) enter the contact list; 0 picks a tenth of the "
                      "smallest radius. Always at least the cohesion range.");
    prm.leave_subsection();

    prm.enter_subsection("Solver");
    prm.declare_entry("Method", "nlgs", Selection("nlgs|active-set|mprgp|interior-point"),
                      "Contact solver: 'nlgs' (nonlinear Gauss-Seidel, the entries below), "
                      "'active-set' (projected Newton method on the frictionless problem, the "
                      "sparse Delassus operator factorised by CHOLMOD) or 'mprgp' (matrix-free "
                      "projected conjugate gradient with proportioning, on both cores with "
                      "Threads = 2) or 'interior-point' (Mehrotra's predictor-corrector, CHOLMOD: "
                      "the one that reaches 1e-8 on dense packings). The last three stop at "
                      "Residual target; with friction their steps use NLGS and the log says so. "
                      "docs/performance.md compares them.");
    prm.declare_entry("Residual target", "1e-3", Double(),
                      "Active set, MPRGP, interior point: the solve ends when the law residual, max over "
                      "contacts of |min(r~, u~ / W_nn)| over the mean loaded impulse r~ "
                      "(dimensionless, docs/laws.md), is below this, in (0, 1). The default is "
                      "below the 1.2-1.5e-3 NLGS leaves on average at its default Tolerance (1e-4, "
                      "Quad) in steady shear, where MPRGP at 1.5e-3 let overlaps grow past a radius "
                      "(docs/performance.md); 1e-11 is a converged solve.");
    prm.declare_entry("Regularization", "1e-8", Double(),
                      "Active set: relative regularisation delta in [0, 1e-4] of the Newton matrix "
                      "W_FF + delta diag(W_FF) (redundant contacts make W_FF singular); it changes "
                      "the Newton step, not the solution.");
    prm.declare_entry("Predictor sweeps", "10", Integer(0),
                      "Active set, MPRGP, interior point: NLGS sweeps before their iterations, >= 0 "
                      "(0 suits the interior point).");
    prm.declare_entry("Maximum factorizations", "50", Integer(1),
                      "Active set: Newton iterations (factorisations) per step before the step is "
                      "solved by NLGS instead; interior point: iterations before it stops, not "
                      "converged, >= 1.");
    prm.declare_entry("Tolerance", "1e-4", Double(), "NLGS tolerance, > 0 (relative, see Norm).");
    prm.declare_entry("Norm", "Quad", Selection("Quad|Maxm"),
                      "Convergence norm of the established NSCD code: 'Quad' (mean-square) or "
                      "'Maxm' (maximum over contacts).");
    prm.declare_entry("Relaxation", "1", Double(), "Relaxation omega in (0, 1]: r = omega r_law + (1 - omega) r_old.");
    prm.declare_entry("Check interval", "10", Integer(1), "Sweeps between convergence checks, >= 1.");
    prm.declare_entry("Maximum iterations", "10000", Integer(1),
                      "Maximum number of sweeps per step (MPRGP: products with the Delassus "
                      "operator), >= 1.");
    prm.declare_entry("Contact order", "fixed", Selection("fixed|alternating|random"),
                      "Order of the local solves: 'fixed' (detection order: cells by rows, bottom to "
                      "top), 'alternating' (that order and its reverse in turn, a symmetric Gauss-Seidel) "
                      "or 'random' (shuffled every sweep).");
    prm.declare_entry("Seed", "1", Integer(0), "Seed of the random contact order.");
    prm.declare_entry("Streams", "1", Integer(1),
                      "With Contact order = fixed: windows of 64 x Streams consecutive contacts, "
                      "each cut into this many streams solved one contact from each in turn, >= 1 "
                      "(1: the detection order itself). Contacts 64 apart rarely share a body, so "
                      "the processor overlaps their updates: 4 streams do 1.2-1.5 times more contact "
                      "updates per second for about 3 % more sweeps, and change the trajectory "
                      "(docs/performance.md).");
    prm.declare_entry("Threads", "1", Integer(1),
                      "Bands of contacts solved at once, >= 1 (1: the serial sweep). T > 1 cuts the "
                      "contacts (rows of cells, bottom to top) into 2T bands and solves the even bands "
                      "concurrently, then the odd ones: a Gauss-Seidel sweep in that band order, the "
                      "same result on any number of cores. Needs Contact order = fixed. The contact "
                      "detection also runs in T threads (the same contacts whatever T).");
    prm.declare_entry("Gap tolerance", "0", Double(),
                      "Extra IQS convergence criterion, as a fraction of the smallest radius (>= 0; "
                      "0: off, the established code's norms only): every contact's gap violation "
                      "theta h max(0, -(u_n + shift)) must be below it. Limits the overlaps that the "
                      "norms let accumulate under high pressure, at the price of more sweeps.");
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
    prm.declare_entry("Compaction speed limit", "1", Double(),
                      "Before Shear start, the upper wall's vertical speed is capped at this value, m/s "
                      "(>= 0; 0: no cap), so that the compaction stroke under P cannot hit the grains "
                      "at tens of m/s and tunnel into the layer. Not applied while shearing, nor to a deformable "
                      "upper body (see Upper body compaction damping).");
    prm.declare_entry("Upper body thickness", "1.5e-4", Double(),
                      "Thickness of the first body the upper wall stands for, m (> 0; paper: 1.5e-4): "
                      "its mass is density * thickness * L.");
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
    prm.declare_entry("Upper body model", "rigid", Selection("rigid|fem|reduced|sph|mlp"),
                      "rigid: a rough wall of discs with the mass of the first body (the paper's "
                      "classical model); fem: a plane-strain elastic body of that thickness "
                      "(deal.II), touched through half-disc elements (the paper's hybrid model); reduced: "
                      "that body condensed onto its contact nodes plus Upper body modes vibration modes "
                      "(Craig-Bampton), cheaper than fem, exact in the static limit; "
                      "sph, mlp: the same body as an SPH (square lattice) or movable-lattice-particle "
                      "(hexagonal lattice) block whose bottom row of particles carries the half-discs, "
                      "sub-cycled inside each contact step (docs/first_bodies.md).");
    prm.declare_entry("Upper body Young's modulus", "1e11", Double(),
                      "E of the deformable upper body, Pa (> 0; paper: 1e11 and 3e9).");
    prm.declare_entry("Upper body Poisson ratio", "0.33", Double(),
                      "nu of the deformable upper body, plane strain (in (-1, 0.5); paper: 0.33; "
                      "mlp: at most 0.25).");
    prm.declare_entry("Upper body cell size", "0", Double(),
                      "Cell size of the fem upper body's mesh, or particle spacing of the sph and mlp "
                      "bodies, m (>= 0); 0: the smallest grain diameter d(1-s), the paper's choice.");
    prm.declare_entry("Upper body smoothing length ratio", "1.2", Double(),
                      "Smoothing length over particle spacing of the sph upper body (in [1, 2]).");
    prm.declare_entry("Upper body element degree", "1", Integer(1, 4),
                      "Degree p of the fem upper body's Q_p elements.");
    prm.declare_entry("Upper body modes", "20", Integer(0),
                      "Fixed-interface vibration modes kept by the reduced upper body (>= 0; 0: static "
                      "condensation plus the load mode only), docs/fem.md.");
    prm.declare_entry("Upper body mass damping", "0", Double(),
                      "Rayleigh coefficient a of C = a M + b K for the fem upper body, 1/s (>= 0).");
    prm.declare_entry("Upper body stiffness damping", "0", Double(),
                      "Rayleigh coefficient b of C = a M + b K for the fem upper body, s (>= 0).");
    prm.declare_entry("Half-disc diameter", "0", Double(),
                      "Diameter of the half-disc contact elements on the fem upper body, m (>= 0); "
                      "0: the cell size (one per boundary edge, the paper's choice).");
    prm.declare_entry("Upper body compaction damping", "1", Double(),
                      "Damping ratio zeta (>= 0) of the deformable upper body's first thickness mode, "
                      "omega_1 = pi c_p / (2 H), added before Shear start as damping of the velocity "
                      "towards rest at gamma = 2 zeta omega_1 (fem: mass-proportional Rayleigh damping) "
                      "and removed when shearing starts: the body then lands on the layer at the "
                      "terminal speed P / (rho H gamma) (0.7 m/s for the paper's steel body) instead of "
                      "falling freely onto it, and does not ring (no numerical damping at theta = 0.5). "
                      "The rigid wall's Compaction speed limit plays this part. 0: off.");
    prm.leave_subsection();
  }

  CaseParameters read_case_parameters(const ParameterFile &f)
  {
    const auto positive     = [](double v) { return v > 0 && std::isfinite(v); };
    const auto non_negative = [](double v) { return v >= 0 && std::isfinite(v); };

    CaseParameters p;
    p.scene     = f.get("Simulation/Scene");
    p.time_step = f.get_checked("Simulation/Time step", positive, "a positive time step in s");
    p.end_time  = f.get_checked("Simulation/End time", positive, "a positive end time in s");
    p.theta     = f.get_double("Simulation/Theta");

    p.law.type = f.get("Contact law/Law") == "IQS" ? dem::ContactLaw::Type::iqs : dem::ContactLaw::Type::elas;
    p.law.cohesion = f.get_checked("Contact law/Cohesion", non_negative, "a cohesion >= 0 in N/m");
    p.law.cohesion_range =
      f.get_checked("Contact law/Cohesion range", non_negative, "a distance >= 0 in m");
    if (p.law.cohesion > 0 && p.law.cohesion_range == 0)
      f.fail("Contact law/Cohesion range", "a positive range in m, since Contact law/Cohesion > 0");
    p.law.stiffness = f.get_checked("Contact law/Stiffness", positive, "a positive stiffness in N/m^2");
    p.law.overlap_recovery = f.get_double("Contact law/Overlap recovery");
    p.law.friction  = f.get_checked("Contact law/Friction coefficient", non_negative, "a coefficient >= 0");
    p.detection_distance =
      f.get_checked("Contact law/Detection distance", non_negative, "a distance >= 0 in m");

    const std::string method = f.get("Solver/Method");
    p.solver.method = method == "active-set" ? dem::SolverParameters::Method::active_set
                      : method == "mprgp"    ? dem::SolverParameters::Method::mprgp
                      : method == "interior-point" ? dem::SolverParameters::Method::interior_point
                                             : dem::SolverParameters::Method::nlgs;
    p.solver.residual_target = f.get_checked("Solver/Residual target", [](double v) { return v > 0 && v < 1; },
                                             "a relative residual in (0, 1)");
    p.solver.regularization = f.get_checked("Solver/Regularization", [](double v) { return v >= 0 && v <= 1e-4; },
                                            "a regularisation in [0, 1e-4]");
    p.solver.max_factorizations = f.get_integer("Solver/Maximum factorizations");
    p.solver.predictor_sweeps   = f.get_integer("Solver/Predictor sweeps");
    p.solver.tolerance = f.get_checked("Solver/Tolerance", positive, "a positive tolerance");
    p.solver.norm = f.get("Solver/Norm") == "Quad" ? dem::SolverParameters::Norm::quad : dem::SolverParameters::Norm::maxm;
    p.solver.relaxation = f.get_checked("Solver/Relaxation", [](double v) { return v > 0 && v <= 1; },
                                        "a relaxation in (0, 1]");
    p.solver.check_interval = f.get_integer("Solver/Check interval");
    p.solver.max_iterations = f.get_integer("Solver/Maximum iterations");
    const std::string order = f.get("Solver/Contact order");
    p.solver.order = order == "random"        ? dem::SolverParameters::Order::random
                     : order == "alternating" ? dem::SolverParameters::Order::alternating
                                              : dem::SolverParameters::Order::fixed;
    p.solver.seed           = f.get_integer("Solver/Seed");
    p.solver.threads        = f.get_integer("Solver/Threads");
    p.solver.streams        = f.get_integer("Solver/Streams");
    if (p.solver.threads > 1 && p.solver.order != dem::SolverParameters::Order::fixed)
      f.fail("Solver/Threads", "1 with Solver/Contact order = " + order +
                                 " (bands solved at once need the fixed order)");
    p.gap_tolerance         = f.get_checked("Solver/Gap tolerance", non_negative, "a fraction >= 0 of the smallest radius");

    p.statistics_interval = f.get_integer("Output/Statistics interval");
    p.field_interval      = f.get_integer("Output/Field interval");
    p.plots               = f.get_bool("Output/Plots");
    p.checkpoint_interval      = f.get_double("Output/Checkpoint interval");
    p.checkpoint_step_interval = f.get_integer("Output/Checkpoint step interval");

    auto &c = p.collision;
    if (p.scene == "collision")
      {
        c.diameter = f.get_checked("Collision/Diameter", positive, "a positive diameter in m");
        c.density  = f.get_checked("Collision/Density", positive, "a positive density in kg/m^3");
        c.impact_velocity = f.get_checked("Collision/Impact velocity",
                                          [](double v) { return v != 0 && std::isfinite(v); },
                                          "a non-zero velocity in m/s");
        c.initial_gap = f.get_checked("Collision/Initial gap",
                                      [&](double v) { return v > -0.5 * c.diameter; },
                                      "a gap in m larger than minus half the diameter");
        c.time_step_ratio = f.get_checked("Collision/Time step ratio", non_negative, "a ratio >= 0");
        c.stop_when_separated = f.get_bool("Collision/Stop when separated");
      }

    auto &sc = p.shear;
    if (p.scene == "shear")
      {
        const std::string S = "Shear cell/";
        sc.n_discs         = f.get_integer(S + "Number of discs");
        sc.mean_diameter   = f.get_checked(S + "Mean diameter", positive, "a positive diameter in m");
        sc.diameter_spread = f.get_double(S + "Diameter spread");
        sc.density         = f.get_checked(S + "Density", positive, "a positive density in kg/m^3");
        sc.length          = f.get_checked(S + "Length", positive, "a positive length in m");
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
        sc.pressure  = f.get_checked(S + "Pressure", positive, "a positive pressure in Pa");
        sc.ramp_time = f.get_checked(S + "Pressure ramp time", non_negative, "a time >= 0 in s");
        sc.sliding_velocity = f.get_checked(S + "Sliding velocity", [](double v) { return std::isfinite(v); }, "a velocity in m/s");
        sc.shear_start = f.get_checked(S + "Shear start", non_negative, "a time >= 0 in s");
        sc.compaction_speed = f.get_checked(S + "Compaction speed limit", non_negative, "a speed >= 0 in m/s");
        sc.upper_body_thickness = f.get_checked(S + "Upper body thickness", positive, "a positive thickness in m");
        sc.profile_samples = f.get_integer(S + "Profile samples");
        sc.layer_thickness = f.get_checked(S + "Layer thickness", non_negative, "a thickness >= 0 in m");
        sc.seed = f.get_integer(S + "Seed");
        sc.upper_body_model = f.get(S + "Upper body model");
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
        sc.sph_smoothing_ratio = f.get_checked(S + "Upper body smoothing length ratio",
                                               [](double v) { return v >= 1 && v <= 2; }, "a ratio in [1, 2]");
        sc.upper_youngs_modulus = f.get_checked(S + "Upper body Young's modulus", positive, "a positive modulus in Pa");
        sc.upper_poisson_ratio = f.get_checked(S + "Upper body Poisson ratio", [](double v) { return v > -1 && v < 0.5; },
                                               "a Poisson ratio in (-1, 0.5)");
        sc.upper_cell_size = f.get_checked(S + "Upper body cell size", non_negative, "a size >= 0 in m");
        sc.upper_degree = f.get_integer(S + "Upper body element degree");
        sc.upper_modes  = f.get_integer(S + "Upper body modes");
        sc.upper_mass_damping = f.get_checked(S + "Upper body mass damping", non_negative, "a coefficient >= 0 in 1/s");
        sc.upper_stiffness_damping = f.get_checked(S + "Upper body stiffness damping", non_negative, "a coefficient >= 0 in s");
        sc.half_disc_diameter = f.get_checked(S + "Half-disc diameter", non_negative, "a diameter >= 0 in m");
        sc.upper_compaction_damping = f.get_checked(S + "Upper body compaction damping", non_negative, "a damping ratio >= 0");
        if (sc.upper_body_model != "rigid")
          try
            {
              coupling::check_first_body(first_body_parameters(p));
            }
          catch (const InputError &e)
            {
              throw InputError(f.filename() + ": " + e.what());
            }
      }
    return p;
  }

  coupling::FirstBodyParameters first_body_parameters(const CaseParameters &p)
  {
    const auto                   &k = p.shear;
    coupling::FirstBodyParameters b;
    b.model              = k.upper_body_model;
    b.length             = k.length;
    b.thickness          = k.upper_body_thickness;
    b.youngs_modulus     = k.upper_youngs_modulus;
    b.poisson_ratio      = k.upper_poisson_ratio;
    b.density            = k.density;
    b.resolution         = k.upper_cell_size > 0 ? k.upper_cell_size : k.mean_diameter * (1 - k.diameter_spread);
    b.degree             = k.upper_degree;
    b.modes              = k.upper_modes;
    b.rayleigh_mass      = k.upper_mass_damping;
    b.rayleigh_stiffness = k.upper_stiffness_damping;
    b.theta              = p.theta;
    b.time_step          = p.time_step;
    b.pressure           = k.pressure;
    b.pressure_ramp_time = k.ramp_time;
    b.compaction_damping = k.shear_start > 0 ? k.upper_compaction_damping : 0.0;
    b.smoothing_ratio    = k.sph_smoothing_ratio;
    return b;
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
