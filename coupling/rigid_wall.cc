/// @file The rigid model: the upper first body as a rough wall of discs, a clump in the
/// scene's particle system, x and rotation imposed (at rest), y free under the load, with
/// the mass of the first body it stands for.

#include "coupling/models.h"

#include "core/parameter_file.h"
#include "dem/engine/particle_system.h"

#include <deal.II/base/parameter_handler.h>

#include <algorithm>

namespace tribo::coupling
{
  void RigidWallParameters::declare(dealii::ParameterHandler &prm)
  {
    prm.declare_entry("Compaction speed limit", "1", dealii::Patterns::Double(),
                      "Before Shear start, the upper wall's vertical speed is capped at this value, m/s "
                      "(>= 0; 0: no cap), so that the compaction stroke under P cannot hit the grains "
                      "at tens of m/s and tunnel into the layer. Not applied while shearing, nor to a deformable "
                      "upper body (see Upper body compaction damping).");
  }

  void RigidWallParameters::parse(const ParameterFile &f, FirstBodyParameters &p)
  {
    p.rigid.compaction_speed_limit =
      f.get_checked(p.section.entry("Compaction speed limit"), is_non_negative, "a speed >= 0 in m/s");
  }

  namespace
  {
    class RigidWall : public FirstBody
    {
    public:
      /// @p y_to_surface: the wall's mean disc radius, m.
      RigidWall(unsigned int wall, double y_to_surface, double speed_limit)
        : wall(wall), to_surface(y_to_surface), speed_limit(speed_limit)
      {}

      unsigned int system_body() const override { return wall; }
      double       y_to_surface() const override { return to_surface; }
      double       load_time(double t, double) const override { return t; }

      /// The load on its y; before the shear its |v_y| capped at the compaction speed
      /// limit (numerical damping of the compaction stroke).
      void before_step(dem::ParticleSystem &s, double normal_force, bool sliding) override
      {
        s.bodies[wall].load[1] = -normal_force;
        auto &vy               = s.bodies[wall].velocity.y();
        if (!sliding && speed_limit > 0)
          vy = std::clamp(vy, -speed_limit, speed_limit);
      }

      FirstBodyState state(const dem::ParticleSystem &s, const std::vector<double> &power) const override
      {
        const auto &b = s.bodies[wall];
        return {b.position.y(), b.velocity.y(), b.position.y() - to_surface, power[wall], b.kinetic_energy(), 0.0};
      }

    private:
      unsigned int wall;
      double       to_surface, speed_limit;
    };
  } // namespace

  std::unique_ptr<FirstBody> place_rigid_wall(const FirstBodyParameters &p, const FirstBodyPlacement &where)
  {
    const auto [clump, diameter] = where.add_wall();
    auto &u                      = where.system.bodies[clump];
    u.drive                      = {{dem::Drive::velocity, dem::Drive::force, dem::Drive::velocity}};
    const double discs_mass      = u.mass;
    u.mass                       = p.density * p.thickness * p.length;
    u.inertia *= u.mass / discs_mass;
    return std::make_unique<RigidWall>(clump, 0.5 * diameter, p.rigid.compaction_speed_limit);
  }
} // namespace tribo::coupling
