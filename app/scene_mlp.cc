/// @file The movable-lattice-particle scenes (Popov and Filippov 2006, section 5):
/// mlp_ordering (random start -> lattice, Fig. 2), mlp_compression (slab pressed on its
/// left and right boundaries: elastic or plastic, Figs. 3-5, and the compression wave),
/// mlp_beams (two beams pressed together and rubbed: the "liquid layer", Fig. 6).
/// Each runs its own Langevin loop (mlp/langevin.h) and writes statistics.csv,
/// summary.json, results.h5, scene tables (CSV), fields/particles_NNNNN.vtu with
/// fields/particles.pvd, and log lines (docs/outputs.md, section MLP).
///
/// Units: 2D, per unit depth (masses kg/m, forces N/m, pressures and moduli Pa = N/m^2,
/// energies J/m). x is the axis of the loads (left-right), y the transverse axis.

#include "app/particle_scenes.h"
#include "core/errors.h"
#include "core/output.h"
#include "core/run_control.h"
#include "core/serialization.h"
#include "mlp/analysis.h"
#include "mlp/interaction.h"
#include "mlp/langevin.h"
#include "mlp/linear_theory.h"
#include "mlp/particles.h"

#include <deal.II/base/data_out_base.h>

#include <boost/property_tree/json_parser.hpp>
#include <boost/property_tree/ptree.hpp>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <complex>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <sstream>

namespace tribo::app
{
  namespace
  {
    using mlp::Particles;
    using mlp::Vec2;
    using dealii::Patterns::Bool;
    using dealii::Patterns::Double;
    using dealii::Patterns::Integer;
    using dealii::Patterns::Selection;

    // ------------------------------------------------------------------ settings

    /// Settings shared by all MLP scenes (subsection "MLP").
    struct CommonSettings
    {
      mlp::LatticeType            lattice = mlp::LatticeType::hexagonal;
      mlp::InteractionParameters  interaction;
      mlp::LangevinParameters     langevin;
      double                      mass     = 0; ///< kg/m
      double                      end_time = 0; ///< s
      unsigned int                statistics_interval = 1, snapshot_interval = 0;
      bool                        plots  = true;
      bool                        mapped = false; ///< k_c and f0 from (E, nu)
    };

    /// A double entry that must satisfy @p ok (InputError naming the entry otherwise).
    template <typename Check>
    double checked(const ParameterFile &f, const std::string &path, Check ok,
                   const std::string &expected)
    {
      return f.get_checked(path, ok, expected);
    }

    /// A non-negative integer entry of at least @p min.
    unsigned int count(const ParameterFile &f, const std::string &path, long min)
    {
      const long v = f.get_integer(path);
      if (v < min)
        f.fail(path, "an integer >= " + std::to_string(min));
      return static_cast<unsigned int>(v);
    }

    const auto positive     = [](double v) { return v > 0; };
    const auto non_negative = [](double v) { return v >= 0; };

    /// Reads subsection "MLP" (common to the scenes) and Simulation/End time. The (E, nu) mapping wins over
    /// Pair stiffness and Return force amplitude when Young's modulus > 0.
    CommonSettings read_common(const ParameterFile &f)
    {
      CommonSettings s;
      s.lattice = f.get("MLP/Lattice") == "square" ? mlp::LatticeType::square
                                                  : mlp::LatticeType::hexagonal;
      auto &ip  = s.interaction;
      ip.n      = mlp::symmetry_order(s.lattice);
      ip.r0     = checked(f, "MLP/Spacing", positive, "a positive spacing r0 in m");
      s.mass    = checked(f, "MLP/Particle mass", positive, "a positive mass in kg/m");
      ip.stiffness = checked(f, "MLP/Pair stiffness", positive, "a positive k_c = U''(r0) in N/m^2");
      ip.f0     = checked(f, "MLP/Return force amplitude", non_negative, "f0 >= 0 in N/m");
      ip.width  = checked(f, "MLP/Well width", [](double v) { return v >= 1 && v <= 30; },
                         "a Morse width a r0 in [1, 30], e.g. 7");
      ip.form   = f.get("MLP/Return force form") == "potential" ? mlp::ReturnForceForm::potential
                                                               : mlp::ReturnForceForm::paper;
      const double E = checked(f, "MLP/Young's modulus", non_negative,
                               "a 2D Young's modulus >= 0 in Pa (0: use Pair stiffness and Return force amplitude)");
      if (E > 0)
        {
          if (s.lattice != mlp::LatticeType::hexagonal)
            f.fail("MLP/Young's modulus", "0 for a square lattice (the (E, nu) mapping is for the "
                                          "hexagonal lattice; set Pair stiffness and Return force amplitude)");
          const double nu = f.get_double("MLP/Poisson ratio");
          if (!(nu > -1 && nu <= 1.0 / 3.0))
            f.fail("MLP/Poisson ratio", "a 2D Poisson ratio in (-1, 1/3] (return forces only lower "
                                        "nu below the central-force 1/3), e.g. 0.2");
          const auto m = mlp::hexagonal_model_for(E, nu, ip.r0);
          ip.stiffness = m.stiffness;
          ip.f0        = m.f0;
          s.mapped     = true;
        }
      try
        {
          ip.validate();
        }
      catch (const InputError &e)
        {
          throw InputError(f.filename() + ": subsection MLP: " + e.what());
        }
      auto &lp          = s.langevin;
      lp.damping        = checked(f, "MLP/Damping", non_negative, "eta >= 0 in kg/(m s)");
      lp.thermal_energy = checked(f, "MLP/Thermal energy", non_negative, "k_B T >= 0 in J/m");
      lp.time_step      = checked(f, "MLP/Time step", non_negative, "a time step >= 0 in s (0: half the stable limit)");
      lp.seed           = count(f, "MLP/Seed", 0);
      s.end_time        = checked(f, "Simulation/End time", positive, "a positive end time in s");
      s.statistics_interval = count(f, "MLP/Statistics interval", 1);
      s.snapshot_interval   = count(f, "MLP/Snapshot interval", 0);
      s.plots               = f.get_bool("Output/Plots");
      return s;
    }

    /// Mass density of the ideal lattice, rho = m / area per particle, kg/m^3.
    double lattice_density(const CommonSettings &s)
    {
      return s.mass / mlp::area_per_particle(s.lattice, s.interaction.r0);
    }

    /// Linear theory of the configured lattice along x: 2D Young's modulus E (Pa, uniaxial
    /// stress with free lateral faces) and longitudinal speed c_L (m/s, plane wave).
    /// Hexagonal: mlp::hexagonal_elasticity with k1 = k_t, k2 = k_c - k_t (isotropic).
    /// Square along an axis: E = C11 - C12^2/C11 = k_c, c_L = sqrt(k_c/rho).
    std::pair<double, double> axial_theory(const CommonSettings &s)
    {
      const auto  &ip  = s.interaction;
      const double k_t = ip.n * ip.f0 / ip.r0;
      if (s.lattice == mlp::LatticeType::hexagonal)
        {
          const auto e = mlp::hexagonal_elasticity(k_t, ip.stiffness - k_t, ip.r0, s.mass);
          return {e.youngs_modulus, e.longitudinal_speed};
        }
      return {ip.stiffness, std::sqrt(ip.stiffness / lattice_density(s))};
    }

    // ------------------------------------------------------------------ helpers

    /// Per particle, from the pairs of the current neighbour list: @p net = |sum_j F_ret,ij|
    /// (the paper's eq. 24, N/m) and @p bond = mean over its bonds (r < r_c) of |F_ret,ij|
    /// (N/m; 0 for a particle without bonds). F_ret is Interaction::return_force, the
    /// force on i; in a homogeneously strained lattice the net value cancels, the bond
    /// mean measures the rotation of the bonds from the lattice axes.
    void return_force_magnitudes(const mlp::ForceField &field, const Particles &p,
                                 const mlp::Box &box, std::vector<double> &net,
                                 std::vector<double> &bond)
    {
      const unsigned int n = p.size();
      std::vector<Vec2>  sum(n, Vec2::Zero());
      std::vector<unsigned int> bonds(n, 0);
      bond.assign(n, 0.0);
      const double rc = field.interaction().cutoff();
      for (const auto &[i, j] : field.neighbours().pairs())
        {
          const Vec2 d = box.minimum_image(p.position[j] - p.position[i]);
          if (d.norm() >= rc)
            continue;
          const Vec2   f = field.interaction().return_force(d);
          const double a = f.norm();
          sum[i] += f;
          sum[j] -= f;
          bond[i] += a;
          bond[j] += a;
          ++bonds[i];
          ++bonds[j];
        }
      net.resize(n);
      for (unsigned int i = 0; i < n; ++i)
        {
          net[i] = sum[i].norm();
          bond[i] = bonds[i] ? bond[i] / bonds[i] : 0.0;
        }
    }

    /// Mean number of bonds (pairs closer than r_c) per particle, 2 n_bonds / N.
    double mean_coordination(const mlp::ForceField &field, const Particles &p, const mlp::Box &box)
    {
      const double rc = field.interaction().cutoff();
      unsigned long bonds = 0;
      for (const auto &[i, j] : field.neighbours().pairs())
        if (box.minimum_image(p.position[j] - p.position[i]).norm() < rc)
          ++bonds;
      return p.size() ? 2.0 * bonds / p.size() : 0.0;
    }

    /// Writes the snapshot fields/particles_NNNNN.vtu at time @p t (s), one vertex per
    /// particle with point data velocity (m/s), group, force magnitude |F| (N/m), net and
    /// bond-mean |F_return| (N/m), and adds it to the index particles.pvd of @p fields.
    void write_particles(FieldWriter &fields, double t, const Particles &p,
                         const std::vector<double> &ret_net, const std::vector<double> &ret_bond)
    {
      std::vector<dealii::DataOutBase::Patch<0, 2>> patches(p.size());
      for (unsigned int i = 0; i < p.size(); ++i)
        {
          auto &patch       = patches[i];
          patch.vertices[0] = dealii::Point<2>(p.position[i].x(), p.position[i].y());
          patch.patch_index = i;
          patch.data.reinit(6, 1);
          patch.data(0, 0) = p.velocity[i].x();
          patch.data(1, 0) = p.velocity[i].y();
          patch.data(2, 0) = p.group[i];
          patch.data(3, 0) = p.force[i].norm();
          patch.data(4, 0) = ret_net[i];
          patch.data(5, 0) = ret_bond[i];
        }
      const std::vector<std::string> names = {"velocity", "velocity", "group", "force",
                                              "return_force_net", "return_force_bond"};
      const std::vector<std::tuple<unsigned int, unsigned int, std::string,
                                   dealii::DataComponentInterpretation::DataComponentInterpretation>>
        ranges = {{0, 1, "velocity", dealii::DataComponentInterpretation::component_is_part_of_vector}};
      dealii::DataOutBase::VtkFlags flags;
      flags.compression_level = dealii::DataOutBase::VtkFlags::best_speed;
      std::ostringstream os;
      dealii::DataOutBase::write_vtu(patches, names, ranges, flags, os);
      char name[40];
      std::snprintf(name, sizeof name, "particles_%05u.vtu", fields.n_indexed("particles"));
      atomic_write(fields.directory() + "/" + name, os.str());
      fields.index("particles", t, name);
    }

    // ------------------------------------------------------------------ scenes

    /// What an MLP scene adds to MlpSimulation, the family's part of the time loop.
    class MlpScene
    {
    public:
      virtual ~MlpScene() = default;
      /// Places the particles and sets the box.
      virtual void build(Particles &p, mlp::Box &box) = 0;
      /// Called once the force field exists, before the first step (e.g. relaxation).
      virtual void prepare(Particles &, const mlp::Box &, mlp::ForceField &, Log &) {}
      /// Sets the external forces for time @p t (s), before the step that ends at t.
      virtual void set_loads(Particles &, double /*t*/) {}
      /// Before the step from @p t to t + @p dt (s), after set_loads(t + dt).
      virtual void before_step(Particles &, double /*t*/, double /*dt*/) {}
      /// After every step, at time @p t (s): per-step updates and measurements.
      virtual void after_step(Particles &, double /*t*/, double /*dt*/) {}
      /// True when the scene has reached its own end (the run stops, complete).
      virtual bool finished() const { return false; }
      /// The scene's statistics columns at time @p t as (name, value) pairs (measurements
      /// due at t are taken here: a row is due).
      virtual void measure(const Particles &p, const mlp::Box &box, const mlp::ForceField &field, double t,
                           Row &row) = 0;
      /// Scene results (summary.json "results") and tables (CSV and results.h5 groups).
      virtual void finish(const Particles &p, const mlp::Box &box, const mlp::ForceField &field,
                          const TimeSeries &stats, double t, JsonObject &results,
                          std::map<std::string, TimeSeries> &tables) = 0;
      /// Checkpoint: what the scene carries from step to step (loads, accumulators, tables
      /// so far); what build() makes is rebuilt with the scene. Default: nothing.
      virtual void save(CheckpointOut &) const {}
      virtual void load(CheckpointIn &) {}
    };

    /// mlp_ordering: N particles at random positions (no two closer than d_min) in a
    /// rectangle `Region enlargement` times the ideal packing area, open boundaries, a
    /// capped steepest descent removing the worst overlaps (x += min(|F|/k_c, 0.02 r0)
    /// F/|F| per iteration), then Langevin dynamics at low temperature. Result: the
    /// structure factor S(q) = |sum_k exp(-i q.x_k)|^2 / N (FT of the two-point density
    /// correlation, eqs. 19-21) on a grid, and its angular harmonics on the Bragg ring.
    class OrderingScene : public MlpScene
    {
    public:
      OrderingScene(const ParameterFile &f, const CommonSettings &c) : s(c)
      {
        n_particles   = count(f, "MLP ordering/Particles", 2);
        enlargement   = checked(f, "MLP ordering/Region enlargement", [](double v) { return v >= 1 && v <= 4; },
                                "a factor in [1, 4], e.g. 1.2");
        aspect        = checked(f, "MLP ordering/Aspect ratio", positive, "a positive width/height ratio");
        min_distance  = checked(f, "MLP ordering/Minimum distance", [](double v) { return v > 0 && v < 1; },
                                "a fraction of r0 in (0, 1), e.g. 0.75") * s.interaction.r0;
        relaxation    = count(f, "MLP ordering/Relaxation iterations", 0);
        grid          = count(f, "MLP ordering/Structure factor points", 11) | 1u;
        q_range       = checked(f, "MLP ordering/Structure factor range", [](double v) { return v > 1.2; },
                                "a multiple > 1.2 of the first Bragg wave number, e.g. 1.6");
      }

      void build(Particles &p, mlp::Box &box) override
      {
        box = mlp::Box();
        const Vec2 size = mlp::random_region_size(s.lattice, n_particles, s.interaction.r0, aspect, enlargement);
        mlp::add_random_particles(p, Vec2::Zero(), size, n_particles, min_distance, s.mass, s.langevin.seed);
      }

      void prepare(Particles &p, const mlp::Box &box, mlp::ForceField &field, Log &log) override
      {
        const double cap = 0.02 * s.interaction.r0;
        for (unsigned int k = 0; k < relaxation; ++k)
          {
            field.compute(p, box);
            for (unsigned int i = 0; i < p.size(); ++i)
              {
                const double f = p.force[i].norm();
                if (f > 0)
                  p.position[i] += std::min(f / s.interaction.stiffness, cap) / f * p.force[i];
              }
          }
        log("mlp_ordering: " + std::to_string(p.size()) + " random particles, " +
            std::to_string(relaxation) + " capped relaxation iterations");
      }

      void measure(const Particles &p, const mlp::Box &, const mlp::ForceField &, double, Row &row) override
      {
        row("extent_x", mlp::extent(p, 0))("extent_y", mlp::extent(p, 1));
      }

      /// Bragg wave number of the first shell, 1/m: 4 pi/(sqrt(3) c) hexagonal, 2 pi/c square.
      double bragg() const
      {
        const double c = s.interaction.r0;
        return s.lattice == mlp::LatticeType::hexagonal ? 4 * M_PI / (std::sqrt(3.0) * c) : 2 * M_PI / c;
      }

      void finish(const Particles &p, const mlp::Box &box, const mlp::ForceField &field,
                  const TimeSeries &, double, JsonObject &results,
                  std::map<std::string, TimeSeries> &tables) override
      {
        const double q_b = bragg();
        const auto   S   = mlp::structure_factor(p, q_range * q_b, grid);
        TimeSeries   table({"qx", "qy", "S"});
        // Angular harmonics A_m = |sum S e^{i m theta}| / sum S over the ring
        // 0.85 q_B < |q| < 1.15 q_B: 1 for m-fold delta peaks, 0 for a uniform ring.
        std::complex<double> h4 = 0, h6 = 0;
        double               ring = 0;
        for (unsigned int b = 0; b < S.ny; ++b)
          for (unsigned int a = 0; a < S.nx; ++a)
            {
              const double qx = S.x0 + a * S.dx, qy = S.y0 + b * S.dy, v = S(a, b);
              table.add_row({qx, qy, v});
              const double q = std::hypot(qx, qy) / q_b;
              if (q > 0.85 && q < 1.15)
                {
                  const double th = std::atan2(qy, qx);
                  h4 += v * std::polar(1.0, 4 * th);
                  h6 += v * std::polar(1.0, 6 * th);
                  ring += v;
                }
            }
        tables["structure_factor"] = table;
        results.set("bragg_wave_number", q_b);
        results.set("harmonic_4", ring > 0 ? std::abs(h4) / ring : 0.0);
        results.set("harmonic_6", ring > 0 ? std::abs(h6) / ring : 0.0);
        results.set("mean_coordination", mean_coordination(field, p, box));
        results.set("n_particles", long(p.size()));
      }

    private:
      CommonSettings s;
      unsigned int   n_particles = 0, relaxation = 0, grid = 0;
      double         enlargement = 1, aspect = 1, min_distance = 0, q_range = 1.6;
    };

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
        pressure = checked(f, "MLP compression/Pressure", non_negative, "a pressure >= 0 in Pa");
        rise     = checked(f, "MLP compression/Load rise time", non_negative, "a time >= 0 in s");
        maps     = count(f, "MLP compression/Density maps", 0);
        lambda   = checked(f, "MLP compression/Gaussian width", positive, "a positive lambda / r0^2, e.g. 1")
                   * s.interaction.r0 * s.interaction.r0;
        stop_h   = checked(f, "MLP compression/Stop at delta_h", [](double v) { return v >= 0 && v < 1; },
                           "a fraction of the initial platen distance in [0, 1), e.g. 0.3");
        probe[0] = checked(f, "MLP compression/First probe", [](double v) { return v >= 0 && v < 0.5; },
                           "a fraction of the slab length in [0, 0.5), e.g. 0.1");
        probe[1] = checked(f, "MLP compression/Second probe", [&](double v) { return v > probe[0] && v <= 0.5; },
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

      void before_step(Particles &p, double t, double dt) override { kick_platens(p, t, dt); }

      /// Platen distance over its initial value.
      double platen_ratio(const Particles &p) const
      {
        return (p.position[platen[1][0]].x() - p.position[platen[0][0]].x()) / gap0;
      }

      bool finished() const override { return stroke_end; }

      void after_step(Particles &p, double t, double dt) override
      {
        kick_platens(p, t, dt);
        stroke_end = platen_ratio(p) < stop_h;
        for (unsigned int k = 0; k < 2; ++k)
          if (arrival[k] < 0 && v_star > 0 && p.velocity[probe_index[k]].x() > v_star / 3)
            arrival[k] = t;
      }

      void measure(const Particles &p, const mlp::Box &, const mlp::ForceField &, double t, Row &row) override
      {
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

      void finish(const Particles &p, const mlp::Box &, const mlp::ForceField &,
                  const TimeSeries &stats, double t, JsonObject &results,
                  std::map<std::string, TimeSeries> &tables) override
      {
        if (map_count < maps)
          density_snapshot(p, t); // the last map at the final time, if the run stopped early
        const auto   dh    = stats.column("delta_h");
        const auto   times = stats.column("time");
        double       lowest = 1, late = 0;
        unsigned int n_late = 0;
        for (std::size_t i = 0; i < dh.size(); ++i)
          {
            lowest = std::min(lowest, dh[i]);
            if (times[i] >= 0.7 * t)
              {
                late += dh[i];
                ++n_late;
              }
          }
        const double strain = youngs > 0 ? pressure / youngs : 0.0;
        results.set("youngs_modulus_theory", youngs);
        results.set("elastic_strain", strain);
        results.set("delta_h_elastic", 1 - strain);
        results.set("delta_h_min", lowest);
        results.set("delta_h_late_mean", n_late ? late / n_late : dh.back());
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

    /// mlp_beams: two lattice beams stacked along y in a box periodic along x (beams of
    /// infinite length) and y (a gap of 3 r0 across the y-period, beyond the interaction
    /// range, so that the beams touch only at their contact). The contact plane is
    /// horizontal, a row plane of the lattice (for the hexagonal lattice the close-packed
    /// plane, its easy slip plane); the paper's profile "along x, orthogonal to the
    /// contact" is our profile along y. The upper beam is shifted along x by `Interface
    /// offset` r0 from the natural stacking (a stacking fault at the contact). The outer
    /// row of each beam carries the pressing load +-P r0 along y (lower beam up, upper
    /// beam down); the transverse load, total +-tau L_x sin(2 pi f t) per beam along x
    /// (lower +, upper -), acts on every particle of the beam (+-tau r0 / ny: a body
    /// force, shear stress rising from 0 at the outer row to tau at the contact) or on
    /// the outer row (+-tau r0 per particle: uniform shear stress tau).
    /// Profile: mean |F_return| in layers along y (eq. 24, averaged over x and over time
    /// after Profile start).
    class BeamsScene : public MlpScene
    {
    public:
      BeamsScene(const ParameterFile &f, const CommonSettings &c) : s(c)
      {
        nx        = count(f, "MLP beams/Columns", 4);
        ny        = count(f, "MLP beams/Rows per beam", 2);
        pressure  = checked(f, "MLP beams/Pressure", non_negative, "a pressure >= 0 in Pa");
        tau       = checked(f, "MLP beams/Transverse traction", non_negative, "a traction amplitude >= 0 in Pa");
        freq      = checked(f, "MLP beams/Frequency", positive, "a positive frequency in Hz");
        offset    = checked(f, "MLP beams/Interface offset", [](double v) { return v >= 0 && v < 1; },
                            "a fraction of r0 in [0, 1)");
        start     = checked(f, "MLP beams/Profile start", non_negative, "a time >= 0 in s");
        layer     = checked(f, "MLP beams/Layer thickness", positive,
                            "a positive thickness in row spacings, e.g. 1"); // times h_row in build()
        body_load = f.get("MLP beams/Transverse load on") == "body";
      }

      void build(Particles &p, mlp::Box &box) override
      {
        const double c  = s.interaction.r0;
        const bool   hx = s.lattice == mlp::LatticeType::hexagonal;
        h_row           = hx ? 0.5 * std::sqrt(3.0) * c : c;
        layer *= h_row;
        box.periodic_x = box.periodic_y = true;
        box.lx         = nx * c;
        box.ly         = (2 * ny - 1) * h_row + 3 * c;
        const Vec2 lower(0.25 * c, 1.5 * c);
        mlp::add_lattice_patch(p, s.lattice, lower, nx, ny, c, s.mass, 0);
        // Natural stacking: row ny of one lattice is shifted by c/2 if ny is odd (hexagonal).
        const double natural = (hx && ny % 2 == 1) ? 0.5 * c : 0.0;
        mlp::add_lattice_patch(p, s.lattice, lower + Vec2(natural + offset * c, ny * h_row), nx, ny, c,
                               s.mass, 1);
        for (auto &x : p.position)
          x = box.wrap(x);
        contact_y = lower.y() + (ny - 0.5) * h_row;
        bins      = static_cast<unsigned int>(std::ceil(box.ly / layer));
        sum_net.assign(bins, 0.0);
        sum_bond.assign(bins, 0.0);
        samples.assign(bins, 0.0);
        for (unsigned int b = 0; b < 2; ++b)
          beam_y0[b] = mean_y(p, b);
      }

      /// Mean y of beam @p b (m); the beams do not cross the y-period.
      static double mean_y(const Particles &p, unsigned int b)
      {
        double       sum = 0;
        unsigned int n   = 0;
        for (unsigned int i = 0; i < p.size(); ++i)
          if (p.group[i] == b)
            {
              sum += p.position[i].y();
              ++n;
            }
        return sum / n;
      }

      void set_loads(Particles &p, double t) override
      {
        const double c = s.interaction.r0;
        forcing        = tau * std::sin(2 * M_PI * freq * t);
        const double fx = body_load ? forcing * c / ny : 0.0;
        for (unsigned int i = 0; i < p.size(); ++i)
          p.external_force[i] = Vec2(p.group[i] == 0 ? fx : -fx, 0);
        const double outer = body_load ? 0.0 : forcing * c;
        for (unsigned int i = 0; i < nx; ++i)
          {
            p.external_force[i] += Vec2(outer, pressure * c);                            // lower beam, row 0
            p.external_force[2 * nx * ny - nx + i] += Vec2(-outer, -pressure * c);       // upper beam, top row
          }
      }

      void after_step(Particles &p, double, double dt) override
      {
        // Mean x displacement of each beam, by integrating its mean velocity (the
        // positions wrap along x).
        double v[2] = {0, 0};
        for (unsigned int i = 0; i < p.size(); ++i)
          v[p.group[i]] += p.velocity[i].x();
        for (unsigned int b = 0; b < 2; ++b)
          displacement[b] += dt * v[b] / (nx * ny);
      }

      void measure(const Particles &p, const mlp::Box &box, const mlp::ForceField &field, double t,
                   Row &row) override
      {
        if (t >= start)
          sample_profile(p, box, field);
        row("transverse_traction", forcing)("slip", displacement[0] - displacement[1])
          ("beam_gap_change", (mean_y(p, 1) - mean_y(p, 0)) - (beam_y0[1] - beam_y0[0]))
          ("coordination", mean_coordination(field, p, box));
      }

      /// Adds the per-particle |F_return| (net and bond mean) to the layer of each particle.
      void sample_profile(const Particles &p, const mlp::Box &box, const mlp::ForceField &field)
      {
        std::vector<double> net, bond;
        return_force_magnitudes(field, p, box, net, bond);
        for (unsigned int i = 0; i < p.size(); ++i)
          {
            const unsigned int b = std::min(bins - 1, static_cast<unsigned int>(p.position[i].y() / layer));
            sum_net[b] += net[i];
            sum_bond[b] += bond[i];
            samples[b] += 1;
          }
      }

      /// Mean of @p sum over the layers whose centre is within @p half of @p y0 (m).
      double window(const std::vector<double> &sum, double y0, double half) const
      {
        double v = 0, n = 0;
        for (unsigned int b = 0; b < bins; ++b)
          if (std::abs((b + 0.5) * layer - y0) <= half)
            {
              v += sum[b];
              n += samples[b];
            }
        return n > 0 ? v / n : 0.0;
      }

      void finish(const Particles &, const mlp::Box &, const mlp::ForceField &, const TimeSeries &stats,
                  double, JsonObject &results, std::map<std::string, TimeSeries> &tables) override
      {
        TimeSeries profile({"y", "y_from_contact", "f_return_net", "f_return_bond", "n_samples"});
        for (unsigned int b = 0; b < bins; ++b)
          profile.add_row({(b + 0.5) * layer, (b + 0.5) * layer - contact_y,
                           samples[b] ? sum_net[b] / samples[b] : 0.0,
                           samples[b] ? sum_bond[b] / samples[b] : 0.0, samples[b]});
        tables["profiles"] = profile;
        const double half_beam = 0.5 * ny * h_row, w = 1.5 * h_row;
        const double bulk_net  = 0.5 * (window(sum_net, contact_y - half_beam, w) +
                                       window(sum_net, contact_y + half_beam, w));
        const double bulk_bond = 0.5 * (window(sum_bond, contact_y - half_beam, w) +
                                        window(sum_bond, contact_y + half_beam, w));
        const double contact_net  = window(sum_net, contact_y, w);
        const double contact_bond = window(sum_bond, contact_y, w);
        results.set("contact_y", contact_y);
        results.set("f_return_net_contact", contact_net);
        results.set("f_return_net_bulk", bulk_net);
        results.set("f_return_bond_contact", contact_bond);
        results.set("f_return_bond_bulk", bulk_bond);
        results.set("contact_over_bulk_bond", bulk_bond > 0 ? contact_bond / bulk_bond : 0.0);
        results.set("contact_over_bulk_net", bulk_net > 0 ? contact_net / bulk_net : 0.0);
        const auto slip = stats.column("slip");
        double     amp  = 0;
        for (double v : slip)
          amp = std::max(amp, std::abs(v));
        results.set("slip_max", amp);
        results.set("slip_final", slip.back());
      }

      /// The transverse load, the beams' displacements and the profile sums.
      void save(CheckpointOut &ar) const override
      {
        ar << forcing << displacement << sum_net << sum_bond << samples;
      }
      void load(CheckpointIn &ar) override { ar >> forcing >> displacement >> sum_net >> sum_bond >> samples; }

    private:
      CommonSettings s;
      unsigned int   nx = 0, ny = 0, bins = 0;
      bool           body_load = true;
      double pressure = 0, tau = 0, freq = 0, offset = 0, start = 0, layer = 0, h_row = 0;
      double contact_y = 0, forcing = 0, displacement[2] = {0, 0}, beam_y0[2] = {0, 0};
      std::vector<double> sum_net, sum_bond, samples;
    };

    /// Throws RunError if a particle is farther than @p bound (m) from @p centre: a
    /// body flying apart, usually a step too large for the stiffened potential under a
    /// high load (the step guard assumes the ideal lattice), caught before the cell
    /// lists of the neighbour search grow with the spread.
    void check_bounded(const Particles &p, const Vec2 &centre, double bound, double t)
    {
      for (unsigned int i = 0; i < p.size(); ++i)
        if ((p.position[i] - centre).norm() > bound)
          throw RunError("MLP: particle " + std::to_string(i) + " is " +
                         to_text((p.position[i] - centre).norm()) + " m from the centre of the "
                         "initial configuration at t = " + to_text(t) + " s (bound " + to_text(bound) +
                         " m): the system flew apart; lower MLP/Time step (the stable limit "
                         "assumes the ideal lattice; compression stiffens the bonds) or the loads");
    }

    /// The scene named by Simulation/Scene.
    std::unique_ptr<MlpScene> make_mlp_scene(const ParameterFile &f, const CommonSettings &s,
                                             const std::string &name)
    {
      if (name == "mlp_ordering")
        return std::make_unique<OrderingScene>(f, s);
      if (name == "mlp_compression")
        {
          auto scene = std::make_unique<CompressionScene>(f, s);
          scene->set_end_time(s.end_time);
          return scene;
        }
      if (name == "mlp_beams")
        return std::make_unique<BeamsScene>(f, s);
      throw InputError(f.where("Simulation/Scene") + ": entry 'Simulation/Scene' = '" + name +
                       "': expected mlp_ordering, mlp_compression or mlp_beams");
    }

    // ------------------------------------------------------------------ run helpers

    /// The time step: MLP/Time step, or half the stable limit when it is 0. A step above
    /// the limit is an InputError naming the entry, the limit and a step that works.
    mlp::LangevinParameters checked_step(const ParameterFile &f, mlp::ForceField &field,
                                         const Particles &p, mlp::LangevinParameters lp)
    {
      if (lp.time_step == 0)
        {
          lp.time_step = 1e-300;
          mlp::LangevinIntegrator probe(field, p, lp);
          lp.time_step = 0.5 * probe.max_time_step();
          return lp;
        }
      try
        {
          mlp::LangevinIntegrator probe(field, p, lp);
        }
      catch (const InputError &e)
        {
          throw InputError(f.where("MLP/Time step") + ": entry 'MLP/Time step' = '" +
                           f.get("MLP/Time step") + "': " + e.what());
        }
      return lp;
    }
  } // namespace

  void declare_mlp_scene_parameters(dealii::ParameterHandler &prm)
  {
    prm.enter_subsection("MLP");
    prm.declare_entry("Lattice", "hexagonal", Selection("hexagonal|square"),
                      "Lattice symmetry of the return forces: hexagonal (n = 6) or square (n = 4).");
    prm.declare_entry("Spacing", "1e-6", Double(), "Equilibrium distance r0 of the pair potential = lattice spacing c, m (> 0).");
    prm.declare_entry("Particle mass", "6.755e-9", Double(),
                      "Mass per particle per unit depth, kg/m (> 0; 6.755e-9 = 7800 kg/m^3 x (sqrt(3)/2) r0^2 at r0 = 1e-6 m).");
    prm.declare_entry("Pair stiffness", "1e9", Double(), "k_c = U''(r0), N/m^2 (> 0). Ignored when Young's modulus > 0.");
    prm.declare_entry("Return force amplitude", "83.333", Double(),
                      "f0 of the return force f0 sin(n phi), N/m (>= 0); transverse bond stiffness "
                      "k_t = n f0/r0 (83.333 with the defaults: k_t = k_c/2). Ignored when Young's modulus > 0.");
    prm.declare_entry("Young's modulus", "0", Double(),
                      "Target 2D Young's modulus, Pa (>= 0). If > 0 (hexagonal only) it and Poisson ratio set "
                      "Pair stiffness and Return force amplitude through the pure-strain mapping "
                      "(docs/mlp.md) and those two entries are ignored.");
    prm.declare_entry("Poisson ratio", "0.2", Double(), "Target 2D Poisson ratio in (-1, 1/3], used when Young's modulus > 0.");
    prm.declare_entry("Well width", "7", Double(), "Morse a r0 in [1, 30]: larger is a narrower, stiffer-curving well.");
    prm.declare_entry("Return force form", "paper", Selection("paper|potential"),
                      "paper: eq. (18) as published; potential: the conservative variant (r0/r) times it.");
    prm.declare_entry("Damping", "0.005", Double(), "Langevin friction eta, kg/(m s) = N s/m^2 (>= 0); relaxation time m/eta.");
    prm.declare_entry("Thermal energy", "1e-8", Double(),
                      "k_B T per particle and degree of freedom, J/m (>= 0; the Morse depth is k_c/(2 (a)^2), "
                      "1.02e-5 J/m with the defaults).");
    prm.declare_entry("Time step", "0", Double(),
                      "Time step, s (>= 0; 0: half the stable limit 0.5 x 2/omega_max). Simulation/Time step is not used.");
    prm.declare_entry("Seed", "1", Integer(0), "Seed of the noise and of the random initial positions.");
    prm.declare_entry("Statistics interval", "100", Integer(1), "Steps between rows of statistics.csv, >= 1.");
    prm.declare_entry("Snapshot interval", "0", Integer(0),
                      "Steps between VTU snapshots in fields/ (particles.pvd); 0: the first and the last only.");
    prm.leave_subsection();

    // One flat subsection per scene (`tribo params` lists one level of subsections).
    prm.enter_subsection("MLP ordering");
    prm.declare_entry("Particles", "256", Integer(2), "Number of particles (paper: 256).");
    prm.declare_entry("Region enlargement", "1.2", Double(), "Area of the random region over the ideal packing area, in [1, 4].");
    prm.declare_entry("Aspect ratio", "1", Double(), "Width/height of the random region (> 0).");
    prm.declare_entry("Minimum distance", "0.75", Double(), "Smallest initial distance between particles, fraction of r0 in (0, 1).");
    prm.declare_entry("Relaxation iterations", "300", Integer(0),
                      "Capped steepest-descent iterations before the dynamics (step min(|F|/k_c, 0.02 r0)), >= 0.");
    prm.declare_entry("Structure factor points", "121", Integer(11), "Wave vectors per side of the S(q) grid (made odd), >= 11.");
    prm.declare_entry("Structure factor range", "1.6", Double(), "q_max of the grid over the first Bragg wave number (> 1.2).");
    prm.leave_subsection();

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

    prm.enter_subsection("MLP beams");
    prm.declare_entry("Columns", "32", Integer(4), "Particles per row (along x, the periodic contact length), >= 4.");
    prm.declare_entry("Rows per beam", "12", Integer(2), "Rows of each beam (along y, across the contact), >= 2.");
    prm.declare_entry("Pressure", "5e7", Double(), "Pressing traction on the outer rows, Pa (>= 0).");
    prm.declare_entry("Transverse traction", "5e7", Double(), "Amplitude tau of the sinusoidal transverse traction, Pa (>= 0).");
    prm.declare_entry("Transverse load on", "body", Selection("body|outer row"),
                      "Where the transverse traction acts: 'body' (spread over every particle of a beam, "
                      "shear stress largest at the contact) or 'outer row' (uniform shear stress).");
    prm.declare_entry("Frequency", "1e7", Double(), "Frequency f of the transverse traction, Hz (> 0).");
    prm.declare_entry("Interface offset", "0.5", Double(), "x-shift of the upper beam from the natural stacking, fraction of r0 in [0, 1).");
    prm.declare_entry("Profile start", "2e-7", Double(), "Time from which the |F_return| profile is averaged, s (>= 0).");
    prm.declare_entry("Layer thickness", "1", Double(), "Thickness of the profile layers along y, in row spacings (> 0; 1: one row per layer).");
    prm.leave_subsection();
  }

  void check_mlp_scene(const ParameterFile &file)
  {
    Particles      particles;
    mlp::Box       box;
    CommonSettings s     = read_common(file);
    auto           scene = make_mlp_scene(file, s, file.get("Simulation/Scene"));
    scene->build(particles, box);
    mlp::ForceField field(s.interaction);
    checked_step(file, field, particles, s.langevin);
  }

  namespace
  {
    /// An MLP scene as the driver runs it: Langevin steps of MLP/Time step, a statistics
    /// row every Statistics interval steps (the first at t = 0), snapshots every
    /// Snapshot interval steps, and a guard against a body flying apart.
    class MlpSimulation : public Simulation
    {
    public:
      MlpSimulation(const ParameterFile &file, Log &log)
        : s(read_common(file))
        , scene_name(file.get("Simulation/Scene"))
      {
        scene = make_mlp_scene(file, s, scene_name);
        scene->build(particles, box);
        field = std::make_unique<mlp::ForceField>(s.interaction);
        field->set_parallel(false);
        s.langevin = checked_step(file, *field, particles, s.langevin);
        scene->prepare(particles, box, *field, log);
        integrator = std::make_unique<mlp::LangevinIntegrator>(*field, particles, s.langevin);
        dt         = s.langevin.time_step;
        n_steps    = std::max(1L, std::lround(std::ceil(s.end_time / dt - 1e-9)));
        {
          const auto [E, c_l] = axial_theory(s);
          std::ostringstream os;
          os << "scene " << scene_name << ": " << particles.size() << " particles, k_c = "
             << s.interaction.stiffness << " N/m^2, f0 = " << s.interaction.f0 << " N/m"
             << (s.mapped ? " (from Young's modulus and Poisson ratio)" : "") << ", E = " << E
             << " Pa, c_L = " << c_l << " m/s; dt = " << dt << " s (limit "
             << integrator->max_time_step() << " s), " << n_steps << " steps";
          log(os.str());
        }
        // Escape bound: the initial configuration's half diagonal plus 1000 r0.
        Vec2 lo = particles.position[0], hi = lo;
        for (const Vec2 &x : particles.position)
          {
            lo = lo.cwiseMin(x);
            hi = hi.cwiseMax(x);
          }
        centre = 0.5 * (lo + hi);
        bound  = 0.5 * (hi - lo).norm() + 1000 * s.interaction.r0;
        scene->set_loads(particles, 0);
        field->compute(particles, box);
      }

      double time() const override { return step * dt; }
      double end_time() const override { return n_steps * dt; }
      bool   reached_end(unsigned long k) const override { return k >= n_steps; }
      bool   finished() const override { return scene->finished(); }

      void advance(unsigned long k, const std::function<void(const std::string &)> &) override
      {
        scene->set_loads(particles, (k + 1) * dt);
        scene->before_step(particles, k * dt, dt);
        integrator->step(particles, box);
        step = k + 1;
        if (!box.periodic_x)
          check_bounded(particles, centre, bound, time());
        scene->after_step(particles, time(), dt);
      }

      bool row(Row &row) override
      {
        const double ke = particles.kinetic_energy();
        row("kinetic_energy", ke)("kinetic_temperature", ke / particles.size())
          ("n_pairs", double(field->neighbours().pairs().size()));
        scene->measure(particles, box, *field, time(), row);
        return true;
      }
      bool row_at_start() const override { return true; }
      bool row_due(unsigned long k) override { return k % s.statistics_interval == 0; }
      bool snapshot_due(unsigned long k) override
      {
        return s.snapshot_interval > 0 && k % s.snapshot_interval == 0;
      }
      void write_snapshot(FieldWriter &fields) override
      {
        std::vector<double> net, bond;
        return_force_magnitudes(*field, particles, box, net, bond);
        write_particles(fields, time(), particles, net, bond);
      }
      /// A failed run's particles have flown apart (check_bounded): no snapshot of them.
      bool         snapshot_a_failed_state() const override { return false; }
      unsigned int n_snapshots(const FieldWriter &fields) const override { return fields.n_indexed("particles"); }

      std::string resumed_line(unsigned long k) const override
      {
        return "resumed at step " + std::to_string(k) + " (t = " + to_text(time()) + " s) of " +
               std::to_string(n_steps);
      }

      void summarize(const RunEnd &end, JsonObject &summary, RunOutputs &out) override
      {
        scene->finish(particles, box, *field, end.statistics, time(), out.results, out.tables);
        summary.set("time_step", dt);
        summary.set("stable_time_step_limit", integrator->max_time_step());
        summary.set("steps_planned", long(n_steps));
        summary.set("n_particles", long(particles.size()));
        summary.set("pair_stiffness", s.interaction.stiffness);
        summary.set("return_force_amplitude", s.interaction.f0);
        out.scalars["time_step"] = dt;
        if (s.plots)
          out.plot_script = "plot_mlp.py";
        std::ostringstream os;
        os << end.step << " steps in " << end.wall_time << " s";
        out.last_line = os.str();
      }

      // After the step number (the driver's), every object's state in this order.
      void save(CheckpointOut &ar) const override
      {
        particles.save(ar);
        field->save(ar);
        integrator->save(ar);
        scene->save(ar);
      }
      void load(CheckpointIn &ar, unsigned long k) override
      {
        step = k;
        particles.load(ar);
        field->load(ar);
        integrator->load(ar);
        scene->load(ar);
      }

    private:
      CommonSettings                           s;
      std::string                              scene_name;
      Particles                                particles;
      mlp::Box                                 box;
      std::unique_ptr<MlpScene>                scene;
      std::unique_ptr<mlp::ForceField>         field;
      std::unique_ptr<mlp::LangevinIntegrator> integrator;
      double                                   dt = 0, bound = 0;
      Vec2                                     centre;
      unsigned long                            n_steps = 0, step = 0;
    };
  } // namespace

  std::unique_ptr<Simulation> make_mlp_simulation(const ParameterFile &file, Log &log)
  {
    return std::make_unique<MlpSimulation>(file, log);
  }
} // namespace tribo::app
