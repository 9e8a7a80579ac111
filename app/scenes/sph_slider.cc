// The SPH slider scene (sph_slider): the slider block on a substrate of Maveyraud, Benz,
// Ouillon, Sornette and Sornette (1999), an Experiment of the SPH family
// (app/scenes/sph_family.h).
//
// SI units. The vertical axis is the last one (y in 2D, z in 3D); in 2D (plane strain)
// forces are per metre of depth (N/m) and masses kg/m. Boundary forces are those of the
// substrate on the block, upward (repulsive) positive.
#include "app/scene_hooks.h"
#include "app/scenes/sph_family.h"
#include "app/steady_state.h"

#include "core/errors.h"
#include "sph/lattice.h"
#include "sph/solver.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <sstream>

namespace tribo::app
{
  using namespace sph_scenes;

  namespace
  {
    using dealii::Patterns::Anything;
    using dealii::Patterns::Bool;
    using dealii::Patterns::Double;
    using dealii::Patterns::Integer;
    using dealii::Patterns::Selection;
    using sph::Tensor;

    const std::string slider_section = "SPH slider";

    /// Surfaces of the slider experiment (paper's sections 3 and 4).
    enum class Surface
    {
      periodic,       ///< both lattices aligned and of the same spacing
      tilted,         ///< the block's lattice rotated in the x-vertical plane
      twisted,        ///< 3D: the block's lattice rotated about the vertical axis
      incommensurate, ///< block spacing = ratio * substrate spacing
      step,           ///< one-particle step on the substrate beyond x_step
      holes,          ///< a fraction of the substrate's top particles removed
      random_heights, ///< substrate top particles moved vertically, uniform in +/- dz/2
      fractal         ///< self-affine substrate top of fractal dimension D_f, rms dz
    };

    /// Everything the slider scene reads from its subsection.
    struct SliderParameters
    {
      unsigned int          dim = 3;
      sph::Material         material;
      sph::LatticeType      lattice = sph::LatticeType::cubic;
      double                spacing = 0, smoothing_ratio = 1.2;
      std::array<double, 3> block{}, substrate{};
      bool                  periodic = true;
      double                pressure = 0, tau = 0, velocity = 0, slide_start = 0, end_time = 0;
      double                gamma = 0, settling_gamma = 0;
      bool                  damping_to_sliding_velocity = true;
      unsigned int          driven_layers = 1;
      bool                  drive_reset = false; ///< Drive = reset: v_x = V set after each step only
      sph::SolverParameters integration; ///< viscosity, CFL number, step floor, fixed step
      double                stiffness_factor = 1, range_ratio = 1;
      bool                  rest_on_tips = false;
      Surface               surface = Surface::periodic;
      double                angle = 0, ratio = 1, hole_fraction = 0, dz = 0, fractal_dimension = 2.5;
      double                step_position = 0;
      std::uint64_t         seed = 1;
      unsigned int          regions = 4;
      double                statistics_interval = 0, field_interval = 0, averaging_fraction = 0.5;
    };

    /// Reads and checks the subsection "SPH slider" (and Simulation/End time).
    SliderParameters read_slider(EntryReader &r)
    {
      const std::string s = slider_section + "/";
      SliderParameters  p;
      p.dim      = static_cast<unsigned int>(std::stoi(r.text(s + "Dimension")));
      p.material = material_named(r.text(s + "Material"));
      p.lattice  = r.text(s + "Lattice") == "hcp" ? sph::LatticeType::hexagonal : sph::LatticeType::cubic;
      p.spacing  = r.number(s + "Particle spacing", is_positive, "a positive particle spacing in m");
      p.smoothing_ratio = r.number(s + "Smoothing length ratio", [](double v) { return v >= 1 && v <= 2; },
                                   "a ratio h/a in [1, 2]");
      p.block     = r.lengths(s + "Block size");
      p.substrate = r.lengths(s + "Substrate size");
      p.periodic  = r.text(s + "Periodic") == "true";
      p.pressure  = r.number(s + "Pressure", is_positive, "a positive pressure in Pa");
      p.tau       = r.number(s + "Pressure ramp time", is_positive, "a positive ramp time tau in s");
      p.velocity  = r.number(s + "Sliding velocity", is_non_negative, "a sliding velocity >= 0 in m/s");
      p.slide_start = r.number(s + "Slide start", is_non_negative, "a start time >= 0 in s");
      p.end_time = r.number("Simulation/End time", is_positive, "a positive end time in s");
      p.gamma    = r.number(s + "Gamma", is_non_negative, "a damping rate gamma >= 0 in 1/s");
      p.settling_gamma = r.number(s + "Settling gamma", is_non_negative, "a damping rate >= 0 in 1/s");
      p.damping_to_sliding_velocity = r.text(s + "Damping reference") == "sliding velocity";
      p.driven_layers = static_cast<unsigned int>(r.integer(s + "Driven layers", 1, "an integer >= 1"));
      p.drive_reset   = r.text(s + "Drive") == "reset";
      p.integration = read_integration(r, s);
      p.stiffness_factor = r.number(s + "Boundary stiffness factor", is_positive, "a positive factor");
      p.range_ratio = r.number(s + "Boundary range ratio", [](double v) { return v > 0 && v < 2; },
                               "a ratio d/a in (0, 2)");
      p.rest_on_tips = r.text(s + "Block rest") == "tips";
      const std::string surface = r.text(s + "Surface");
      const std::map<std::string, Surface> surfaces = {
        {"periodic", Surface::periodic}, {"tilted", Surface::tilted}, {"twisted", Surface::twisted},
        {"incommensurate", Surface::incommensurate}, {"step", Surface::step},
        {"holes", Surface::holes}, {"random heights", Surface::random_heights},
        {"fractal", Surface::fractal}};
      p.surface = surfaces.at(surface);
      if (p.surface == Surface::twisted && p.dim != 3)
        r.fail(s + "Surface", "'twisted' only with Dimension = 3 (a rotation about the vertical axis; in 2D use "
                              "'tilted')");
      p.angle   = r.number(s + "Tilt angle", [](double v) { return v >= 0 && v <= 45; },
                           "an angle in degrees in [0, 45]") * M_PI / 180;
      p.ratio   = r.number(s + "Mesh ratio", is_positive, "a positive ratio (golden mean 1.618...)");
      p.hole_fraction = r.number(s + "Hole fraction", [](double v) { return v >= 0 && v < 1; },
                                 "a fraction in [0, 1)");
      p.dz = r.number(s + "Roughness amplitude", is_non_negative, "a height >= 0 in m");
      p.fractal_dimension = r.number(s + "Fractal dimension", [&](double v) {
        return p.surface != Surface::fractal || (v > p.dim - 1.0 && v < p.dim);
      }, "D_f in (dim - 1, dim) for Surface = fractal");
      p.step_position = r.number(s + "Step position", is_non_negative, "a position >= 0 in m");
      p.seed    = static_cast<std::uint64_t>(r.integer(s + "Seed", 0, "an integer >= 0"));
      p.regions = static_cast<unsigned int>(r.integer(s + "Local friction regions", 1, "an integer >= 1"));
      p.statistics_interval = r.number(s + "Statistics interval", is_positive, "a positive interval in s");
      p.field_interval = r.number(s + "Field interval", is_non_negative, "an interval >= 0 in s (0: first and last)");
      p.averaging_fraction = r.number(s + "Averaging fraction", [](double v) { return v > 0 && v <= 1; },
                                      "a fraction in (0, 1]");
      if (p.slide_start >= p.end_time)
        r.fail(s + "Slide start", "a start time below Simulation/End time = " + to_text(p.end_time) + " s");
      if (p.block[0] > p.substrate[0] || (p.dim == 3 && p.block[1] > p.substrate[1]))
        r.fail(s + "Block size", "a block no wider than the substrate");
      if (p.surface == Surface::incommensurate && p.ratio == 1)
        r.fail(s + "Mesh ratio", "a ratio != 1 for Surface = incommensurate");
      return p;
    }

    /// A vector along the vertical (last) axis of length @p value.
    template <int dim>
    Tensor<1, dim> vertical(double value)
    {
      Tensor<1, dim> t;
      t[dim - 1] = value;
      return t;
    }

    /// Mean of @p v over indices in @p rows.
    double mean_of(const std::vector<double> &v, const std::vector<std::size_t> &rows)
    {
      double s = 0;
      for (auto r : rows)
        s += v[r];
      return rows.empty() ? 0.0 : s / rows.size();
    }

    /// Standard deviation (population) of @p v over indices in @p rows.
    double std_of(const std::vector<double> &v, const std::vector<std::size_t> &rows)
    {
      const double m = mean_of(v, rows);
      double       s = 0;
      for (auto r : rows)
        s += (v[r] - m) * (v[r] - m);
      return rows.empty() ? 0.0 : std::sqrt(s / rows.size());
    }

    /// The slider experiment: a block (body 1) pressed on a substrate (body 0) by a
    /// pressure P on its top layer ramped as P (1 - exp(-t/tau)), the substrate's bottom
    /// layer fixed; from the slide start the top layer(s) of the block move horizontally
    /// at V (vertical motion free) and the friction on the block's contact layer is
    /// measured: mu = -F_x/F_n sign(V) with F = sum of the boundary forces of the substrate
    /// on the block's first layer (F_n upward positive; mu > 0 is a drag; the paper's
    /// mu_l has the opposite sign).
    template <int dim>
    class Slider : public Experiment<dim>
    {
    public:
      Slider(const SliderParameters &p, sph::Solver<dim> &solver, Log &log)
        : p(p)
      {
        build(solver, log);
      }

      /// Load area A (m^2, m in 2D) and the nominal normal force P A (N, N/m in 2D).
      double area() const { return load_area; }

      /// The bodies' sizes, first in summary.json.
      std::vector<std::pair<std::string, long>> counts() const override
      {
        return {{"n_block", long(n_b)}, {"n_substrate", long(n_s)}};
      }

      /// Lands on the slide start.
      double step_limit(const sph::Solver<dim> &solver) const override
      {
        if (sliding || solver.time >= p.slide_start)
          return std::numeric_limits<double>::infinity();
        return p.slide_start - solver.time;
      }

      /// Starts sliding at the slide start; keeps the loaded layer's velocities and the
      /// block's positions at the start of the step (for the pressure's work, the drive
      /// and the unwrapped displacements).
      void before_step(SphWorld<dim> &world) override
      {
        auto &solver = world.solver;
        if (!sliding && solver.time >= p.slide_start * (1 - 1e-12))
          start_sliding(solver);
        if (sliding && drive < 0)
          install_drive(solver);
        const auto &s = solver.state;
        for (unsigned int q = 0; q < top.size(); ++q)
          v_top[q] = s.v[top[q]];
        for (unsigned int q = 0; q < block.size(); ++q)
          x_block[q] = s.x[block[q]];
      }

      /// Work of the pressure over the step, W += F_i(t + dt/2) . (v_i + v_i')/2 dt;
      /// the drive's impulse over the step (N s, what the solver's constraint v_x = V on the
      /// driven particles supplied: at every Runge-Kutta stage, or as the reset after the
      /// step with Drive = reset) and its work, V times it;
      /// interval sums of the contact forces (midpoint rates) weighted by dt.
      void after_step(SphWorld<dim> &world) override
      {
        auto        &solver = world.solver;
        const double dt     = world.dt;
        auto        &s    = solver.state;
        const double ramp = 1 - std::exp(-(solver.time - 0.5 * dt) / p.tau);
        for (unsigned int q = 0; q < top.size(); ++q)
          work_pressure += ramp * load_per_particle * 0.5 * (v_top[q][dim - 1] + s.v[top[q]][dim - 1]) * dt;
        if (drive >= 0)
          {
            auto        &constraint = solver.imposed[drive];
            const double impulse    = constraint.impulse[0];
            constraint.impulse      = Tensor<1, dim>();
            drive_impulse += impulse;
            work_drive += p.velocity * impulse;
          }
        const auto &bf = solver.last_rates().boundary_force;
        for (unsigned int q = 0; q < contact.size(); ++q)
          {
            const unsigned int i = contact[q];
            sum_fx[region[q]] += bf[i][0] * dt;
            sum_fn[region[q]] += bf[i][dim - 1] * dt;
          }
        for (unsigned int q = 0; q < block.size(); ++q)
          displacement[q] += solver.neighbours().separation(s.x[block[q]], x_block[q]);
        interval += dt;
      }

      /// The slider's columns (see columns()): interval means of the contact forces and
      /// the drive, centre-of-mass motion, energies; resets the interval sums.
      void measure(const SphWorld<dim> &world, Row &row) override
      {
        const auto &solver = world.solver;
        const auto &s = solver.state;
        double      fx = 0, fn = 0;
        for (unsigned int r = 0; r < p.regions; ++r)
          {
            fx += sum_fx[r];
            fn += sum_fn[r];
          }
        const double w = interval > 0 ? 1 / interval : 0.0;
        // At t = 0 (no interval yet) the instantaneous forces are 0 anyway.
        const double sign = p.velocity >= 0 ? 1.0 : -1.0;
        const auto   mu_of = [&](double x, double n) { return n > 0 ? -sign * x / n : 0.0; };
        Tensor<1, dim> dx_cm, v_cm;
        double         m_b = 0, ke_b = 0, ke_s = 0, e_int = 0;
        for (unsigned int q = 0; q < block.size(); ++q)
          {
            const unsigned int i = block[q];
            dx_cm += s.mass[i] * displacement[q];
            v_cm += s.mass[i] * s.v[i];
            m_b += s.mass[i];
          }
        for (unsigned int i = 0; i < s.size(); ++i)
          {
            (s.body[i] == 1 ? ke_b : ke_s) += 0.5 * s.mass[i] * s.v[i].norm_square();
            e_int += s.mass[i] * s.e[i];
          }
        dx_cm /= m_b;
        v_cm /= m_b;
        const double ramp     = 1 - std::exp(-solver.time / p.tau);
        const double residual = work_pressure + work_drive - (ke_b + ke_s) - e_int;
        row("force_x", fx * w)("force_normal", fn * w)("mu", mu_of(fx, fn))
          ("normal_force_ratio", ramp > 0 ? fn * w / (p.pressure * load_area * ramp) : 0.0)
          ("drive_force_x", drive_impulse * w)("block_dx", dx_cm[0])("block_dz", dx_cm[dim - 1])
          ("block_vx", v_cm[0])("block_vz", v_cm[dim - 1])("kinetic_energy_block", ke_b)
          ("kinetic_energy_substrate", ke_s)("internal_energy", e_int)("work_pressure", work_pressure)
          ("work_drive", work_drive)("energy_residual", residual);
        for (unsigned int k = 0; k < p.regions; ++k)
          row("mu_region_" + std::to_string(k), mu_of(sum_fx[k], sum_fn[k]));
        std::fill(sum_fx.begin(), sum_fx.end(), 0.0);
        std::fill(sum_fn.begin(), sum_fn.end(), 0.0);
        drive_impulse = 0;
        interval      = 0;
      }

      /// The window: the last N whole lattice periods a/V of the sliding phase,
      /// N = floor(f (t_e - t_s) V/a) (t_s slide start, t_e end of the run, f the averaging
      /// fraction, a the substrate spacing), so that the climbs and descents over the
      /// substrate's particles cancel; if N = 0, the last f (t_e - t_s). mu_mean = -sum(F_x)/sum(F_n) over it (rows are
      /// interval means over equal times), mu_std the standard deviation of the rows' mu,
      /// mu_stderr the standard error of mu_mean from batch means, each batch a whole lattice
      /// period when the window holds 3 or more (mu_stderr_batches says which).
      void summarize(const SphWorld<dim> &world, const TimeSeries &stats, JsonObject &res) override
      {
        const double t_end = world.solver.time;
        const auto   t       = stats.column("time");
        const double sliding = std::max(0.0, t_end - p.slide_start);
        const double period  = p.velocity > 0 ? p.spacing / p.velocity : 0.0;
        const double whole   = period > 0 ? std::floor(p.averaging_fraction * sliding / period * (1 + 1e-9)) : 0.0;
        const double t0      = t_end - (whole >= 1 ? whole * period : p.averaging_fraction * sliding);
        std::vector<std::size_t> rows;
        for (std::size_t r = 1; r < t.size(); ++r)
          if (t[r] > t0 && t_end > p.slide_start)
            rows.push_back(r);
        const auto fx = stats.column("force_x"), fn = stats.column("force_normal");
        const double sign = p.velocity >= 0 ? 1.0 : -1.0;
        const double fn_mean = mean_of(fn, rows);
        res.set("window_start", t0);
        res.set("window_end", t_end);
        res.set("window_rows", long(rows.size()));
        res.set("window_lattice_periods", whole);
        res.set("mu_mean", fn_mean > 0 ? -sign * mean_of(fx, rows) / fn_mean : 0.0);
        res.set("mu_std", std_of(stats.column("mu"), rows));
        {
          // With 3 or more whole lattice periods in the window, each period is a batch (the
          // climb over the substrate's particles averages out within it); else batch means
          // (steady_state.h) of the rows in time order, which that oscillation inflates. The
          // ratio is formed per batch as for mu_mean.
          std::vector<double> ratio, load;
          if (whole >= 3)
            {
              ratio.assign(static_cast<std::size_t>(whole), 0.0);
              load.assign(ratio.size(), 0.0);
              for (const std::size_t r : rows)
                {
                  const double k = std::ceil((t[r] - t0) / period * (1 - 1e-9)) - 1;
                  const auto   b = static_cast<std::size_t>(std::clamp(k, 0.0, whole - 1));
                  ratio[b] += fx[r];
                  load[b] += fn[r];
                }
            }
          else
            {
              std::vector<double> fx_rows, fn_rows;
              for (const std::size_t r : rows)
                {
                  fx_rows.push_back(fx[r]);
                  fn_rows.push_back(fn[r]);
                }
              ratio = batch_means(fx_rows);
              load  = batch_means(fn_rows);
            }
          for (std::size_t b = 0; b < ratio.size(); ++b)
            ratio[b] = load[b] > 0 ? -sign * ratio[b] / load[b] : 0.0;
          res.set("mu_stderr", batch_standard_error(ratio));
          res.set("mu_stderr_batches", whole >= 3 ? "lattice periods" : "rows (fewer than 3 lattice periods: "
                                                                        "inflated by the climb over the substrate)");
        }
        res.set("mu_rows_mean", mean_of(stats.column("mu"), rows));
        res.set("normal_force_mean", fn_mean);
        res.set("tangential_force_mean", mean_of(fx, rows));
        res.set("nominal_normal_force", p.pressure * load_area);
        res.set("normal_force_ratio", fn_mean / (p.pressure * load_area));
        res.set("drive_force_mean", mean_of(stats.column("drive_force_x"), rows));
        res.set("block_vx_mean", mean_of(stats.column("block_vx"), rows));
        for (unsigned int k = 0; k < p.regions; ++k)
          res.set("mu_region_" + std::to_string(k) + "_mean",
                  mean_of(stats.column("mu_region_" + std::to_string(k)), rows));
        res.set("load_area", load_area);
        res.set("pressure", p.pressure);
        res.set("sliding_velocity", p.velocity);
        res.set("gamma", p.gamma);
        res.set("slide_start", p.slide_start);
        res.set("sliding_distance", std::max(0.0, t_end - p.slide_start) * p.velocity);
        res.set("n_block", long(n_b));
        res.set("n_substrate", long(n_s));
        res.set("n_contact_layer", long(contact.size()));
        res.set("n_driven", long(driven.size()));
        res.set("n_loaded", long(top.size()));
        res.set("n_fixed", long(fixed.size()));
        res.set("surface_height_rms", surface_rms);
        res.set("surface_height_peak", surface_peak);
        res.set("surface_holes", long(surface_removed));
        res.set("rest_gap", rest_gap);
      }

      /// The phase, the interval sums, the works and the unwrapped block displacements
      /// (the damping is the solver's).
      void save(CheckpointOut &ar) const override
      {
        ar << sliding << sum_fx << sum_fn << displacement << work_pressure << work_drive << drive_impulse
           << interval;
      }
      void load(CheckpointIn &ar) override
      {
        ar >> sliding >> sum_fx >> sum_fn >> displacement >> work_pressure >> work_drive >> drive_impulse >>
          interval;
      }

    private:
      /// Distance between horizontal layers of a lattice of spacing @p a (m).
      double layer_spacing(double a) const { return sph::layer_spacing<dim>(p.lattice, a); }

      /// Box of the lengths "Lx, Ly, Lz" (2D: Lx and Lz).
      Tensor<1, dim> box(const std::array<double, 3> &l) const
      {
        Tensor<1, dim> b;
        b[0]       = l[0];
        b[dim - 1] = l[2];
        if (dim == 3)
          b[1] = l[1];
        return b;
      }

      /// The substrate's points with the surface modifier applied to its top layer; keeps
      /// the realised roughness (rms and peak height change of the top layer, holes made).
      std::vector<Tensor<1, dim>> substrate_points(double a, Tensor<1, dim> &size)
      {
        size = box(p.substrate);
        if (p.periodic)
          size[0] = std::max(3.0, std::round(size[0] / a)) * a;
        auto         pts = sph::lattice_points<dim>(p.lattice, Tensor<1, dim>(), size, a);
        const double tol = 0.25 * layer_spacing(a);
        const auto   top_layer = sph::surface_layer(pts, tol);
        std::vector<double> z0;
        for (unsigned int i : top_layer)
          z0.push_back(pts[i][dim - 1]);
        single_layer = top_layer.size() == pts.size();
        const std::size_t n_lattice = pts.size();
        switch (p.surface)
          {
            case Surface::step:
              sph::add_step(pts, p.step_position, layer_spacing(a), tol);
              break;
            case Surface::holes:
              sph::random_holes(pts, p.hole_fraction, p.seed, tol);
              break;
            case Surface::random_heights:
              sph::random_heights(pts, p.dz, p.seed, tol);
              break;
            case Surface::fractal:
              sph::fractal_heights(pts, p.fractal_dimension, p.dz, size,
                                   static_cast<unsigned int>(size[0] / a / 2), p.seed, tol);
              break;
            default:
              break;
          }
        if (p.surface == Surface::random_heights || p.surface == Surface::fractal)
          {
            double sq = 0;
            for (unsigned int k = 0; k < top_layer.size(); ++k)
              {
                const double dz = pts[top_layer[k]][dim - 1] - z0[k];
                sq += dz * dz;
                surface_peak = std::max(surface_peak, std::abs(dz));
              }
            surface_rms = std::sqrt(sq / top_layer.size());
          }
        if (p.surface == Surface::holes)
          surface_removed = n_lattice - pts.size();
        return pts;
      }

      /// The block's points (origin 0): a box lattice, or for Surface = tilted (twisted) a
      /// lattice rotated by the tilt angle about the box centre in the x-vertical (x-y)
      /// plane and cut to the box.
      std::vector<Tensor<1, dim>> block_points(double a) const
      {
        const Tensor<1, dim> size = box(p.block);
        if (p.surface != Surface::tilted && p.surface != Surface::twisted)
          return sph::lattice_points<dim>(p.lattice, Tensor<1, dim>(), size, a);
        const unsigned int axis = p.surface == Surface::tilted ? dim - 1 : 1;
        return sph::rotated_lattice_points<dim>(p.lattice, size, a, p.angle, axis);
      }

      /// Builds both bodies, the load, the fixed bottom, the boundary law, the damping
      /// and the particle groups (top, driven, contact layer and its regions).
      void build(sph::Solver<dim> &solver, Log &log)
      {
        const double a_s = p.spacing;
        const double a_b = p.surface == Surface::incommensurate ? p.ratio * p.spacing : p.spacing;
        Tensor<1, dim> sub_size;
        const auto   sub = substrate_points(a_s, sub_size);
        auto         blk = block_points(a_b);
        if (sub.empty() || blk.empty())
          throw InputError(slider_section + ": the block or the substrate has no particle (spacing " +
                           to_text(a_s) + " m too large for the sizes)");
        const Tensor<1, dim> blk_size = box(p.block);
        Tensor<1, dim>       centre;
        centre[0] = 0.5 * (sub_size[0] - blk_size[0]);
        if (dim == 3)
          centre[1] = 0.5 * (sub_size[1] - blk_size[1]);
        // At rest where the spring law f1 of range d = ratio a_s vanishes (Block rest).
        const Tensor<1, dim> shift = sph::rest_shift(sub, blk, centre, a_s, p.range_ratio * a_s,
                                                     p.periodic ? sub_size[0] : 0.0, p.rest_on_tips);
        for (auto &x : blk)
          x += shift;
        double sub_top = -1e300, blk_bottom = 1e300;
        for (const auto &x : sub)
          sub_top = std::max(sub_top, x[dim - 1]);
        for (const auto &x : blk)
          blk_bottom = std::min(blk_bottom, x[dim - 1]);
        rest_gap = blk_bottom - sub_top;

        const auto &m = p.material;
        n_s = sub.size();
        n_b = blk.size();
        sph::add_particles(solver.state, sub, m.rho0, sph::volume_per_particle<dim>(p.lattice, a_s),
                           p.smoothing_ratio * a_s, 0, 0);
        const unsigned int first = sph::add_particles(
          solver.state, blk, m.rho0, sph::volume_per_particle<dim>(p.lattice, a_b), p.smoothing_ratio * a_b, 0, 1);
        first_block = first;

        // Groups (indices into the state).
        const double lb = layer_spacing(a_b), tol_b = p.surface == Surface::tilted ? 0.6 * a_b : 0.25 * lb;
        // The bottom layer is fixed; a single-layer substrate is rigid (all fixed), as the
        // paper's random and fractal substrates (its section 4.3).
        if (single_layer)
          for (unsigned int i = 0; i < sub.size(); ++i)
            fixed.push_back(i);
        else
          for (unsigned int i : sph::surface_layer(sub, 0.25 * layer_spacing(a_s), false))
            fixed.push_back(i);
        for (unsigned int i : sph::surface_layer(blk, tol_b, true))
          top.push_back(first + i);
        for (unsigned int i : sph::surface_layer(blk, tol_b, false))
          contact.push_back(first + i);
        double blk_top = -1e300;
        for (const auto &x : blk)
          blk_top = std::max(blk_top, x[dim - 1]);
        for (unsigned int i = 0; i < blk.size(); ++i)
          {
            block.push_back(first + i);
            if (blk[i][dim - 1] > blk_top - (p.driven_layers - 0.5) * lb - tol_b)
              driven.push_back(first + i);
          }
        // Regions: the contact layer in equal groups by initial x (block frame).
        std::vector<unsigned int> order(contact.size());
        std::iota(order.begin(), order.end(), 0U);
        std::sort(order.begin(), order.end(), [&](unsigned int u, unsigned int v) {
          return solver.state.x[contact[u]][0] < solver.state.x[contact[v]][0];
        });
        region.assign(contact.size(), 0);
        for (unsigned int q = 0; q < order.size(); ++q)
          region[order[q]] = std::min<unsigned int>(p.regions - 1, q * p.regions / order.size());
        sum_fx.assign(p.regions, 0);
        sum_fn.assign(p.regions, 0);
        v_top.resize(top.size());
        x_block.resize(block.size());
        displacement.assign(block.size(), Tensor<1, dim>());

        // Load: P A over the top layer, ramped; bottom fixed.
        load_area         = dim == 2 ? blk_size[0] : blk_size[0] * blk_size[1];
        load_per_particle = -p.pressure * load_area / top.size();
        sph::ExternalForce<dim> load;
        load.particles = top;
        load.force     = vertical<dim>(load_per_particle);
        load.tau       = p.tau;
        solver.external.push_back(load);
        sph::ImposedVelocity<dim> bottom;
        bottom.particles = fixed;
        solver.imposed.push_back(bottom);
        set_damping(solver, p.settling_gamma, false);

        const auto [E, nu] = young_and_poisson(m);
        std::ostringstream os;
        os << "sph_slider " << dim << "D " << m.name << ": substrate " << n_s << " particles (a = " << a_s
           << " m" << (p.periodic ? ", periodic in x with period " + to_text(sub_size[0]) + " m" : "")
           << "), block " << n_b << " (a = " << a_b << " m), h = " << p.smoothing_ratio << " a; E = " << E
           << " Pa, nu = " << nu << "; boundary " << solver.parameters().boundary.describe() << "; load "
           << top.size() << " particles, P A = " << p.pressure * load_area << (dim == 2 ? " N/m" : " N")
           << "; contact layer " << contact.size() << ", driven " << driven.size() << ", fixed " << fixed.size();
        log(os.str());
      }

      /// Damping of both bodies at rate @p gamma (1/s): relative to a fixed reference
      /// (block: (V, 0, 0) once sliding, 0 before; substrate: 0), or to each body's
      /// centre-of-mass velocity (Damping reference = centre of mass, while sliding).
      void set_damping(sph::Solver<dim> &solver, double gamma, bool slide) const
      {
        solver.damping.clear();
        if (gamma <= 0)
          return;
        const bool     com = slide && !p.damping_to_sliding_velocity;
        sph::Damping   sub{0, gamma, com, {{0, 0, 0}}};
        sph::Damping   blk{1, gamma, com, {{slide ? p.velocity : 0.0, 0, 0}}};
        solver.damping = {sub, blk};
      }

      /// Slide start: every block particle gets v_x = V (the paper's first step), the
      /// damping switches to the sliding phase's gamma.
      void start_sliding(sph::Solver<dim> &solver)
      {
        sliding = true;
        for (unsigned int i : block)
          solver.state.v[i][0] = p.velocity;
        set_damping(solver, p.gamma, true);
      }

      /// The drive: v_x = V imposed on the driven particles, their other components free:
      /// by the solver at every Runge-Kutta stage (Drive = exact), or set after each step
      /// only (Drive = reset, sph::ImposedVelocity::between_steps), the driven particles then
      /// slowed by the layer below within each step.
      void install_drive(sph::Solver<dim> &solver)
      {
        sph::ImposedVelocity<dim> push;
        push.particles  = driven;
        push.velocity   = vertical<dim>(0);
        push.velocity[0] = p.velocity;
        push.components = 1; // x imposed, the others free
        push.between_steps = p.drive_reset;
        drive           = static_cast<int>(solver.imposed.size());
        solver.imposed.push_back(push);
      }

      SliderParameters            p;
      unsigned int                n_b = 0, n_s = 0, first_block = 0;
      double                      surface_rms = 0, surface_peak = 0; ///< top-layer height change, m
      std::size_t                 surface_removed = 0;               ///< holes made in the top layer
      double                      rest_gap = 0; ///< block's lowest minus substrate's highest z at t = 0, m
      bool                        single_layer = false;              ///< one-layer (rigid) substrate
      std::vector<unsigned int>   fixed, top, contact, driven, block, region;
      std::vector<double>         sum_fx, sum_fn;
      std::vector<Tensor<1, dim>> v_top, x_block, displacement;
      double load_area = 0, load_per_particle = 0, work_pressure = 0, work_drive = 0;
      double drive_impulse = 0, interval = 0;
      int    drive = -1; ///< index of the drive in the solver's imposed velocities (-1: none yet)
      bool   sliding = false;
    };

    /// The solver of the slider: spring boundary law f1 with K = k E a^(dim-2) (N/m in 3D,
    /// Pa = N/m per m in 2D; the paper's eq. 25 estimate K ~ E h) and range d = ratio a.
    template <int dim>
    sph::SolverParameters slider_solver(const SliderParameters &p, double substrate_period)
    {
      sph::SolverParameters s = p.integration;
      s.period   = p.periodic ? substrate_period : 0;
      const double E = young_and_poisson(p.material).first;
      s.boundary = sph::BoundaryForce::spring(p.stiffness_factor * E * std::pow(p.spacing, dim - 2),
                                              p.range_ratio * p.spacing);
      return s;
    }

    /// The slider of @p p (after checking the periodic length against the neighbour
    /// search's 3 cut-offs).
    template <int dim>
    std::unique_ptr<Simulation> make_slider(EntryReader &r, const SliderParameters &p, Log &log)
    {
      const double period = std::max(3.0, std::round(p.substrate[0] / p.spacing)) * p.spacing;
      if (p.periodic && period < 3 * 2 * std::max(p.smoothing_ratio, p.range_ratio) * p.spacing *
                                   (p.surface == Surface::incommensurate ? p.ratio : 1.0))
        r.fail(slider_section + "/Substrate size", "a substrate at least 3 cut-offs long when periodic");
      return make_simulation<dim>(
        LoopSettings{"sph_slider", p.end_time, p.statistics_interval, p.field_interval},
        std::make_unique<sph::Solver<dim>>(std::vector<sph::Material>{p.material}, slider_solver<dim>(p, period)),
        [&](sph::Solver<dim> &solver) { return std::make_unique<Slider<dim>>(p, solver, log); });
    }
  } // namespace

  void declare_sph_slider_parameters(dealii::ParameterHandler &prm)
  {
    prm.enter_subsection(slider_section);
    prm.declare_entry("Material", "granite", Selection("granite|basalt"),
                      "Rock of both bodies: Tillotson equation of state and shear modulus "
                      "(docs/sph.md; granite G = 9.72 GPa, basalt G = 22.7 GPa).");
    prm.declare_entry("Dimension", "3", Selection("2|3"),
                      "2 (plane strain, forces per metre of depth) or 3. The vertical axis is the last.");
    prm.declare_entry("Lattice", "cubic", Selection("cubic|hcp"),
                      "Lattice of both bodies: square/simple cubic or hexagonal (2D)/hexagonal close-packed (3D).");
    prm.declare_entry("Particle spacing", "3.125e-4", Double(),
                      "Nearest-neighbour spacing a of the substrate (and of the block unless incommensurate), m, > 0.");
    prm.declare_entry("Smoothing length ratio", "1.2", Double(), "h/a, in [1, 2].");
    prm.declare_entry("Block size", "5e-3, 3.75e-3, 2.5e-3", Anything(),
                      "Block box \"Lx, Ly, Lz\", m, z vertical; 2D uses Lx and Lz. Paper: 0.5 x 0.375 x 0.25 cm.");
    prm.declare_entry("Substrate size", "1e-2, 5e-3, 2.5e-3", Anything(),
                      "Substrate box \"Lx, Ly, Lz\", m (Lx rounded to a whole number of spacings when periodic). "
                      "Paper: 1 x 0.5 x 0.25 cm.");
    prm.declare_entry("Periodic", "true", Bool(),
                      "Substrate (and the whole domain) periodic along x with period Lx: the block never reaches an edge.");
    prm.declare_entry("Pressure", "1e8", Double(),
                      "Normal pressure P on the block's top layer, Pa (> 0), as equal vertical forces P A/n.");
    prm.declare_entry("Pressure ramp time", "3e-5", Double(), "tau of the ramp P (1 - exp(-t/tau)), s (> 0).");
    prm.declare_entry("Sliding velocity", "1", Double(),
                      "Horizontal velocity V imposed on the block's driven top layer(s) from the slide start, m/s (>= 0).");
    prm.declare_entry("Slide start", "1.5e-4", Double(),
                      "Time at which sliding starts (all block particles get v_x = V once), s; below the end time.");
    prm.declare_entry("Gamma", "1e6", Double(),
                      "Damping rate gamma of both bodies while sliding, 1/s (>= 0; 0: none). Paper: 1e6 - 1e9.");
    prm.declare_entry("Settling gamma", "1e6", Double(),
                      "Damping rate before the slide start (settling under the ramped load), 1/s (>= 0).");
    prm.declare_entry("Damping reference", "centre of mass", Selection("centre of mass|sliding velocity"),
                      "While sliding: 'centre of mass' damps each body toward its own centre-of-mass velocity "
                      "(eq. 36, f = -m gamma (v - v_cm): no net force, so the drive alone balances the friction); "
                      "'sliding velocity' damps the block toward (V, 0, 0) and the substrate toward 0 (the paper's "
                      "f = -m gamma (v_x - V), -m gamma v_y, -m gamma v_z: the damping then also pushes the block "
                      "and holds it vertically). Before sliding both bodies are damped toward rest.");
    prm.declare_entry("Driven layers", "2", Integer(1),
                      "Number of top layers of the block whose horizontal velocity is imposed (vertical free), >= 1. "
                      "The paper drives the first and sometimes the second layer; the block follows either "
                      "(2D quick case: mu 0.0025 with one, 0.0012 with two; docs/validation.md).");
    prm.declare_entry("Drive", "exact", Selection("exact|reset"),
                      "How the driven layers move at V: 'exact' imposes v_x = V at every Runge-Kutta stage (the "
                      "constraint's force balances the block); 'reset' integrates them with the others and sets "
                      "v_x = V after each step (an explicit code's reading of the paper's 'moved with velocity v'; "
                      "the resets' impulse is the drive's).");
    declare_integration_entries(prm);
    prm.declare_entry("Boundary stiffness factor", "1",  Double(),
                      "k in the spring law f1 between the bodies, K = k E a^(dim-2) (N/m in 3D, N/m per m "
                      "of depth in 2D; the paper's K ~ E h estimate), > 0.");
    prm.declare_entry("Boundary range ratio", "1", Double(),
                      "Range d of f1 as a fraction of a, in (0, 2); the block starts with every block-substrate "
                      "distance >= d (Block rest).");
    prm.declare_entry("Block rest", "valleys", Selection("valleys|tips"),
                      "Where the block starts, each contact particle at the distance d of f1 from the substrate: "
                      "'valleys' (lowest, the block's lattice shifted horizontally into the substrate's hollows) "
                      "or 'tips' (the lattices stacked, each contact particle d above a substrate particle, the "
                      "paper's 'at a distance equal to the inter-particle spacing'; an unstable rest).");
    prm.declare_entry("Surface", "periodic",
                      Selection("periodic|tilted|twisted|incommensurate|step|holes|random heights|fractal"),
                      "Contact surfaces: 'periodic' (aligned lattices), 'tilted' (block lattice rotated by Tilt angle "
                      "in the x-vertical plane: a stepped contact face), 'twisted' (3D: rotated by Tilt angle about "
                      "the vertical axis, flat faces, the rows crossing the substrate's at that angle), "
                      "'incommensurate' (block spacing = Mesh ratio x a), 'step' (one-particle step on the substrate "
                      "beyond Step position), 'holes' (Hole fraction of the substrate's top layer removed), "
                      "'random heights' (substrate top moved uniformly in +/- dz/2), 'fractal' (self-affine "
                      "substrate top of dimension D_f, rms height dz).");
    prm.declare_entry("Tilt angle", "10", Double(), "Rotation of the block's lattice for 'tilted' and 'twisted', degrees, [0, 45].");
    prm.declare_entry("Mesh ratio", "1.618033988749895", Double(),
                      "Block spacing / substrate spacing for 'incommensurate' (> 0, != 1; golden mean by default).");
    prm.declare_entry("Hole fraction", "0.3", Double(), "Fraction of the substrate's top particles removed, [0, 1).");
    prm.declare_entry("Roughness amplitude", "1.5e-4", Double(),
                      "dz, m (>= 0): full width of the uniform heights, or rms of the fractal heights.");
    prm.declare_entry("Fractal dimension", "2.5", Double(), "D_f of the fractal substrate, in (dim - 1, dim).");
    prm.declare_entry("Step position", "6e-3", Double(),
                      "x beyond which the substrate is one layer higher, m (>= 0). The block rests centred, its "
                      "front at (Lx_substrate + Lx_block)/2 (7.5e-3 m in paper.prm): put the step ahead of it for "
                      "the block to run into it.");
    prm.declare_entry("Seed", "1", Integer(0), "Seed of the random surfaces, >= 0.");
    prm.declare_entry("Local friction regions", "4", Integer(1),
                      "Number of equal groups (by initial x) of the contact layer with their own mu, >= 1.");
    prm.declare_entry("Statistics interval", "1e-6", Double(),
                      "Simulated time between rows of statistics.csv, s (> 0); forces are averaged over it.");
    prm.declare_entry("Field interval", "5e-5", Double(),
                      "Simulated time between VTU snapshots, s (>= 0; 0: first and last only).");
    prm.declare_entry("Averaging fraction", "0.5", Double(),
                      "mu_mean and mu_std in summary.json average the last N whole lattice periods a/V within the last "
                      "fraction f of the sliding phase (the last f of it if shorter than one period), in (0, 1].");
    prm.leave_subsection();
  }

  SceneHooks sph_slider_hooks()
  {
    return {{declare_sph_slider_parameters},
            [](const ParameterFile &file) {
              EntryReader r(file);
              read_slider(r);
            },
            [](const ParameterFile &file, const CaseParameters &, Log &log) {
              EntryReader              r(file);
              const SliderParameters p = read_slider(r);
              return p.dim == 2 ? make_slider<2>(r, p, log) : make_slider<3>(r, p, log);
            }};
  }
} // namespace tribo::app
