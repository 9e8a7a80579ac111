#include "app/scenes/mlp_family.h"

#include "app/scene_hooks.h"
#include "core/errors.h"
#include "core/point_cloud.h"
#include "core/run_control.h"
#include "mlp/analysis.h"
#include "mlp/linear_theory.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace tribo::app
{
  void declare_mlp_parameters(dealii::ParameterHandler &prm)
  {
    using dealii::Patterns::Double;
    using dealii::Patterns::Integer;
    using dealii::Patterns::Selection;
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
  }
} // namespace tribo::app

namespace tribo::app::mlp_scenes
{
  unsigned int count(const ParameterFile &f, const std::string &path, long min)
  {
    const long v = f.get_integer(path);
    if (v < min)
      f.fail(path, "an integer >= " + std::to_string(min));
    return static_cast<unsigned int>(v);
  }

  CommonSettings read_common(const ParameterFile &f)
  {
    CommonSettings s;
    s.lattice = f.get("MLP/Lattice") == "square" ? mlp::LatticeType::square
                                                : mlp::LatticeType::hexagonal;
    auto &ip  = s.interaction;
    ip.n      = mlp::symmetry_order(s.lattice);
    ip.r0     = f.get_checked("MLP/Spacing", is_positive, "a positive spacing r0 in m");
    s.mass    = f.get_checked("MLP/Particle mass", is_positive, "a positive mass in kg/m");
    ip.stiffness = f.get_checked("MLP/Pair stiffness", is_positive, "a positive k_c = U''(r0) in N/m^2");
    ip.f0     = f.get_checked("MLP/Return force amplitude", is_non_negative, "f0 >= 0 in N/m");
    ip.width  = f.get_checked("MLP/Well width", [](double v) { return v >= 1 && v <= 30; },
                       "a Morse width a r0 in [1, 30], e.g. 7");
    ip.form   = f.get("MLP/Return force form") == "potential" ? mlp::ReturnForceForm::potential
                                                             : mlp::ReturnForceForm::paper;
    const double E = f.get_checked("MLP/Young's modulus", is_non_negative,
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
    lp.damping        = f.get_checked("MLP/Damping", is_non_negative, "eta >= 0 in kg/(m s)");
    lp.thermal_energy = f.get_checked("MLP/Thermal energy", is_non_negative, "k_B T >= 0 in J/m");
    lp.time_step      = f.get_checked("MLP/Time step", is_non_negative, "a time step >= 0 in s (0: half the stable limit)");
    lp.seed           = count(f, "MLP/Seed", 0);
    s.end_time        = f.get_checked("Simulation/End time", is_positive, "a positive end time in s");
    s.statistics_interval = count(f, "MLP/Statistics interval", 1);
    s.snapshot_interval   = count(f, "MLP/Snapshot interval", 0);
    s.plots               = f.get_bool("Output/Plots");
    return s;
  }

  double lattice_density(const CommonSettings &s)
  {
    return s.mass / mlp::area_per_particle(s.lattice, s.interaction.r0);
  }

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

  namespace
  {
    /// Writes the snapshot fields/particles_NNNNN.vtu at time @p t (s), one vertex per
    /// particle with point data velocity (m/s), group, force magnitude |F| (N/m), net and
    /// bond-mean |F_return| (N/m), and adds it to the index particles.pvd of @p fields.
    void write_particles(FieldWriter &fields, double t, const Particles &p,
                         const std::vector<double> &ret_net, const std::vector<double> &ret_bond)
    {
      std::vector<std::array<double, 3>> points;
      PointField velocity{"velocity", 2, {}}, group{"group", 1, {}}, force{"force", 1, {}};
      for (unsigned int i = 0; i < p.size(); ++i)
        {
          points.push_back({{p.position[i].x(), p.position[i].y(), 0}});
          velocity.values.insert(velocity.values.end(), {p.velocity[i].x(), p.velocity[i].y()});
          group.values.push_back(p.group[i]);
          force.values.push_back(p.force[i].norm());
        }
      char name[40];
      std::snprintf(name, sizeof name, "particles_%05u.vtu", fields.n_indexed("particles"));
      atomic_write(fields.directory() + "/" + name,
                   point_cloud_vtu(2, points, {velocity, group, force, {"return_force_net", 1, ret_net},
                                               {"return_force_bond", 1, ret_bond}}));
      fields.index("particles", t, name);
    }

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

    /// An MLP scene as the driver runs it: Langevin steps of MLP/Time step, a statistics
    /// row every Statistics interval steps (the first at t = 0), snapshots every
    /// Snapshot interval steps, and a guard against a body flying apart.
    class MlpSimulation : public Simulation
    {
    public:
      MlpSimulation(const ParameterFile &file, Log &log, SceneFactory make_scene)
        : s(read_common(file))
        , scene_name(file.get("Simulation/Scene"))
        , scene(make_scene(file, s))
      {
        scene->build(particles, box);
        field = std::make_unique<mlp::ForceField>(s.interaction);
        field->set_parallel(false);
        world.field = field.get();
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
        world.time = k * dt;
        world.dt   = dt;
        scene->before_step(world);
        integrator->step(particles, box);
        step = k + 1;
        if (!box.periodic_x)
          check_bounded(particles, centre, bound, time());
        world.time = time();
        scene->after_step(world);
      }

      bool row(Row &row) override
      {
        const double ke = particles.kinetic_energy();
        row("kinetic_energy", ke)("kinetic_temperature", ke / particles.size())
          ("n_pairs", double(field->neighbours().pairs().size()));
        world.time = time();
        scene->measure(world, row);
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
        mlp::return_force_magnitudes(*field, particles, box, net, bond);
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
        world.time = time();
        scene->summarize(world, end.statistics, out.results);
        out.tables = scene->tables();
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
      MlpWorld                                 world{particles, box}; ///< what the scene's hooks see
      std::unique_ptr<MlpScene>                scene;
      std::unique_ptr<mlp::ForceField>         field;
      std::unique_ptr<mlp::LangevinIntegrator> integrator;
      double                                   dt = 0, bound = 0;
      Vec2                                     centre;
      unsigned long                            n_steps = 0, step = 0;
    };
  } // namespace

  void check_scene(const ParameterFile &file, SceneFactory make_scene)
  {
    Particles      particles;
    mlp::Box       box;
    CommonSettings s     = read_common(file);
    auto           scene = make_scene(file, s);
    scene->build(particles, box);
    mlp::ForceField field(s.interaction);
    checked_step(file, field, particles, s.langevin);
  }

  std::unique_ptr<Simulation> make_simulation(const ParameterFile &file, Log &log, SceneFactory make_scene)
  {
    return std::make_unique<MlpSimulation>(file, log, make_scene);
  }
} // namespace tribo::app::mlp_scenes
