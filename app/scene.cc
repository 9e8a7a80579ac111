#include "app/scene.h"

namespace tribo::app
{
  std::unique_ptr<Scene> make_collision_scene(const CaseParameters &p);
  std::unique_ptr<Scene> make_compaction_scene(const CaseParameters &p);
  std::unique_ptr<Scene> make_shear_scene(const CaseParameters &p);

  std::unique_ptr<Scene> make_scene(const CaseParameters &p)
  {
    if (p.scene == "collision")
      return make_collision_scene(p);
    if (p.scene == "shear")
      return make_shear_scene(p);
    return make_compaction_scene(p);
  }
} // namespace tribo::app
