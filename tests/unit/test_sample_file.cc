// Sample files (app/sample_file.h): a run's final state written as a sample and read back
// starts the same bodies, to the last bit for the grains.
#include "app/case_parameters.h"
#include "app/sample_file.h"
#include "app/scene_hooks.h"
#include "app/scenes.h"
#include "core/parameter_file.h"
#include "dem/engine/moreau_jean.h"

#include <deal.II/base/parameter_handler.h>

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

using namespace tribo;

namespace
{
  /// The shear cell of 120 grains (cases/shear/small.prm's sample), @p steps steps in,
  /// with the overrides @p settings.
  struct Cell
  {
    dealii::ParameterHandler      prm;
    app::CaseParameters           p;
    std::unique_ptr<app::Scene>   scene;
    dem::ParticleSystem           system;

    explicit Cell(const std::vector<std::string> &settings)
    {
      app::declare_case_parameters(prm);
      ParameterFile file(prm);
      file.parse(std::string(TRIBO_SOURCE_DIR) + "/cases/shear/small.prm");
      for (const auto &s : settings)
        file.set(s);
      p     = app::read_case_parameters(file);
      scene = app::make_shear_scene(file, p);
      scene->build(system);
    }
  };
} // namespace

TEST(SampleFile, AFinalStateReadBackStartsTheSameBodies)
{
  // A sheared state: grains moving and spinning, the lower wall displaced along x.
  Cell first({"Shear cell/Shear start=0", "Shear cell/Pressure ramp time=0"});
  dem::MoreauJean mj(0.5, first.p.law, first.p.solver, 0.1 * first.system.min_radius());
  app::NscdWorld world{first.system};
  for (unsigned long step = 0; step < 400; ++step)
    {
      world.step = step;
      first.scene->before_step(world);
      mj.step(first.system, first.p.time_step);
    }
  const std::string text = first.scene->sample(first.system);
  const std::string path = ::testing::TempDir() + "sample_final.csv";
  std::ofstream(path) << text;

  Cell second({"Shear cell/Sample file=" + path});
  // The same file again, byte for byte: every number read back is the double written.
  EXPECT_EQ(second.scene->sample(second.system), text);
  ASSERT_EQ(second.system.bodies.size(), first.system.bodies.size());
  ASSERT_EQ(second.system.discs.size(), first.system.discs.size());
  std::vector<unsigned int> discs_of(first.system.bodies.size(), 0);
  for (const auto &disc : first.system.discs)
    ++discs_of[disc.body];
  double moving = 0;
  for (std::size_t d = 0; d < first.system.discs.size(); ++d)
    {
      const auto &a = first.system.bodies[first.system.discs[d].body];
      const auto &b = second.system.bodies[second.system.discs[d].body];
      EXPECT_EQ(second.system.discs[d].radius, first.system.discs[d].radius);
      dem::Vec2 xa = first.system.wrap(first.system.disc_centre(d));
      if (xa.x() >= first.system.period)
        xa.x() = 0;
      const dem::Vec2 xb = second.system.disc_centre(d);
      if (discs_of[first.system.discs[d].body] == 1) // a grain: to the last bit
        {
          EXPECT_EQ(xb.x(), xa.x()) << "disc " << d;
          EXPECT_EQ(xb.y(), xa.y()) << "disc " << d;
          EXPECT_EQ(b.velocity, a.velocity) << "disc " << d;
          EXPECT_EQ(b.spin, a.spin) << "disc " << d;
          moving = std::max(moving, a.velocity.norm());
        }
      else // a wall disc: its clump is rebuilt about the centre of mass of its discs
        EXPECT_LT((xb - xa).norm(), 1e-15 * first.system.period) << "disc " << d;
    }
  EXPECT_GT(moving, 0.1); // a state in motion, not the generated one at rest
}
