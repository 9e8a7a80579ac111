// The SPH cantilever-plate scene (sph_plate): the clamped plate used to validate the
// elastic solver (Gray, Monaghan and Swift 2001), an Experiment of the SPH family
// (app/scenes/sph_family.h). 2D plane strain, SI units, per metre of depth.
#include "app/scene_hooks.h"
#include "app/scenes/sph_family.h"

#include "sph/lattice.h"
#include "sph/solver.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace tribo::app
{
  using namespace sph_scenes;

  namespace
  {
    using dealii::Patterns::Double;
    using dealii::Patterns::Selection;
    using sph::Tensor;

    const std::string plate_section = "SPH plate";

    /// Parameters of the cantilever plate (2D plane strain).
    struct PlateParameters
    {
      sph::Material material;
      double        length = 0, thickness = 0, spacing = 0, smoothing_ratio = 1.2, tip_velocity = 0;
      sph::SolverParameters integration; ///< viscosity, CFL number, step floor
      double        end_time = 0;
      double        statistics_interval = 0, field_interval = 0;
    };

    /// Reads and checks the subsection "SPH plate".
    PlateParameters read_plate(EntryReader &r)
    {
      const std::string s = plate_section + "/";
      PlateParameters   p;
      p.material  = material_named(r.text(s + "Material"));
      p.length    = r.number(s + "Length", is_positive, "a positive length in m");
      p.thickness = r.number(s + "Thickness", is_positive, "a positive thickness in m");
      p.spacing   = r.number(s + "Particle spacing", is_positive, "a positive particle spacing in m");
      p.smoothing_ratio = r.number(s + "Smoothing length ratio", [](double v) { return v >= 1 && v <= 2; },
                                   "a ratio h/a in [1, 2]");
      p.tip_velocity = r.number(s + "Tip velocity", is_positive, "a positive velocity in m/s");
      p.integration  = read_integration(r, s);
      p.end_time = r.number("Simulation/End time", is_positive, "a positive end time in s");
      p.statistics_interval = r.number(s + "Statistics interval", is_positive, "a positive interval in s");
      p.field_interval = r.number(s + "Field interval", is_non_negative, "an interval >= 0 in s");
      if (p.thickness < 3 * p.spacing || p.length < 3 * p.thickness)
        r.fail(s + "Thickness", "at least 3 particle spacings and at most a third of the length");
      return p;
    }

    /// First mode of a clamped-free beam, w(x) = cosh kx - cos kx - s (sinh kx - sin kx),
    /// s = (cosh kL + cos kL)/(sinh kL + sin kL), kL = 1.875104 (dimensionless shape).
    double cantilever_mode(double x, double L)
    {
      const double kL = 1.875104068711961, k = kL / L;
      const double s  = (std::cosh(kL) + std::cos(kL)) / (std::sinh(kL) + std::sin(kL));
      return std::cosh(k * x) - std::cos(k * x) - s * (std::sinh(k * x) - std::sin(k * x));
    }

    /// The cantilever plate (2D plane strain): a plate 0 <= x < L, 0 <= y < H clamped by
    /// three fixed columns at x < 0, started with the first mode's velocity
    /// v_y(x) = V w(x)/w(L) (V the tip velocity). Thin-plate theory:
    /// omega^2 = E H^2 k^4/(12 rho (1 - nu^2)), kL = 1.875 (E, nu of the small-strain
    /// moduli). The tip deflection w_tip(t) = (V/omega) sin(omega t): its first zero after
    /// t = 0 is at pi/omega; before that the first zero of the tip velocity, pi/(2 omega).
    class Plate : public Experiment<2>
    {
    public:
      Plate(const PlateParameters &p, sph::Solver<2> &solver, Log &log) : p(p)
      {
        const double a = p.spacing;
        Tensor<1, 2> origin, size;
        origin[0] = -3 * a;
        size[0]   = p.length + 3 * a;
        size[1]   = p.thickness;
        const auto pts = sph::lattice_points<2>(sph::LatticeType::cubic, origin, size, a);
        sph::add_particles(solver.state, pts, p.material.rho0, a * a, p.smoothing_ratio * a, 0, 0);
        sph::ImposedVelocity<2> clamp;
        double                  x_max = -1e300;
        for (const auto &x : pts)
          x_max = std::max(x_max, x[0]);
        for (unsigned int i = 0; i < pts.size(); ++i)
          {
            if (pts[i][0] < 0)
              clamp.particles.push_back(i);
            else
              solver.state.v[i][1] = p.tip_velocity * cantilever_mode(pts[i][0], p.length) /
                                     cantilever_mode(p.length, p.length);
            if (pts[i][0] > x_max - 0.25 * a)
              {
                tip.push_back(i);
                y0.push_back(pts[i][1]);
              }
          }
        solver.imposed.push_back(clamp);
        const auto [E, nu] = young_and_poisson(p.material);
        const double k     = 1.875104068711961 / p.length;
        omega = std::sqrt(E * p.thickness * p.thickness * k * k * k * k /
                          (12 * p.material.rho0 * (1 - nu * nu)));
        std::ostringstream os;
        os << "sph_plate 2D " << p.material.name << ": " << pts.size() << " particles (" << clamp.particles.size()
           << " clamped), L = " << p.length << " m, H = " << p.thickness << " m, E = " << E << " Pa, nu = " << nu
           << "; thin-plate omega = " << omega << " 1/s (period " << 2 * M_PI / omega << " s)";
        log(os.str());
      }

      /// Records the tip deflection (mean over the tip column, m) and velocity (m/s)
      /// at every step and finds the first zero crossings.
      void after_step(SphWorld<2> &world) override
      {
        const auto &solver = world.solver;
        double w = 0, v = 0;
        tip_state(solver, w, v);
        const double t = solver.time;
        if (t_v0 == 0 && v_prev > 0 && v <= 0)
          t_v0 = t_prev + (t - t_prev) * v_prev / (v_prev - v);
        if (t_w0 == 0 && w_prev > 0 && w <= 0)
          t_w0 = t_prev + (t - t_prev) * w_prev / (w_prev - w);
        t_prev = t;
        w_prev = w;
        v_prev = v;
      }

      void measure(const SphWorld<2> &world, Row &row) override
      {
        const auto &solver = world.solver;
        double w = 0, v = 0;
        tip_state(solver, w, v);
        const double ke = solver.state.kinetic_energy(), ei = solver.state.internal_energy();
        row("tip_deflection", w)("tip_velocity", v)("kinetic_energy", ke)("internal_energy", ei)
          ("total_energy", ke + ei);
      }

      void summarize(const SphWorld<2> &, const TimeSeries &stats, JsonObject &res) override
      {
        const double measured = t_w0 > 0 ? M_PI / t_w0 : t_v0 > 0 ? M_PI / (2 * t_v0) : 0.0;
        res.set("omega_analytic", omega);
        res.set("omega_measured", measured);
        res.set("omega_ratio", measured / omega);
        res.set("measured_from", t_w0 > 0 ? "tip deflection zero (t = pi/omega)"
                                 : t_v0 > 0 ? "tip velocity zero (t = pi/(2 omega))" : "none (run too short)");
        res.set("first_velocity_zero", t_v0);
        res.set("first_deflection_zero", t_w0);
        const auto w = stats.column("tip_deflection");
        res.set("max_tip_deflection", *std::max_element(w.begin(), w.end()));
        res.set("amplitude_thin_plate", p.tip_velocity / omega);
        const auto e = stats.column("total_energy");
        res.set("energy_change_ratio", e.front() > 0 ? (e.back() - e.front()) / e.front() : 0.0);
      }

      /// The tip's previous values and the zero crossings found so far.
      void save(CheckpointOut &ar) const override { ar << t_prev << w_prev << v_prev << t_v0 << t_w0; }
      void load(CheckpointIn &ar) override { ar >> t_prev >> w_prev >> v_prev >> t_v0 >> t_w0; }

    private:
      /// Mean vertical displacement @p w (m) and velocity @p v (m/s) of the tip column.
      void tip_state(const sph::Solver<2> &solver, double &w, double &v) const
      {
        w = v = 0;
        for (unsigned int q = 0; q < tip.size(); ++q)
          {
            w += solver.state.x[tip[q]][1] - y0[q];
            v += solver.state.v[tip[q]][1];
          }
        w /= tip.size();
        v /= tip.size();
      }

      PlateParameters           p;
      std::vector<unsigned int> tip;
      std::vector<double>       y0;
      double                    omega = 0;
      double t_prev = 0, w_prev = 0, v_prev = 0, t_v0 = 0, t_w0 = 0;
    };

    /// Reads "SPH plate" and builds the plate.
    std::unique_ptr<Simulation> make_plate(EntryReader &r, Log &log)
    {
      const PlateParameters p = read_plate(r);
      return make_simulation<2>(
        LoopSettings{"sph_plate", p.end_time, p.statistics_interval, p.field_interval},
        std::make_unique<sph::Solver<2>>(std::vector<sph::Material>{p.material}, p.integration),
        [&](sph::Solver<2> &solver) { return std::make_unique<Plate>(p, solver, log); });
    }
  } // namespace

  void declare_sph_plate_parameters(dealii::ParameterHandler &prm)
  {
    prm.enter_subsection(plate_section);
    prm.declare_entry("Material", "granite", Selection("granite|basalt"), "Rock of the plate.");
    prm.declare_entry("Length", "0.2", Double(), "Free length L of the plate, m (> 0).");
    prm.declare_entry("Thickness", "0.02", Double(), "Thickness H, m (>= 3 spacings, <= L/3).");
    prm.declare_entry("Particle spacing", "3.333333333333333e-3", Double(), "Square-lattice spacing a, m (> 0).");
    prm.declare_entry("Smoothing length ratio", "1.2", Double(), "h/a, in [1, 2].");
    prm.declare_entry("Tip velocity", "0.05", Double(), "Initial tip velocity V of the first mode, m/s (> 0).");
    declare_integration_entries(prm);
    prm.declare_entry("Statistics interval", "2e-5", Double(), "Simulated time between rows, s (> 0).");
    prm.declare_entry("Field interval", "0", Double(), "Simulated time between VTU snapshots, s (>= 0).");
    prm.leave_subsection();
  }

  SceneHooks sph_plate_hooks()
  {
    return {{declare_sph_plate_parameters},
            [](const ParameterFile &file) {
              EntryReader r(file);
              read_plate(r);
            },
            [](const ParameterFile &file, const CaseParameters &, Log &log) {
              EntryReader r(file);
              return make_plate(r, log);
            }};
  }
} // namespace tribo::app
