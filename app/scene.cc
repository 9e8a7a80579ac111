#include "app/scene.h"

namespace tribo::app
{
  std::unique_ptr<Scene> make_collision_scene(const CaseParameters &p);
  std::unique_ptr<Scene> make_shear_scene(const CaseParameters &p);

  std::unique_ptr<Scene> make_scene(const CaseParameters &p)
  {
    if (p.scene == "collision")
      return make_collision_scene(p);
    return make_shear_scene(p);
  }
} // namespace tribo::app
