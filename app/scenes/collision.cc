// Two discs in a head-on collision along x (Cao et al. 2011, Fig. 8).
#include "app/nscd_simulation.h"
#include "app/scene.h"
#include "app/scene_hooks.h"

#include <boost/archive/binary_iarchive.hpp>
#include <boost/archive/binary_oarchive.hpp>

#include <algorithm>
#include <cmath>

namespace tribo::app
{
  namespace
  {
    /// Two discs colliding head-on (subsection Collision).
    struct CollisionParameters
    {
      double diameter;         ///< m, both discs
      double density;          ///< kg/m^3
      double impact_velocity;  ///< relative normal velocity at t = 0, m/s (> 0 approaching)
      double initial_gap;      ///< m
      double time_step_ratio;  ///< dt*/dt with dt* = sqrt(m_eff/k); 0: use Simulation/Time step
      bool   stop_when_separated;

      static void declare(dealii::ParameterHandler &prm)
      {
        using dealii::Patterns::Double;
        prm.enter_subsection("Collision");
        prm.declare_entry("Diameter", "1.2e-6", Double(), "Diameter of both discs, m (> 0).");
        prm.declare_entry("Density", "7800", Double(), "Density, kg/m^3 (> 0).");
        prm.declare_entry("Impact velocity", "2", Double(),
                          "Relative normal velocity at t = 0, m/s: > 0 approaching, < 0 separating, not 0.");
        prm.declare_entry("Initial gap", "1e-10", Double(), "Gap between the discs at t = 0, m (> -diameter/2).");
        prm.declare_entry("Time step ratio", "0", Double(),
                          "dt*/dt with dt* = sqrt(m_eff/k), >= 0; if > 0 it sets the time step and "
                          "Simulation/Time step is ignored.");
        prm.declare_entry("Stop when separated", "true", dealii::Patterns::Bool(),
                          "End the run once the discs have touched and are farther apart than the "
                          "detection distance.");
        prm.leave_subsection();
      }

      /// InputError naming the entry for a value out of range.
      static CollisionParameters parse(const ParameterFile &f)
      {
        CollisionParameters c;
        c.diameter = f.get_checked("Collision/Diameter", is_positive, "a positive diameter in m");
        c.density  = f.get_checked("Collision/Density", is_positive, "a positive density in kg/m^3");
        c.impact_velocity = f.get_checked("Collision/Impact velocity",
                                          [](double v) { return v != 0 && std::isfinite(v); },
                                          "a non-zero velocity in m/s");
        c.initial_gap = f.get_checked("Collision/Initial gap", [&](double v) { return v > -0.5 * c.diameter; },
                                      "a gap in m larger than minus half the diameter");
        c.time_step_ratio     = f.get_checked("Collision/Time step ratio", is_non_negative, "a ratio >= 0");
        c.stop_when_separated = f.get_bool("Collision/Stop when separated");
        return c;
      }
    };

    /// Disc 0 moves at +v/2 towards disc 1 at -v/2 (v = Impact velocity).
    class CollisionScene : public Scene
    {
    public:
      CollisionScene(const CaseParameters &p, const CollisionParameters &c) : Scene(p), collision(c) {}

      void build(dem::ParticleSystem &s) override
      {
        const auto  &c = collision;
        const double r = 0.5 * c.diameter;
        s.add_disc({0, 0}, r, c.density);
        s.add_disc({2 * r + c.initial_gap, 0}, r, c.density);
        s.bodies[0].velocity = {0.5 * c.impact_velocity, 0};
        s.bodies[1].velocity = {-0.5 * c.impact_velocity, 0};
        m_eff        = 0.5 * s.bodies[0].mass;
        energy_start = s.kinetic_energy();
      }

      /// dt*/ratio with dt* = sqrt(m_eff/k) when a ratio is given.
      double time_step(const dem::ParticleSystem &) const override
      {
        if (collision.time_step_ratio > 0)
          return std::sqrt(m_eff / prm.law.stiffness) / collision.time_step_ratio;
        return prm.time_step;
      }

      void measure(const NscdWorld &w, Row &row) override
      {
        const auto &s  = w.system;
        const auto &mj = *w.integrator;
        const double gap = (s.bodies[1].position - s.bodies[0].position).norm() -
                           s.discs[0].radius - s.discs[1].radius;
        const double vrel = s.bodies[1].velocity.x() - s.bodies[0].velocity.x();
        double       fn   = 0;
        if (!mj.contacts().empty())
          fn = mj.contact_force()[1].x();
        // Round-off forces (a cohesive pair at rest) count as no force.
        peak_force        = std::max(peak_force, std::abs(fn));
        const bool loaded = std::abs(fn) > 1e-9 * std::max(prm.law.cohesion, peak_force);
        if (loaded)
          {
            touched = true;
            ++contact_steps;
          }
        if (touched && !loaded && gap > mj.detection_distance())
          separated = true;
        last_gap = gap;
        row("gap", gap)("relative_normal_velocity", vrel)("normal_force", fn)
          ("energy_change", s.kinetic_energy() / energy_start - 1);
      }

      bool finished() const override { return collision.stop_when_separated && separated; }

      void summarize(const NscdWorld &w, const TimeSeries &, JsonObject &j) override
      {
        const auto &s = w.system;
        const double dt_star = std::sqrt(m_eff / prm.law.stiffness);
        const double v_in    = collision.impact_velocity;
        const double v_out   = s.bodies[1].velocity.x() - s.bodies[0].velocity.x();
        j.set("effective_mass", m_eff);
        j.set("dt_star", dt_star);
        j.set("time_step_ratio", dt_star / time_step(s));
        j.set("escape_velocity", std::sqrt(2 * prm.law.cohesion * prm.law.cohesion_range / m_eff));
        j.set("separated", separated);
        j.set("kinetic_energy_initial", energy_start);
        j.set("kinetic_energy_final", s.kinetic_energy());
        // Only a pair that has separated has a final kinetic energy to compare:
        // a bound pair still exchanges energy with the contact (null in JSON).
        j.set("energy_loss", separated ? 1 - s.kinetic_energy() / energy_start : NAN);
        j.set("restitution_coefficient", !separated ? NAN : v_in > 0 ? v_out / v_in : -v_out / v_in);
        j.set("final_gap", last_gap);
        j.set("contact_duration", contact_steps * time_step(s));
        j.set("elastic_contact_duration", M_PI * dt_star);
      }

      void save(CheckpointOut &ar) const override
      {
        ar << m_eff << energy_start << last_gap << peak_force << contact_steps << touched << separated;
      }

      void load(CheckpointIn &ar) override
      {
        ar >> m_eff >> energy_start >> last_gap >> peak_force >> contact_steps >> touched >> separated;
      }

    private:
      CollisionParameters collision;
      double        m_eff = 0, energy_start = 0, last_gap = 0, peak_force = 0;
      unsigned long contact_steps = 0;
      bool   touched = false, separated = false;
    };
  } // namespace

  SceneHooks collision_hooks()
  {
    return {{CollisionParameters::declare},
            [](const ParameterFile &f) { CollisionParameters::parse(f); },
            [](const ParameterFile &f, const CaseParameters &p, Log &log) {
              return make_nscd_simulation(p, std::make_unique<CollisionScene>(p, CollisionParameters::parse(f)), log);
            }};
  }
} // namespace tribo::app
