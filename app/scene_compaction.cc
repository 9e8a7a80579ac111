// A periodic layer of discs pressed between two rough walls (clumps of discs):
// the lower wall is fixed, the upper one is pushed down by P L (N/m) and is
// free in y only. The compaction stage of the third-body shear cell.
#include "app/scene.h"

#include <algorithm>
#include <cmath>
#include <random>

namespace tribo::app
{
  namespace
  {
    class CompactionScene : public Scene
    {
    public:
      explicit CompactionScene(const CaseParameters &p) : Scene(p), rng(p.compaction.seed) {}

      void build(dem::ParticleSystem &s) override
      {
        const auto  &k     = prm.compaction;
        const double d_max = k.mean_diameter * (1 + k.diameter_spread);
        s.period           = k.length;

        // Lower wall: a row of discs along y = 0, fixed.
        lower = add_wall(s, d_max / 2);
        for (auto &d : s.bodies[lower].drive)
          d = dem::Drive::velocity;

        // Grains on a loose triangular lattice above it (neighbours 1.02 d_max
        // apart, so no initial overlap), sizes drawn at random.
        const double       pitch   = 1.02 * d_max;
        const unsigned int columns = std::max(1u, unsigned(k.length / pitch));
        const double       dx      = k.length / columns;
        const double       dy      = std::sqrt(std::max(pitch * pitch - 0.25 * dx * dx, 0.0));
        const unsigned int rows    = (k.n_discs + columns - 1) / columns;
        for (unsigned int i = 0; i < k.n_discs; ++i)
          {
            const unsigned int row = i / columns;
            const double       x   = (i % columns + 0.5 + 0.5 * (row % 2)) * dx;
            const double       y   = d_max + 0.5 * pitch + row * dy;
            s.add_disc({x, y}, 0.5 * draw_diameter(), k.density);
          }

        // Upper wall above the grains: free in y under -P L, fixed in x and rotation,
        // with the mass of the first body it stands for.
        upper = add_wall(s, d_max + 0.5 * pitch + (rows - 1) * dy + pitch);
        auto &u   = s.bodies[upper];
        u.drive   = {{dem::Drive::velocity, dem::Drive::force, dem::Drive::velocity}};
        const double wall_mass = u.mass;
        u.mass    = k.density * k.upper_body_thickness * k.length;
        u.inertia *= u.mass / wall_mass;
      }

      void before_step(dem::ParticleSystem &s, unsigned long step) override
      {
        const auto  &k    = prm.compaction;
        const double ramp = k.ramp_steps > 0 ? std::min(1.0, double(step + 1) / k.ramp_steps) : 1.0;
        s.bodies[upper].load[1] = -ramp * k.pressure * k.length;
      }

      std::vector<std::string> columns() const override
      {
        return {"upper_wall_y", "upper_wall_vy", "lower_wall_normal_force", "applied_force",
                "solid_fraction", "power_lower_wall", "power_upper_wall"};
      }

      std::vector<double> measure(const dem::ParticleSystem &s, const dem::MoreauJean &mj,
                                  const dem::StepReport &) override
      {
        const auto &f = mj.contact_force();
        // The layer's solid fraction between the wall disc centres.
        const double height = s.bodies[upper].position.y() - s.bodies[lower].position.y();
        return {s.bodies[upper].position.y(), s.bodies[upper].velocity.y(),
                f.empty() ? 0.0 : -f[lower].y(), -s.bodies[upper].load[1],
                grain_area(s) / (height * prm.compaction.length),
                mj.external_power().empty() ? 0.0 : mj.external_power()[lower],
                mj.external_power().empty() ? 0.0 : mj.external_power()[upper]};
      }

      void summarize(const dem::ParticleSystem &s, const TimeSeries &stats, JsonObject &j) override
      {
        // Mean lower-wall force over the last fifth of the rows.
        const auto   fl = stats.column("lower_wall_normal_force");
        const auto   fa = stats.column("applied_force");
        const auto   phi = stats.column("solid_fraction");
        const size_t n  = fl.size(), first = n - std::max<size_t>(1, n / 5);
        double       sum_l = 0, sum_a = 0, sum_phi = 0;
        for (size_t i = first; i < n; ++i)
          {
            sum_l += fl[i];
            sum_a += fa[i];
            sum_phi += phi[i];
          }
        const double m = n - first;
        const auto  &k = prm.compaction;
        j.set("target_normal_force", k.pressure * k.length);
        j.set("mean_lower_wall_normal_force", n ? sum_l / m : 0.0);
        j.set("normal_force_ratio", n && sum_a > 0 ? sum_l / sum_a : 0.0);
        j.set("mean_solid_fraction", n ? sum_phi / m : 0.0);
        j.set("upper_wall_y", s.bodies[upper].position.y());
        j.set("n_free_discs", long(k.n_discs));
      }

    private:
      double draw_diameter()
      {
        const auto &k = prm.compaction;
        std::uniform_real_distribution<double> u(1 - k.diameter_spread, 1 + k.diameter_spread);
        return k.mean_diameter * u(rng);
      }

      /// A rough wall: discs of drawn sizes spread evenly along the period at height y.
      unsigned int add_wall(dem::ParticleSystem &s, double y)
      {
        const auto         &k = prm.compaction;
        const unsigned int  n = std::max(1u, unsigned(std::round(k.length / k.mean_diameter)));
        std::vector<double> radii(n);
        std::vector<dem::Vec2> centres(n);
        for (unsigned int i = 0; i < n; ++i)
          {
            radii[i]   = 0.5 * draw_diameter();
            centres[i] = {(i + 0.5) * k.length / n, y};
          }
        return s.add_clump(centres, radii, k.density);
      }

      double grain_area(const dem::ParticleSystem &s) const
      {
        double a = 0;
        for (const auto &d : s.discs)
          if (d.body != lower && d.body != upper)
            a += M_PI * d.radius * d.radius;
        return a;
      }

      std::mt19937 rng;
      unsigned int lower = 0, upper = 0;
    };
  } // namespace

  std::unique_ptr<Scene> make_compaction_scene(const CaseParameters &p)
  {
    return std::make_unique<CompactionScene>(p);
  }
} // namespace tribo::app
