/// @file The MLP scene mlp_compression (Popov and Filippov 2006, section 5): a slab
/// pressed between two platens, elastic or plastic (Figs. 3-5), and the compression wave.
/// A scene of the MLP family (app/scenes/mlp_family.h), subsections "MLP" and
/// "MLP compression".
/// 2D, per unit depth: masses kg/m, forces N/m, pressures Pa, energies J/m.

#include "app/scene_hooks.h"
#include "app/scenes/mlp_family.h"
#include "app/steady_state.h"
#include "mlp/analysis.h"
#include "mlp/particles.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <vector>

namespace tribo::app
{
  using namespace mlp_scenes;

  namespace
  {
    /// mlp_compression: a rectangular nx x ny lattice slab, free at top and bottom, pressed
    /// by two rigid platens. A platen is the first (left) or last (right) particle of
    /// every row plus the same column continued over ny rows above and below the slab
    /// (so that a slab that spreads stays between the platens); its particles are held
    /// (group 1 left, 2 right) and move together along x under the total force
    /// +-P(t) H0 (H0 = ny h_row, the initial height: the initial traction is P, Pa) plus
    /// the pair forces on them, by velocity Verlet with the particles (platen mass =
    /// its particles' mass). P(t) = P min(1, t/t_rise). A force per boundary particle
    /// instead would shoot those particles through the slab once it yields. The run
    /// ends early (complete, results "stopped_by_stroke" true) once the platens are closer
    /// than `Stop at delta_h` times their initial distance.
    /// Measures the normalised width along the load, delta_h = (X_right - X_left)(t) /
    /// (X_right - X_left)(0), the platen distance (eq. 23 with the paper's width taken
    /// along the load: it decreases under compression; the platens bound the body), the
    /// transverse delta_w = [max(y) - min(y)](t) / [...](0) of the slab particles,
    /// Gaussian density maps (eq. 22) and histograms at a few times, and the arrival of
    /// the compression wave at two probe particles of the middle row (first time their
    /// v_x exceeds v*/3, v* = P/(rho c_L) the plateau particle velocity: the Airy
    /// front of a weakly dispersive lattice has a third of the plateau at x = c_L t).
    class CompressionScene : public MlpScene
    {
    public:
      CompressionScene(const ParameterFile &f, const CommonSettings &c) : s(c)
      {
        nx       = count(f, "MLP compression/Columns", 4);
        ny       = count(f, "MLP compression/Rows", 2);
        pressure = f.get_checked("MLP compression/Pressure", is_non_negative, "a pressure >= 0 in Pa");
        rise     = f.get_checked("MLP compression/Load rise time", is_non_negative, "a time >= 0 in s");
        maps     = count(f, "MLP compression/Density maps", 0);
        lambda   = f.get_checked("MLP compression/Gaussian width", is_positive, "a positive lambda / r0^2, e.g. 1")
                   * s.interaction.r0 * s.interaction.r0;
        stop_h   = f.get_checked("MLP compression/Stop at delta_h", [](double v) { return v >= 0 && v < 1; },
                           "a fraction of the initial platen distance in [0, 1), e.g. 0.3");
        probe[0] = f.get_checked("MLP compression/First probe", [](double v) { return v >= 0 && v < 0.5; },
                           "a fraction of the slab length in [0, 0.5), e.g. 0.1");
        probe[1] = f.get_checked("MLP compression/Second probe", [&](double v) { return v > probe[0] && v <= 0.5; },
                           "a fraction of the slab length in (First probe, 0.5], e.g. 0.4");
        std::tie(youngs, c_l) = axial_theory(s);
      }

      void build(Particles &p, mlp::Box &box) override
      {
        box = mlp::Box();
        mlp::add_lattice_patch(p, s.lattice, Vec2::Zero(), nx, ny, s.interaction.r0, s.mass);
        h_row = s.lattice == mlp::LatticeType::hexagonal ? 0.5 * std::sqrt(3.0) * s.interaction.r0
                                                          : s.interaction.r0;
        // The platens: the end particles of every row, and the end columns continued.
        const double c   = s.interaction.r0;
        const int    ext = static_cast<int>(ny);
        for (unsigned int side = 0; side < 2; ++side)
          {
            for (unsigned int j = 0; j < ny; ++j)
              platen[side].push_back(j * nx + side * (nx - 1));
            for (int j = -ext; j < static_cast<int>(ny) + ext; ++j)
              if (j < 0 || j >= static_cast<int>(ny))
                {
                  const double shift = (s.lattice == mlp::LatticeType::hexagonal && (j % 2 + 2) % 2 == 1) ? 0.5 * c : 0.0;
                  platen[side].push_back(p.add(Vec2(side * (nx - 1) * c + shift, j * h_row), s.mass));
                }
            for (unsigned int i : platen[side])
              {
                p.group[i] = 1 + side;
                p.fixed[i] = mlp::fix_xy;
              }
          }
        extent0[0] = mlp::extent(p, 0);
        extent0[1] = slab_height(p);
        gap0       = p.position[platen[1][0]].x() - p.position[platen[0][0]].x();
        const unsigned int mid = ny / 2;
        for (unsigned int k = 0; k < 2; ++k)
          {
            probe_index[k] = mid * nx + static_cast<unsigned int>(std::lround(probe[k] * (nx - 1)));
            probe_x[k]     = p.position[probe_index[k]].x() - p.position[mid * nx].x();
          }
        v_star = pressure / (lattice_density(s) * c_l);
      }

      /// Density-map times: evenly spaced over the run, the first at t = 0.
      void set_end_time(double end)
      {
        map_times.clear();
        for (unsigned int k = 0; k < maps; ++k)
          map_times.push_back(maps > 1 ? end * k / (maps - 1) : end);
      }

      /// Pressure P(t), Pa.
      double load(double t) const { return pressure * (rise > 0 ? std::min(1.0, t / rise) : 1.0); }

      /// Half a velocity-Verlet kick of both platens with the force at time @p t:
      /// V += (dt/2) (+-P(t) H0 + sum of the pair forces_x on its particles) / M, then
      /// its particles get the velocity (V, 0).
      void kick_platens(Particles &p, double t, double dt)
      {
        current         = load(t);
        const double H0 = ny * h_row;
        for (unsigned int side = 0; side < 2; ++side)
          {
            double f = (side == 0 ? 1 : -1) * current * H0;
            for (unsigned int i : platen[side])
              f += p.force[i].x();
            platen_velocity[side] += 0.5 * dt * f / (platen[side].size() * s.mass);
            for (unsigned int i : platen[side])
              p.velocity[i] = Vec2(platen_velocity[side], 0);
          }
      }

      /// Extent along y of the slab without the platens, m.
      double slab_height(const Particles &p) const
      {
        double lo = std::numeric_limits<double>::max(), hi = -lo;
        for (unsigned int i = 0; i < p.size(); ++i)
          if (p.group[i] == 0)
            {
              lo = std::min(lo, p.position[i].y());
              hi = std::max(hi, p.position[i].y());
            }
        return hi - lo;
      }

      void before_step(MlpWorld &w) override { kick_platens(w.particles, w.time, w.dt); }

      /// Platen distance over its initial value.
      double platen_ratio(const Particles &p) const
      {
        return (p.position[platen[1][0]].x() - p.position[platen[0][0]].x()) / gap0;
      }

      bool finished() const override { return stroke_end; }

      void after_step(MlpWorld &w) override
      {
        Particles   &p  = w.particles;
        const double t = w.time, dt = w.dt;
        kick_platens(p, t, dt);
        stroke_end = platen_ratio(p) < stop_h;
        for (unsigned int k = 0; k < 2; ++k)
          if (arrival[k] < 0 && v_star > 0 && p.velocity[probe_index[k]].x() > v_star / 3)
            arrival[k] = t;
      }

      void measure(const MlpWorld &w, Row &row) override
      {
        const Particles &p = w.particles;
        const double     t = w.time;
        if (next_map < map_times.size() && t >= map_times[next_map] - 1e-15)
          {
            density_snapshot(p, t);
            ++next_map;
          }
        row("delta_h", platen_ratio(p))("delta_w", slab_height(p) / extent0[1])("pressure", current)
          ("probe1_vx", p.velocity[probe_index[0]].x())("probe2_vx", p.velocity[probe_index[1]].x());
      }

      /// Gaussian density map relative to the ideal lattice's mean pi lambda / A_p
      /// (1 = ideal packing), on nodes r0/2 apart (at most 400 per side) covering the
      /// particles plus 2 r0, and
      /// the histogram (50 bins on [0, 2]) of its value at the node nearest each particle.
      void density_snapshot(const Particles &p, double t)
      {
        const double c = s.interaction.r0;
        Vec2 lo = p.position[0], hi = p.position[0];
        for (const Vec2 &x : p.position)
          {
            lo = lo.cwiseMin(x);
            hi = hi.cwiseMax(x);
          }
        lo -= Vec2(2 * c, 2 * c);
        hi += Vec2(2 * c, 2 * c);
        // Nodes r0/2 apart, at most 400 per side (a body that flew apart gets a coarser map).
        const double       step = std::max({0.5 * c, (hi.x() - lo.x()) / 399, (hi.y() - lo.y()) / 399});
        const unsigned int gx   = static_cast<unsigned int>((hi.x() - lo.x()) / step) + 1;
        const unsigned int gy   = static_cast<unsigned int>((hi.y() - lo.y()) / step) + 1;
        const auto   g     = mlp::gaussian_density(p, lo, hi, gx, gy, lambda);
        const double ideal = M_PI * lambda / mlp::area_per_particle(s.lattice, c);
        const double k     = map_count;
        for (unsigned int b = 0; b < g.ny; ++b)
          for (unsigned int a = 0; a < g.nx; ++a)
            maps_table.add_row({k, t, g.x0 + a * g.dx, g.y0 + b * g.dy, g(a, b) / ideal});
        std::vector<double> bins(50, 0.0);
        double mean = 0, sq = 0;
        for (const Vec2 &x : p.position)
          {
            const unsigned int a = std::min(g.nx - 1, static_cast<unsigned int>(std::lround((x.x() - g.x0) / g.dx)));
            const unsigned int b = std::min(g.ny - 1, static_cast<unsigned int>(std::lround((x.y() - g.y0) / g.dy)));
            const double rel = g(a, b) / ideal;
            mean += rel;
            sq += rel * rel;
            bins[std::min<std::size_t>(49, static_cast<std::size_t>(std::max(0.0, rel) / 0.04))] += 1.0 / p.size();
          }
        mean /= p.size();
        for (unsigned int i = 0; i < bins.size(); ++i)
          histogram_table.add_row({k, t, 0.04 * (i + 0.5), bins[i]});
        snapshot_stats.add_row({k, t, mean, std::sqrt(std::max(0.0, sq / p.size() - mean * mean))});
        ++map_count;
      }

      void summarize(const MlpWorld &w, const TimeSeries &stats, JsonObject &results) override
      {
        const Particles &p      = w.particles;
        const double     t      = w.time;
        auto            &tables = made_tables;
        if (map_count < maps)
          density_snapshot(p, t); // the last map at the final time, if the run stopped early
        const auto   dh    = stats.column("delta_h");
        const auto   times = stats.column("time");
        double              lowest = 1;
        std::vector<double> late;
        for (std::size_t i = 0; i < dh.size(); ++i)
          {
            lowest = std::min(lowest, dh[i]);
            if (times[i] >= 0.7 * t)
              late.push_back(dh[i]);
          }
        const std::vector<double> late_batches = batch_means(late);
        const double strain = youngs > 0 ? pressure / youngs : 0.0;
        results.set("youngs_modulus_theory", youngs);
        results.set("elastic_strain", strain);
        results.set("delta_h_elastic", 1 - strain);
        results.set("delta_h_min", lowest);
        results.set("delta_h_late_mean",
                    late.empty() ? dh.back() : std::accumulate(late.begin(), late.end(), 0.0) / late.size());
        results.set("delta_h_late_stderr", batch_standard_error(late_batches));
        results.set("delta_h_final", dh.back());
        results.set("stopped_by_stroke", stroke_end);
        results.set("longitudinal_speed_theory", c_l);
        results.set("probe_distance", probe_x[1] - probe_x[0]);
        results.set("probe1_arrival", arrival[0]);
        results.set("probe2_arrival", arrival[1]);
        if (arrival[0] >= 0 && arrival[1] > arrival[0])
          {
            const double c = (probe_x[1] - probe_x[0]) / (arrival[1] - arrival[0]);
            results.set("wave_speed", c);
            results.set("wave_speed_over_theory", c / c_l);
          }
        if (maps_table.rows().size())
          {
            tables["density_maps"]       = maps_table;
            tables["density_histograms"] = histogram_table;
            tables["density_snapshots"]  = snapshot_stats;
          }
      }

      /// The platens' load and velocities, the wave arrivals, the stroke flag and the
      /// density maps so far.
      void save(CheckpointOut &ar) const override
      {
        ar << current << platen_velocity << arrival << stroke_end << map_count << next_map;
        maps_table.save(ar);
        histogram_table.save(ar);
        snapshot_stats.save(ar);
      }
      void load(CheckpointIn &ar) override
      {
        ar >> current >> platen_velocity >> arrival >> stroke_end >> map_count >> next_map;
        maps_table.load(ar);
        histogram_table.load(ar);
        snapshot_stats.load(ar);
      }

    private:
      CommonSettings s;
      unsigned int   nx = 0, ny = 0, maps = 0, map_count = 0;
      std::size_t    next_map = 0;
      double         pressure = 0, rise = 0, lambda = 0, h_row = 0, current = 0;
      double         youngs = 0, c_l = 0, v_star = 0, platen_velocity[2] = {0, 0};
      double         probe[2] = {0.1, 0.4}, probe_x[2] = {0, 0}, arrival[2] = {-1, -1};
      double         extent0[2] = {1, 1};
      unsigned int   probe_index[2] = {0, 0};
      std::vector<unsigned int> platen[2];
      double         gap0 = 1, stop_h = 0.3;
      bool           stroke_end = false;
      std::vector<double> map_times;
      TimeSeries maps_table{{"snapshot", "time", "x", "y", "relative_density"}};
      TimeSeries histogram_table{{"snapshot", "time", "relative_density", "fraction"}};
      TimeSeries snapshot_stats{{"snapshot", "time", "mean_relative_density", "std_relative_density"}};
    };

    /// The scene, its subsection "MLP compression" read.
    std::unique_ptr<MlpScene> make_scene(const ParameterFile &f, const CommonSettings &s)
    {
      auto scene = std::make_unique<CompressionScene>(f, s);
      scene->set_end_time(s.end_time);
      return scene;
    }
  } // namespace

  void declare_mlp_compression_parameters(dealii::ParameterHandler &prm)
  {
    using dealii::Patterns::Double;
    using dealii::Patterns::Integer;
    prm.enter_subsection("MLP compression");
    prm.declare_entry("Columns", "40", Integer(4), "Particles per row (along x, the load), >= 4.");
    prm.declare_entry("Rows", "20", Integer(2), "Rows (along y), >= 2.");
    prm.declare_entry("Pressure", "1e8", Double(), "Traction P on the left and right boundaries, Pa (>= 0), compressive.");
    prm.declare_entry("Load rise time", "0", Double(), "P rises linearly over this time, s (>= 0; 0: a step).");
    prm.declare_entry("Stop at delta_h", "0.3", Double(),
                      "End the run (complete) once the platen distance falls below this fraction of its initial value, [0, 1).");
    prm.declare_entry("Density maps", "4", Integer(0), "Gaussian density maps and histograms, evenly spaced in time from t = 0 (>= 0).");
    prm.declare_entry("Gaussian width", "1", Double(), "lambda of eq. (22) over r0^2 (> 0).");
    prm.declare_entry("First probe", "0.1", Double(), "Wave probe, fraction of the slab length from the left boundary, [0, 0.5).");
    prm.declare_entry("Second probe", "0.4", Double(), "Second wave probe, fraction of the length, (First probe, 0.5].");
    prm.leave_subsection();
  }

  SceneHooks mlp_compression_hooks()
  {
    return mlp_scenes::hooks<make_scene>(declare_mlp_compression_parameters);
  }
} // namespace tribo::app
