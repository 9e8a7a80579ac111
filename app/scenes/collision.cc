// Two discs in a head-on collision along x (Cao et al. 2011, Fig. 8).
#include "app/scene.h"

#include <boost/archive/binary_iarchive.hpp>
#include <boost/archive/binary_oarchive.hpp>

#include <algorithm>
#include <cmath>

namespace tribo::app
{
  namespace
  {
    /// Disc 0 moves at +v/2 towards disc 1 at -v/2 (v = Impact velocity).
    class CollisionScene : public Scene
    {
    public:
      explicit CollisionScene(const CaseParameters &p) : Scene(p) {}

      void build(dem::ParticleSystem &s) override
      {
        const auto  &c = prm.collision;
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
        if (prm.collision.time_step_ratio > 0)
          return std::sqrt(m_eff / prm.law.stiffness) / prm.collision.time_step_ratio;
        return prm.time_step;
      }

      void measure(const dem::ParticleSystem &s, const dem::MoreauJean &mj, const dem::StepReport &,
                   Row &row) override
      {
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

      bool finished() const override { return prm.collision.stop_when_separated && separated; }

      void summarize(const dem::ParticleSystem &s, const TimeSeries &, JsonObject &j) override
      {
        const double dt_star = std::sqrt(m_eff / prm.law.stiffness);
        const double v_in    = prm.collision.impact_velocity;
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
      double        m_eff = 0, energy_start = 0, last_gap = 0, peak_force = 0;
      unsigned long contact_steps = 0;
      bool   touched = false, separated = false;
    };
  } // namespace

  std::unique_ptr<Scene> make_collision_scene(const CaseParameters &p)
  {
    return std::make_unique<CollisionScene>(p);
  }
} // namespace tribo::app
