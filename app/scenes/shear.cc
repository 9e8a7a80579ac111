// The third-body shear cell (Cao, Renouf, Dubois, Berthier 2011, Fig. 3a):
// a layer of discs, periodic along x, between a rough lower wall (a clump of discs) and
// the upper first body. The lower wall is fixed until `Shear start`, then slides at V
// along x (fixed in y and rotation); the upper first body carries the pressure P (force
// P L per unit depth, ramped). Before `Shear start` the layer compacts under P; a Shear
// start at or after the End time gives a compaction-only run.
//
// The upper first body is a model of coupling's table (`Upper body model`,
// coupling/first_body.h), seen here through one interface: the scene gives it the place
// where the upper wall's discs would stand (a wall of discs takes them; a deformable body
// puts the bottom of its half-disc elements on their surface, so that all models start
// from the same layer), its load, and asks for its state, fields and checkpoint.
#include "app/nscd_simulation.h"
#include "app/profiles.h"
#include "app/sample_file.h"
#include "app/scene.h"
#include "app/scenes.h"
#include "app/steady_state.h"
#include "core/errors.h"

#include "coupling/first_body.h"
#include "coupling/first_body_models.h"

#include <boost/archive/binary_iarchive.hpp>
#include <boost/archive/binary_oarchive.hpp>
#include <boost/serialization/string.hpp>

#include <algorithm>
#include <functional>
#include <sstream>
#include <cmath>
#include <filesystem>
#include <limits>
#include <numeric>
#include <tuple>
#include <random>

namespace tribo::app
{
  namespace
  {
    using dealii::Patterns::Anything;
    using dealii::Patterns::Double;
    using dealii::Patterns::Integer;

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
      /// sample_final.csv is in @c sample, its final time in start_time.
      std::string             initial_state;
      /// s: the time the run starts at, 0 unless an initial state gives a later one (a whole
      /// number of time steps; the steps before are not run).
      double                  start_time = 0;
      /// The upper first body, a model of coupling's table (coupling/first_body.h). Its
      /// entries are read by coupling (FirstBodyParameters::parse()); the shear cell's fill
      /// the rest (Length, Density, Pressure, ramp, the Simulation's theta and time step; a
      /// cell size of 0 becomes d(1-s), and no compaction damping without a compaction
      /// phase), checked as a whole by coupling::check_first_body(). The scene places it.
      coupling::FirstBodyParameters upper_body;

      /// Declare subsection Shear cell.
      static void declare(dealii::ParameterHandler &prm)
      {
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

      /// Read and check subsection Shear cell of @p f in the case @p p (its time step, End
      /// time and theta); InputError naming the entry.
      static ShearCellParameters parse(const ParameterFile &f, const CaseParameters &p);
    };

    /// Shear cell/Initial state = @p given: the final sample and time of a completed
    /// shear run, checked against the case @p p (its time step and End time) and the
    /// cell @p sc (its Length) into sc.initial_state, sc.sample and sc.start_time.
    void read_initial_state(const ParameterFile &f, const std::string &given, const CaseParameters &p,
                            ShearCellParameters &sc)
    {
      namespace fs         = std::filesystem;
      const std::string E  = "Shear cell/Initial state";
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
      sc.start_time = std::round(steps) * p.time_step;
      sc.sample    = read_sample((dir / "sample_final.csv").string(), sc.length);
    }

    /// The upper first body of the shear cell @p sc: its own entries, read by coupling,
    /// and the cell's geometry, load and the case's time step; checked as a whole.
    coupling::FirstBodyParameters upper_body_parameters(const ParameterFile &f, const CaseParameters &p,
                                                        const ShearCellParameters &sc)
    {
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

    ShearCellParameters ShearCellParameters::parse(const ParameterFile &f, const CaseParameters &p)
    {
      ShearCellParameters sc;
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
        read_initial_state(f, state, p, sc);
      sc.upper_body = upper_body_parameters(f, p, sc);
      return sc;
    }

    class ShearCellScene : public Scene
    {
    public:
      ShearCellScene(const CaseParameters &p, const ShearCellParameters &k)
        : Scene(p)
        , cell(k)
        , rng(k.seed)
      {}

      void build(dem::ParticleSystem &s) override
      {
        const auto &k = cell;
        s.period      = k.length;
        steps_done    = std::lround(cell.start_time / prm.time_step);
        if (!k.sample.empty())
          build_from_sample(s);
        else
          build_generated(s);
        unsigned int grains = 0;
        mean_grain_diameter = 0;
        for (const auto &d : s.discs)
          if (d.body != lower && d.body != upper_body->system_body())
            {
              mean_grain_diameter += 2 * d.radius;
              ++grains;
            }
        mean_grain_diameter /= grains;
        profiles = std::make_unique<LayerProfiles>(
          lower, upper_body->system_body(), 0.5 * lower_wall_diameter,
          k.layer_thickness > 0 ? k.layer_thickness : k.sample.empty() ? k.mean_diameter : mean_grain_diameter);
      }

      void before_step(NscdWorld &w) override
      {
        auto        &s    = w.system;
        const auto   step = w.step;
        const auto  &k    = cell;
        const double t    = step * prm.time_step;
        const double t_load = upper_body->load_time(t, cell.start_time);
        const double ramp   = k.ramp_time > 0 ? std::min(1.0, (t_load + prm.time_step) / k.ramp_time) : 1.0;
        normal_force                 = ramp * k.pressure * k.length;
        sliding                      = t >= k.shear_start;
        s.bodies[lower].velocity.x() = sliding ? k.sliding_velocity : 0.0;
        upper_body->before_step(s, normal_force, sliding);
      }

      std::string description() const override { return upper_body->describe(); }
      double      start_time() const override { return cell.start_time; }
      std::string start_state() const override { return "the state of " + cell.initial_state; }
      std::string plot_script() const override { return "plot_run.py"; }

      /// The grains and both walls; with a deformable upper body the grains and the lower
      /// wall (the body is not made of discs: a run from the sample puts its own upper
      /// body or a generated wall above the grains).
      std::string sample(const dem::ParticleSystem &s) const override
      {
        return sample_text(s, lower, upper_body->system_body());
      }

      void attach(dem::MoreauJean &mj) override { upper_body->attach(mj); }

      std::vector<std::string> write_fields(const std::string &dir, unsigned int index) const override
      {
        return upper_body->write_fields(dir, index);
      }

      void measure(const NscdWorld &w, Row &row) override
      {
        const auto &s  = w.system;
        const auto &mj = *w.integrator;
        const auto &r  = w.report;
        ++steps_done;
        const double t     = steps_done * prm.time_step;
        const auto  &f     = mj.contact_force();
        const auto  &power = mj.external_power();
        const double F     = normal_force;
        std::vector<double> ke_tb(1, 0.0); // summed over the MPI ranks when the state is split over them
        for (std::size_t b = 0; b < s.bodies.size(); ++b)
          if (b != lower && b != upper_body->system_body() && mj.counts(b))
            ke_tb[0] += s.bodies[b].kinetic_energy();
        mj.sum_over_shares(ke_tb);
        const coupling::FirstBodyState ub = upper_body->state(s, power);
        if (sliding && std::isnan(vy_at_shear_start))
          vy_at_shear_start = last_vy;
        last_vy = ub.vy;
        const double gap = ub.y - s.bodies[lower].position.y();
        const double surface_gap = ub.surface - (s.bodies[lower].position.y() + 0.5 * lower_wall_diameter);
        if (surface_gap < 0)
          throw RunError("at t = " + to_text(t) + " s the upper first body is " + to_text(gap) +
                         " m above the lower wall, its surface below the lower wall's: it has passed "
                         "through the layer (contacts missed when a body moves more than the "
                         "detection distance in one step). Use a smaller Simulation/Time step or "
                         "a larger Contact law/Detection distance.");

        // Profiles from every step of the shearing phase, in blocks of block_steps steps
        // (Profile samples blocks over the planned shearing phase), each block one sample.
        const auto &k = cell;
        if (sliding)
          {
            const double        h       = prm.time_step;
            const unsigned long n_steps = std::max(1L, std::lround(std::ceil(prm.end_time / h - 1e-9)));
            const unsigned long first   = std::lround(std::ceil(k.shear_start / h - 1e-9));
            if (block_steps == 0)
              block_steps = std::max(1UL, (n_steps - std::min(n_steps - 1, first) + k.profile_samples - 1) /
                                            k.profile_samples);
            profiles->accumulate(s, mj, ub.surface);
            const unsigned long done = steps_done - std::min(steps_done, first); // shearing steps so far
            if (done % block_steps == 0 || steps_done >= n_steps)
              profiles->end_block((steps_done - profiles->n_open_steps()) * h);
          }

        // mu > 0 when the layer resists the lower wall's sliding, whatever the sign of V.
        const double direction = k.sliding_velocity < 0 ? -1.0 : 1.0;
        row("mu", F > 0 ? -direction * f[lower].x() / F : 0.0)("normal_force", F)
          ("lower_wall_normal_force", -f[lower].y())("upper_wall_y", ub.y)("upper_wall_vy", ub.vy)
          ("gap", gap)("power_lower_wall", power[lower])("power_upper_wall", ub.power)
          ("power_dissipated", -r.power_contacts)("kinetic_energy_third_body", ke_tb[0])
          ("kinetic_energy_upper_wall", ub.kinetic_energy)
          ("solid_fraction", grain_area(s) / (surface_gap * k.length))
          ("elastic_energy_upper_body", ub.stored_energy)("power_damping_upper_body", r.boundary_dissipation)
          ("upper_body_face_shift", upper_body->face_shift());
      }

      void summarize(const NscdWorld &, const TimeSeries &stats, JsonObject &j) override
      {
        const auto  &k     = cell;
        const auto   time  = stats.column("time");
        const double t1    = time.back();
        j.set("sliding", sliding);
        // Averaging window: the steady state when sliding, else the last fifth (compaction).
        double start = time.front() + 0.8 * (t1 - time.front());
        // The upper body's mean vertical velocity just before Shear start (0 before the shear).
        const double landing =
          sliding ? vy_before_shear(time, stats.column("upper_wall_vy"), k.shear_start) : 0.0;
        if (sliding)
          {
            steady = detect_steady_state(time, {stats.column("mu"), stats.column("kinetic_energy")},
                                         k.shear_start, t1, 0.1, {0.01, 0.0});
            start = steady.start;
            j.set("steady_state_reached", steady.reached);
            j.set("steady_state_start", steady.start);
            j.set("upper_body_vy_at_shear_start", vy_at_shear_start);
            j.set("upper_body_vy_before_shear", landing);
          }
        else
          steady.start = t1 + 1; // no profile sample is in a steady state
        const auto stat = [&](const std::string &name) { return mean_and_std(time, stats.column(name), start); };
        // Standard errors by batch means over the averaging window (steady_state.h).
        const auto stderr_of = [&](const std::string &name) {
          return mean_and_stderr(time, stats.column(name), start).second;
        };
        const auto window_batches = [&](const std::string &name) {
          const auto          v = stats.column(name);
          std::vector<double> window;
          for (std::size_t i = 0; i < time.size(); ++i)
            if (time[i] >= start)
              window.push_back(v[i]);
          return batch_means(window);
        };
        j.set("averaging_start", start);
        {
          std::ostringstream note;
          note << "means over t in [" << start << ", " << t1 << "] s: "
               << (!sliding        ? "compaction only, its last fifth"
                   : steady.reached ? "the steady state (mu and the kinetic energy level)"
                                    : "NOT a steady state (mu or the kinetic energy still drifts): the second "
                                      "half of the shearing phase");
          if (sliding)
            note << "; " << profiles->n_samples_after(steady.start) << " profile samples of " << block_steps
                 << " steps each";
          if (std::abs(landing) > still_moving * std::abs(k.sliding_velocity))
            note << ". Over the last microsecond before Shear start the upper body was still moving at "
                 << landing << " m/s on average (more than " << 100 * still_moving
                 << " % of the sliding velocity): the layer had not finished compacting, and the shear "
                    "began with the body landing on it; a later "
                    "Shear cell/Shear start lets it settle";
          averaging = note.str();
        }
        upper_body->summarize(j);
        j.set("normal_force_mean", stat("lower_wall_normal_force").first);
        j.set("normal_force_stderr", stderr_of("lower_wall_normal_force"));
        j.set("normal_force_target", k.pressure * k.length);
        const double h_tb = stat("gap").first - (upper_body->y_to_surface() + 0.5 * lower_wall_diameter);
        j.set("third_body_thickness", h_tb);
        j.set("third_body_thickness_stderr", stderr_of("gap"));
        j.set("solid_fraction_mean", stat("solid_fraction").first);
        j.set("solid_fraction_stderr", stderr_of("solid_fraction"));
        j.set("face_shift_mean", stat("upper_body_face_shift").first);
        j.set("face_shift_stderr", stderr_of("upper_body_face_shift"));
        {
          const auto shift = stats.column("upper_body_face_shift");
          double     largest = 0;
          for (const double x : shift)
            largest = std::max(largest, std::abs(x));
          j.set("face_shift_max", largest);
          const double half_disc = upper_body->half_disc_diameter();
          j.set("face_shift_in_half_discs", half_disc > 0 ? stat("upper_body_face_shift").first / half_disc : 0.0);
        }
        j.set("cohesion_number", prm.law.cohesion / (k.pressure * mean_grain_diameter));
        if (!sliding)
          return;

        const auto [mu_mean, mu_std] = stat("mu");
        j.set("mu_mean", mu_mean);
        j.set("mu_std", mu_std);
        j.set("mu_stderr", stderr_of("mu"));
        const double p_lb = stat("power_lower_wall").first, p_ub = stat("power_upper_wall").first;
        const double p_diss = stat("power_dissipated").first;
        j.set("power_lower_wall_mean", p_lb);
        j.set("power_lower_wall_stderr", stderr_of("power_lower_wall"));
        j.set("power_upper_wall_mean", p_ub);
        j.set("power_upper_wall_stderr", stderr_of("power_upper_wall"));
        j.set("power_dissipated_mean", p_diss);
        j.set("power_dissipated_stderr", stderr_of("power_dissipated"));
        j.set("power_third_body_mean", stat("power_free").first);
        j.set("power_third_body_stderr", stderr_of("power_free"));
        j.set("power_balance_ratio", p_lb != 0 ? p_diss / p_lb : NAN);
        {
          // Per batch: the ratio of the batch means of P_diss and P_LB.
          auto ratio = window_batches("power_dissipated");
          const auto lower_wall = window_batches("power_lower_wall");
          for (std::size_t b = 0; b < ratio.size(); ++b)
            ratio[b] /= lower_wall[b];
          j.set("power_balance_ratio_stderr", batch_standard_error(ratio));
        }
        // The whole balance: what the walls put in goes into dissipation (contacts and a
        // deformable body's damping) or into the energy the grains and the body hold. Over the
        // rows after the window's first, whose powers are the steps between the two energies
        // (with one row per step the books then close to round-off; the means above also
        // count the first row's step, which came before it).
        {
          const auto   e_grains = stats.column("kinetic_energy");
          const auto   e_body_k = stats.column("kinetic_energy_upper_wall");
          const auto   e_body_s = stats.column("elastic_energy_upper_body");
          const auto   first    = std::lower_bound(time.begin(), time.end(), start) - time.begin();
          const auto   last     = time.size() - 1;
          const auto   energy   = [&](std::size_t i) {
            return e_grains[i] + (upper_body->in_energy_balance() ? e_body_k[i] + e_body_s[i] : 0.0);
          };
          const double span     = time[last] - time[first];
          const double rate     = span > 0 ? (energy(last) - energy(first)) / span : 0.0;
          const auto   after_first = [&](const std::string &name) {
            const auto v   = stats.column(name);
            double     sum = 0;
            for (std::size_t i = first + 1; i <= last; ++i)
              sum += v[i];
            return last > std::size_t(first) ? sum / double(last - first) : 0.0;
          };
          const double put_in = after_first("power_lower_wall") + after_first("power_upper_wall");
          j.set("energy_rate_mean", rate);
          j.set("power_balance_closure",
                put_in != 0 ? (after_first("power_dissipated") + after_first("power_damping_upper_body") + rate) / put_in
                            : NAN);
        }
        j.set("inertial_number", std::abs(k.sliding_velocity) / h_tb * mean_grain_diameter *
                                   std::sqrt(k.density / k.pressure));
        j.set("profile_samples_in_steady_state", long(profiles->n_samples_after(steady.start)));
        j.set("profile_steps_per_sample", long(block_steps));

        // Mean stresses over the layers at least two layers away from the walls.
        for (const std::string q : {"sigma_xx", "sigma_yy", "sigma_xy"})
          {
            const auto [mean, error] = profiles->interior_mean(q, steady.start);
            j.set(q + "_mean", mean);
            j.set(q + "_stderr", error);
          }
      }

      std::string averaging_note() const override { return averaging; }

      std::map<std::string, TimeSeries> tables() const override
      {
        TimeSeries table(LayerProfiles::average_columns());
        for (const auto &row : profiles->average(steady.start))
          table.add_row(row);
        return {{"profiles", table}};
      }

      void save(CheckpointOut &ar) const override
      {
        std::ostringstream random;
        random << rng;
        ar << random.str() << steps_done << sliding << normal_force << block_steps << last_vy << vy_at_shear_start;
        profiles->save(ar);
        upper_body->save(ar);
      }

      void load(CheckpointIn &ar) override
      {
        std::string random;
        ar >> random >> steps_done >> sliding >> normal_force >> block_steps >> last_vy >> vy_at_shear_start;
        std::istringstream is(random);
        is >> rng;
        profiles->load(ar);
        upper_body->load(ar);
      }

    private:
      /// The upper first body of Shear cell/Upper body model: a deformable body's surface at
      /// @p surface (m); @p wall adds the rough wall of discs to @p s (its clump and mean
      /// disc diameter) for a model that is one.
      void place_upper_body(dem::ParticleSystem &s, double surface,
                            const std::function<std::pair<unsigned int, double>()> &wall)
      {
        static_assert(LayerProfiles::no_body == coupling::FirstBody::no_system_body);
        upper_body = coupling::make_first_body(cell.upper_body, {s, surface, wall});
      }

      double draw_diameter()
      {
        const auto &k = cell;
        std::uniform_real_distribution<double> u(1 - k.diameter_spread, 1 + k.diameter_spread);
        return k.mean_diameter * u(rng);
      }

      /// A rough wall: discs of drawn sizes (or all of Shear cell/Wall disc diameter)
      /// spread evenly along the period at height y; returns the clump and its mean disc
      /// diameter (both walls draw alike).
      std::pair<unsigned int, double> add_wall(dem::ParticleSystem &s, double y)
      {
        const auto        &k = cell;
        // 0 wall discs: about L/d of them (d the mean or the given wall disc diameter),
        // and never more than fit along L when their diameter is given.
        const double d = k.wall_disc_diameter > 0 ? k.wall_disc_diameter : k.mean_diameter;
        unsigned int n = k.wall_discs > 0 ? k.wall_discs : std::max(1u, unsigned(std::round(k.length / d)));
        if (k.wall_discs == 0 && k.wall_disc_diameter > 0 && n > 1 && n * d > k.length * (1 + 1e-12))
          --n;
        std::vector<double>    radii(n);
        std::vector<dem::Vec2> centres(n);
        for (unsigned int i = 0; i < n; ++i)
          {
            radii[i]   = 0.5 * (k.wall_disc_diameter > 0 ? k.wall_disc_diameter : draw_diameter());
            centres[i] = {(i + 0.5) * k.length / n, y};
          }
        const double mean_diameter = 2 * std::accumulate(radii.begin(), radii.end(), 0.0) / n;
        return {s.add_clump(centres, radii, k.density), mean_diameter};
      }

      /// Grains on a loose triangular lattice (neighbours 1.02 d_max apart) between two
      /// generated walls.
      void build_generated(dem::ParticleSystem &s)
      {
        const auto  &k     = cell;
        const double d_max = k.mean_diameter * (1 + k.diameter_spread);
        std::tie(lower, lower_wall_diameter) = add_wall(s, 0.0);
        for (auto &d : s.bodies[lower].drive)
          d = dem::Drive::velocity;
        const double       pitch   = 1.02 * d_max;
        const unsigned int columns = std::max(1u, unsigned(k.length / pitch));
        const double       dx      = k.length / columns;
        const double       dy      = std::sqrt(std::max(pitch * pitch - 0.25 * dx * dx, 0.0));
        const unsigned int rows    = (k.n_discs + columns - 1) / columns;
        for (unsigned int i = 0; i < k.n_discs; ++i)
          {
            const unsigned int row = i / columns;
            s.add_disc({(i % columns + 0.5 + 0.5 * (row % 2)) * dx, d_max + 0.5 * pitch + row * dy},
                       0.5 * draw_diameter(), k.density);
          }
        const double upper_y = d_max + 0.5 * pitch + (rows - 1) * dy + pitch;
        place_upper_body(s, upper_y - 0.5 * lower_wall_diameter, [&]() { return add_wall(s, upper_y); });
      }

      /// The discs of Shear cell/Sample file (app/sample_file.h): its walls, or generated
      /// walls below and above its grains; a deformable upper body in the upper wall's place.
      void build_from_sample(dem::ParticleSystem &s)
      {
        const auto &k = cell;
        using Body    = SampleDisc::Body;
        // A wall from its rows, moving as its first row says.
        auto wall_of = [&](Body body) {
          std::vector<dem::Vec2> centres;
          std::vector<double>    radii;
          const SampleDisc      *first = nullptr;
          for (const SampleDisc &d : k.sample)
            if (d.body == body)
              {
                centres.push_back(d.centre);
                radii.push_back(d.radius);
                first = first ? first : &d;
              }
          const double       mean_diameter = 2 * std::accumulate(radii.begin(), radii.end(), 0.0) / radii.size();
          const unsigned int wall          = s.add_clump(centres, radii, k.density);
          s.bodies[wall].velocity          = first->velocity;
          s.bodies[wall].spin              = first->spin;
          return std::make_pair(wall, mean_diameter);
        };
        double bottom = std::numeric_limits<double>::infinity(), top = -bottom;
        for (const SampleDisc &d : k.sample)
          if (d.body == Body::grain)
            {
              bottom = std::min(bottom, d.centre.y() - d.radius);
              top    = std::max(top, d.centre.y() + d.radius);
            }
        const auto given = [&](Body body) {
          return std::any_of(k.sample.begin(), k.sample.end(), [&](const SampleDisc &d) { return d.body == body; });
        };
        // The reader ensures upper wall rows come with lower wall rows.
        const bool lower_given = given(Body::lower_wall), upper_given = given(Body::upper_wall);
        // Generated walls clear the grains by a hundredth of a diameter, whatever the
        // wall discs drawn.
        const double clearance = 0.5 * (k.wall_disc_diameter > 0 ? k.wall_disc_diameter
                                                                 : k.mean_diameter * (1 + k.diameter_spread)) +
                                 0.01 * mean_diameter_of(k.sample);
        if (lower_given)
          std::tie(lower, lower_wall_diameter) = wall_of(Body::lower_wall);
        else
          {
            std::tie(lower, lower_wall_diameter) = add_wall(s, 0.0);
            s.bodies[lower].position.y() += bottom - clearance;
          }
        for (auto &d : s.bodies[lower].drive)
          d = dem::Drive::velocity;
        for (const SampleDisc &d : k.sample)
          if (d.body == Body::grain)
            {
              const unsigned int b     = s.add_disc(d.centre, d.radius, k.density);
              s.bodies[b].velocity     = d.velocity;
              s.bodies[b].spin         = d.spin;
            }
        // A deformable body's surface where the upper wall's was, or just clear of the
        // grains; a wall of discs from the sample's rows, or generated above the grains.
        double surface = top + 0.01 * mean_diameter_of(k.sample);
        if (upper_given)
          {
            double y = 0, r = 0;
            int    n = 0;
            for (const SampleDisc &d : k.sample)
              if (d.body == Body::upper_wall)
                {
                  y += d.centre.y();
                  r += d.radius;
                  ++n;
                }
            surface = (y - r) / n;
          }
        place_upper_body(s, surface, [&]() {
          return upper_given ? wall_of(Body::upper_wall) : add_wall(s, top + clearance);
        });
      }

      static double mean_diameter_of(const std::vector<SampleDisc> &sample)
      {
        double sum = 0;
        for (const SampleDisc &d : sample)
          sum += 2 * d.radius;
        return sum / sample.size();
      }

      double grain_area(const dem::ParticleSystem &s) const
      {
        double a = 0;
        for (const auto &d : s.discs)
          if (d.body != lower && d.body != upper_body->system_body())
            a += M_PI * d.radius * d.radius;
        return a;
      }

      ShearCellParameters            cell;
      std::mt19937                   rng;
      unsigned int                   lower = 0;
      unsigned long                  steps_done = 0;
      /// Steps per profile sample, fixed at the first shearing step (0 before).
      unsigned long                  block_steps = 0;
      bool                           sliding    = false; ///< the lower wall has started sliding
      double                         normal_force = 0;   ///< P L at the current ramp, N/m
      /// The upper body's vertical velocity after the last step, and after the last step
      /// before the shear (NaN until the shear starts), m/s.
      double                         last_vy = 0, vy_at_shear_start = NAN;
      /// A body whose mean vertical speed over the landing_window before Shear start exceeds
      /// this fraction of the sliding velocity has not landed (the default case's at 10 us:
      /// -1.17 m/s; landed, its mean over each microsecond from 12 to 30 us stays within
      /// 0.016 m/s, while with APGS at 1e-3 the step's value jiggles by up to 0.15 m/s).
      static constexpr double        still_moving   = 0.01;
      static constexpr double        landing_window = 1e-6; ///< s
      /// The mean of @p vy over the statistics rows with t in [@p shear_start -
      /// landing_window, @p shear_start) (m/s), or vy_at_shear_start without such a row.
      double vy_before_shear(const std::vector<double> &time, const std::vector<double> &vy,
                             double shear_start) const
      {
        double sum = 0;
        int    rows = 0;
        for (std::size_t i = 0; i < time.size(); ++i)
          if (time[i] >= shear_start - landing_window && time[i] < shear_start)
            {
              sum += vy[i];
              ++rows;
            }
        return rows > 0 ? sum / rows : vy_at_shear_start;
      }
      double                         lower_wall_diameter = 0, mean_grain_diameter = 0;
      std::unique_ptr<coupling::FirstBody> upper_body;
      std::unique_ptr<LayerProfiles> profiles;
      SteadyState                    steady;
      std::string                    averaging; ///< the log line of averaging_note()
    };
  } // namespace

  namespace
  {
    /// True for the entries that act only from Shear cell/Shear start on, or not on the
    /// bodies at all: the cases of a study that differ only in these (and in the study's
    /// Shear-phase entries) share one compaction.
    bool acts_only_after_shear_start(const std::string &entry)
    {
      return entry == "Simulation/End time" || entry == "Shear cell/Sliding velocity" ||
             entry == "Shear cell/Profile samples" || entry == "Shear cell/Layer thickness" ||
             entry.rfind("Output/", 0) == 0;
    }

    /// The compaction a shear case starts from (SceneHooks::compaction_of): its overrides
    /// that act before Shear start, End time = Shear start; none for a case with a state of
    /// its own, no compaction or no shearing, or a compaction with a body that is not a wall
    /// of discs (a state holds discs only).
    std::vector<std::string> compaction_of(const StudyCase &c, const std::vector<std::string> &shear_phase)
    {
      const auto   value = [&](const std::string &entry) { return c.value(c.overrides, entry); };
      const double start = std::stod(value("Shear cell/Shear start"));
      if (!value("Shear cell/Initial state").empty() || start <= 0 ||
          start >= std::stod(value("Simulation/End time")))
        return {};
      std::vector<std::string> preparation;
      for (std::size_t i = 0; i < c.overrides.size(); ++i)
        if (!acts_only_after_shear_start(c.entries[i]) &&
            std::find(shear_phase.begin(), shear_phase.end(), c.entries[i]) == shear_phase.end())
          preparation.push_back(c.overrides[i]);
      preparation.push_back("Simulation/End time=" + value("Shear cell/Shear start"));
      preparation.push_back("Output/Plots=false");
      if (!coupling::is_wall_of_discs(c.value(preparation, "Shear cell/Upper body model")))
        return {};
      return preparation;
    }
  } // namespace

  std::unique_ptr<Scene> make_shear_scene(const ParameterFile &f, const CaseParameters &p)
  {
    return std::make_unique<ShearCellScene>(p, ShearCellParameters::parse(f, p));
  }

  SceneHooks shear_hooks()
  {
    SceneHooks hooks{{ShearCellParameters::declare},
                     [](const ParameterFile &f) { ShearCellParameters::parse(f, read_case_parameters(f)); },
                     [](const ParameterFile &f, const CaseParameters &p, Log &log) {
                       return make_nscd_simulation(p, make_shear_scene(f, p), log);
                     }};
    // The sample file and the initial state by their absolute paths.
    hooks.resolve = [](ParameterFile &f) {
      const auto cell = ShearCellParameters::parse(f, read_case_parameters(f));
      if (!cell.sample_file.empty())
        f.set("Shear cell/Sample file=" + cell.sample_file);
      if (!cell.initial_state.empty())
        f.set("Shear cell/Initial state=" + cell.initial_state);
    };
    hooks.compaction_of = compaction_of;
    return hooks;
  }
} // namespace tribo::app
