#include "app/scenes/sph_family.h"

#include "core/point_cloud.h"
#include "core/run_control.h"
#include "sph/solver.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <sstream>

namespace tribo::app::sph_scenes
{
  long EntryReader::integer(const std::string &path, long lowest, const std::string &expected)
  {
    const long v = file.get_integer(path);
    if (v < lowest)
      file.fail(path, expected);
    return v;
  }

  std::array<double, 3> EntryReader::lengths(const std::string &path)
  {
    const std::string     value = text(path);
    std::istringstream    is(value);
    std::array<double, 3> out{};
    std::string           item;
    unsigned int          n = 0;
    while (std::getline(is, item, ','))
      {
        std::size_t used = 0;
        double      v    = 0;
        try
          {
            v = std::stod(item, &used);
          }
        catch (const std::exception &)
          {
            file.fail(path, "three positive lengths in m, \"Lx, Ly, Lz\" (z vertical)");
          }
        if (n >= 3 || !(v > 0) || item.find_first_not_of(" \t", used) != std::string::npos)
          file.fail(path, "three positive lengths in m, \"Lx, Ly, Lz\" (z vertical)");
        out[n++] = v;
      }
    if (n != 3)
      file.fail(path, "three positive lengths in m, \"Lx, Ly, Lz\" (z vertical)");
    return out;
  }

  void EntryReader::fail(const std::string &path, const std::string &expected) const
  {
    file.fail(path, expected);
  }

  std::pair<double, double> young_and_poisson(const sph::Material &m)
  {
    const double K = m.bulk_modulus, G = m.shear_modulus;
    return {9 * K * G / (3 * K + G), (3 * K - 2 * G) / (2 * (3 * K + G))};
  }

  sph::Material material_named(const std::string &name)
  {
    return name == "basalt" ? sph::Material::basalt() : sph::Material::granite();
  }

  void declare_integration_entries(dealii::ParameterHandler &prm)
  {
    using dealii::Patterns::Double;
    prm.declare_entry("Artificial viscosity alpha", "1", Double(), "Monaghan viscosity alpha, >= 0.");
    prm.declare_entry("Artificial viscosity beta", "0.1", Double(), "Monaghan viscosity beta, >= 0.");
    prm.declare_entry("CFL number", "0.3", Double(), "C in dt = C h/(c (1 + 1.2 alpha) + beta max mu), in (0, 1].");
    prm.declare_entry("Step floor", "1e-12", Double(),
                      "Smallest allowed step, s (> 0): a smaller one ends the run with status failed.");
    prm.declare_entry("Fixed step", "0", Double(),
                      "A fixed step, s (>= 0; 0: adaptive, CFL and acceleration limits). A fixed step ignores "
                      "those limits (Maveyraud et al.'s typical step is 5e-8 s); a run that blows up ends failed.");
    prm.declare_entry("Interface viscosity", "false", dealii::Patterns::Bool(),
                      "true: the Monaghan viscosity also acts between particles of different bodies (within "
                      "2 h, counted in the boundary force); false: only the boundary force acts across bodies.");
  }

  sph::SolverParameters read_integration(EntryReader &r, const std::string &section)
  {
    sph::SolverParameters s;
    s.alpha   = r.number(section + "Artificial viscosity alpha", is_non_negative, "alpha >= 0");
    s.beta    = r.number(section + "Artificial viscosity beta", is_non_negative, "beta >= 0");
    s.courant = r.number(section + "CFL number", [](double v) { return v > 0 && v <= 1; }, "a CFL number in (0, 1]");
    s.dt_min  = r.number(section + "Step floor", is_positive, "a positive step floor in s");
    s.fixed_step = r.number(section + "Fixed step", is_non_negative, "a step >= 0 in s (0: adaptive)");
    s.interface_viscosity = r.text(section + "Interface viscosity") == "true";
    return s;
  }

  namespace
  {
    /// VTU text of the particles: one vertex per particle with velocity (m/s), boundary
    /// force (N, N/m in 2D; from the last rate evaluation), pressure P (Pa, compression
    /// is_positive), Cauchy stress sigma = -P I + S (Pa, tension positive; in 2D also the
    /// plane-strain sigma_zz = -P + S_zz, S_zz = -(S_xx + S_yy)), density (kg/m^3),
    /// specific internal energy (J/kg) and body id.
    template <int dim>
    std::string particle_vtu(const sph::Solver<dim> &solver)
    {
      const auto        &s = solver.state;
      const auto        &k = solver.last_rates();
      const unsigned int n = s.size();
      const bool         has_force = k.boundary_force.size() == n;
      const char        *axis      = "xyz";
      std::vector<std::array<double, 3>> points(n, {{0, 0, 0}});
      PointField velocity{"velocity", dim, {}}, force{"boundary_force", dim, {}}, pressure{"pressure", 1, {}};
      std::vector<PointField> normal, shear; // sigma_aa (with sigma_zz in 2D), sigma_ab (a < b)
      for (unsigned int a = 0; a < 3; ++a)
        normal.push_back({std::string("sigma_") + axis[a] + axis[a], 1, {}});
      for (unsigned int a = 0; a < dim; ++a)
        for (unsigned int b = a + 1; b < dim; ++b)
          shear.push_back({std::string("sigma_") + axis[a] + axis[b], 1, {}});
      PointField density{"density", 1, {}}, energy{"internal_energy", 1, {}}, body{"body", 1, {}};
      for (unsigned int i = 0; i < n; ++i)
        {
          const double P = solver.materials()[s.material[i]].evaluate(s.rho[i], s.e[i]).pressure;
          for (unsigned int d = 0; d < dim; ++d)
            {
              points[i][d] = s.x[i][d];
              velocity.values.push_back(s.v[i][d]);
              force.values.push_back(has_force ? k.boundary_force[i][d] : 0.0);
            }
          pressure.values.push_back(P);
          for (unsigned int a = 0; a < dim; ++a)
            normal[a].values.push_back(s.S[i][a][a] - P);
          if (dim == 2)
            normal[2].values.push_back(-(s.S[i][0][0] + s.S[i][1][1]) - P);
          unsigned int c = 0;
          for (unsigned int a = 0; a < dim; ++a)
            for (unsigned int b = a + 1; b < dim; ++b)
              shear[c++].values.push_back(s.S[i][a][b]);
          density.values.push_back(s.rho[i]);
          energy.values.push_back(s.e[i]);
          body.values.push_back(s.body[i]);
        }
      std::vector<PointField> fields = {velocity, force, pressure};
      fields.insert(fields.end(), normal.begin(), normal.end());
      fields.insert(fields.end(), shear.begin(), shear.end());
      fields.insert(fields.end(), {density, energy, body});
      return point_cloud_vtu(dim, points, fields);
    }

    /// The family's Simulation (see make_simulation()).
    template <int dim>
    class SphSimulation : public Simulation
    {
    public:
      SphSimulation(const LoopSettings &settings, std::unique_ptr<sph::Solver<dim>> s,
                    const ExperimentFactory<dim> &make_experiment)
        : ls(settings)
        , solver(std::move(s))
        , exp(make_experiment(*solver))
        , world{*solver}
        , next_row(ls.statistics_interval)
        , next_field(ls.field_interval > 0 ? ls.field_interval : 2 * ls.end_time)
      {}

      double time() const override { return solver->time; }
      double end_time() const override { return ls.end_time; }
      bool   reached_end(unsigned long) const override { return solver->time >= ls.end_time * (1 - 1e-12); }

      void advance(unsigned long, const std::function<void(const std::string &)> &) override
      {
        exp->before_step(world);
        dt       = solver->step(std::min(ls.end_time - solver->time, exp->step_limit(*solver)));
        dt_lo    = std::min(dt_lo, dt);
        dt_hi    = std::max(dt_hi, dt);
        world.dt = dt;
        exp->after_step(world);
      }

      bool row(Row &row) override
      {
        row("dt", dt);
        exp->measure(world, row);
        return true;
      }
      bool row_at_start() const override { return true; }
      bool row_due(unsigned long) override { return passed(next_row, ls.statistics_interval); }
      bool snapshot_due(unsigned long) override { return passed(next_field, ls.field_interval); }

      void write_snapshot(FieldWriter &fields) override
      {
        char name[40];
        std::snprintf(name, sizeof name, "particles_%05u.vtu", fields.n_indexed("particles"));
        atomic_write((std::filesystem::path(fields.directory()) / name).string(), particle_vtu(*solver));
        fields.index("particles", solver->time, name);
      }
      unsigned int n_snapshots(const FieldWriter &fields) const override { return fields.n_indexed("particles"); }

      std::string resumed_line(unsigned long step) const override
      {
        std::ostringstream os;
        os << "resumed at step " << step << " (t = " << solver->time << " s) of the run to " << ls.end_time << " s";
        return os.str();
      }

      void summarize(const RunEnd &end, JsonObject &summary, RunOutputs &out) override
      {
        for (const auto &[name, value] : exp->counts())
          summary.set(name, value);
        summary.set("dimension", long(dim));
        summary.set("end_time", ls.end_time);
        summary.set("dt_min", end.step ? dt_lo : 0.0);
        summary.set("dt_max", dt_hi);
        summary.set("last_step_limiter", solver->last_limiter());
        summary.set("n_particles", long(solver->state.size()));
        exp->summarize(world, end.statistics, out.results);
        out.tables = exp->tables();
        out.scalars["dt_min"] = end.step ? dt_lo : 0.0;
        out.scalars["dt_max"] = dt_hi;
        std::ostringstream os;
        os << end.step << " steps to t = " << solver->time << " s in " << end.wall_time << " s; step "
           << (end.step ? dt_lo : 0.0) << " .. " << dt_hi << " s";
        out.last_line = os.str();
      }

      // After the step number (the driver's), in this order.
      void save(CheckpointOut &ar) const override
      {
        ar << dt << dt_lo << dt_hi << next_row << next_field;
        solver->save(ar);
        exp->save(ar);
      }
      void load(CheckpointIn &ar, unsigned long) override
      {
        ar >> dt >> dt_lo >> dt_hi >> next_row >> next_field;
        solver->load(ar);
        exp->load(ar);
        if (ls.field_interval <= 0) // first and last only, whatever the end time now
          next_field = 2 * ls.end_time;
      }

    private:
      /// True if the solver's time has reached @p next (s); then @p next moves on by
      /// whole @p interval s past it.
      bool passed(double &next, double interval) const
      {
        if (solver->time < next * (1 - 1e-12))
          return false;
        while (next <= solver->time * (1 + 1e-12))
          next += interval;
        return true;
      }

      LoopSettings                      ls;
      std::unique_ptr<sph::Solver<dim>> solver;
      std::unique_ptr<Experiment<dim>>  exp;
      SphWorld<dim>                     world; ///< what the experiment's hooks see
      double dt = 0, dt_lo = std::numeric_limits<double>::infinity(), dt_hi = 0, next_row, next_field;
    };
  } // namespace

  template <int dim>
  std::unique_ptr<Simulation> make_simulation(const LoopSettings &settings, std::unique_ptr<sph::Solver<dim>> solver,
                                              const ExperimentFactory<dim> &make_experiment)
  {
    return std::make_unique<SphSimulation<dim>>(settings, std::move(solver), make_experiment);
  }

  template std::unique_ptr<Simulation> make_simulation<2>(const LoopSettings &, std::unique_ptr<sph::Solver<2>>,
                                                          const ExperimentFactory<2> &);
  template std::unique_ptr<Simulation> make_simulation<3>(const LoopSettings &, std::unique_ptr<sph::Solver<3>>,
                                                          const ExperimentFactory<3> &);
} // namespace tribo::app::sph_scenes
