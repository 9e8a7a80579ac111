#include "app/shear_upper_body.h"

#include "app/profiles.h"

#include <algorithm>
#include <cmath>

namespace tribo::app
{
  namespace
  {
    /// The rough rigid wall: a clump of discs, x and rotation imposed (at rest), y free
    /// under the load.
    class RigidUpperWall : public UpperBody
    {
    public:
      RigidUpperWall(unsigned int wall, double y_to_surface) : wall(wall), to_surface(y_to_surface) {}

      unsigned int system_body() const override { return wall; }
      double       y_to_surface() const override { return to_surface; }
      double       load_time(double t, double) const override { return t; }

      void before_step(dem::ParticleSystem &s, double normal_force, bool, double speed_cap) override
      {
        s.bodies[wall].load[1] = -normal_force;
        // Compaction: cap the wall's speed (numerical damping, compaction only).
        auto &vy = s.bodies[wall].velocity.y();
        if (speed_cap > 0)
          vy = std::clamp(vy, -speed_cap, speed_cap);
      }

      UpperState state(const dem::ParticleSystem &s, const std::vector<double> &power) const override
      {
        const auto &b = s.bodies[wall];
        return {b.position.y(), b.velocity.y(), b.position.y() - to_surface, power[wall], b.kinetic_energy(), 0.0};
      }

    private:
      unsigned int wall;
      double       to_surface;
    };

    /// A deformable first body (coupling::FirstBody) touched through half-disc elements.
    class DeformableUpperBody : public UpperBody
    {
    public:
      DeformableUpperBody(coupling::FirstBodyParameters p, double surface) : length(p.length)
      {
        half_disc = p.half_disc_diameter > 0 ? p.half_disc_diameter : p.length / coupling::chain_nodes(p);
        p.bottom  = surface + 0.5 * half_disc;
        body      = coupling::make_first_body(p);
        for (unsigned int i = 0; i < body->n_nodes(); ++i)
          face_start.push_back(body->node_position(i).x());
      }

      unsigned int system_body() const override { return LayerProfiles::no_body; }
      double       y_to_surface() const override { return 0.5 * half_disc; }
      double       half_disc_diameter() const override { return half_disc; }
      double       load_time(double t, double start) const override { return t - start; }
      void attach(dem::MoreauJean &mj) override { mj.attach(*body, half_disc, {0, -1}, length); }

      /// The body ramps its own load, with the same law; the compaction damping goes when
      /// shearing starts.
      void before_step(dem::ParticleSystem &, double, bool sliding, double) override
      {
        if (sliding)
          body->start_shearing();
      }

      UpperState state(const dem::ParticleSystem &, const std::vector<double> &) const override
      {
        const double y = body->mean_bottom_y();
        return {y, body->mean_bottom_vy(), y - 0.5 * half_disc, body->external_power(), body->kinetic_energy(),
                body->stored_energy()};
      }

      /// sum_i (x_i - x_i(0)) / n over the chain nodes, each minimum image over L.
      double face_shift() const override
      {
        double sum = 0;
        for (unsigned int i = 0; i < face_start.size(); ++i)
          {
            const double dx = body->node_position(i).x() - face_start[i];
            sum += dx - length * std::round(dx / length);
          }
        return sum / face_start.size();
      }
      bool in_energy_balance() const override { return true; }
      std::vector<std::string> write_fields(const std::string &dir, unsigned int index) const override
      {
        return {body->write_fields(dir, index)};
      }
      std::string describe() const override { return body->describe(); }
      void        summarize(JsonObject &j) const override { body->summarize(j); }
      void        save(CheckpointOut &ar) const override { body->save(ar); }
      void        load(CheckpointIn &ar) override { body->load(ar); }

    private:
      double                               length, half_disc = 0;
      std::unique_ptr<coupling::FirstBody> body;
      std::vector<double>                  face_start; ///< x of its chain nodes at the start, m
    };
  } // namespace

  std::unique_ptr<UpperBody> make_rigid_upper_wall(dem::ParticleSystem &s, unsigned int wall, double density,
                                                   double thickness, double length, double y_to_surface)
  {
    auto &u                 = s.bodies[wall];
    u.drive                 = {{dem::Drive::velocity, dem::Drive::force, dem::Drive::velocity}};
    const double discs_mass = u.mass;
    u.mass                  = density * thickness * length;
    u.inertia *= u.mass / discs_mass;
    return std::make_unique<RigidUpperWall>(wall, y_to_surface);
  }

  std::unique_ptr<UpperBody> make_deformable_upper_body(coupling::FirstBodyParameters p, double surface)
  {
    return std::make_unique<DeformableUpperBody>(std::move(p), surface);
  }
} // namespace tribo::app
