#include "app/scenes.h"

#include "app/case_parameters.h"
#include "app/nscd_simulation.h"
#include "app/particle_scenes.h"
#include "core/errors.h"

#include <algorithm>

namespace tribo::app
{
  namespace
  {
    std::unique_ptr<Simulation> make_nscd(const ParameterFile &, const CaseParameters &p, Log &log)
    {
      return make_nscd_simulation(p, log);
    }

#ifdef TRIBO_WITH_SPH_SCENES
    std::unique_ptr<Simulation> make_sph(const ParameterFile &f, const CaseParameters &, Log &log)
    {
      return make_sph_simulation(f, log);
    }
    /// An SPH scene: its subsections, check and factory.
    SceneEntry sph_scene(const std::string &name, const std::string &description)
    {
      return {name, description, "TRIBO_WITH_SPH", declare_sph_scene_parameters, check_sph_scene, make_sph};
    }
#else
    SceneEntry sph_scene(const std::string &name, const std::string &description)
    {
      return {name, description, "TRIBO_WITH_SPH"};
    }
#endif

#ifdef TRIBO_WITH_MLP_SCENES
    std::unique_ptr<Simulation> make_mlp(const ParameterFile &f, const CaseParameters &, Log &log)
    {
      return make_mlp_simulation(f, log);
    }
    /// An MLP scene: its subsections, check and factory.
    SceneEntry mlp_scene(const std::string &name, const std::string &description)
    {
      return {name, description, "TRIBO_WITH_MLP", declare_mlp_scene_parameters, check_mlp_scene, make_mlp};
    }
#else
    SceneEntry mlp_scene(const std::string &name, const std::string &description)
    {
      return {name, description, "TRIBO_WITH_MLP"};
    }
#endif
  } // namespace

  const std::vector<SceneEntry> &scenes()
  {
    static const std::vector<SceneEntry> table = {
      {"collision", "two discs, Cao et al. 2011 Fig. 8", "", nullptr, nullptr, make_nscd},
      {"shear",
       "the third-body shear cell of Cao et al. 2011: a periodic layer of discs compacted, then sheared, "
       "between two rough walls",
       "", nullptr, nullptr, make_nscd},
      sph_scene("sph_slider", "the SPH slider on a substrate of Maveyraud et al. 1999, subsection SPH slider"),
      sph_scene("sph_plate", "the SPH cantilever-plate check, subsection SPH plate"),
      mlp_scene("mlp_ordering",
                "movable lattice particles of Popov and Filippov 2006 ordering from random positions, "
                "subsections MLP and MLP ordering"),
      mlp_scene("mlp_compression", "an MLP slab compressed between two tractions, subsections MLP and "
                                   "MLP compression"),
      mlp_scene("mlp_beams", "two MLP beams in contact under a transverse traction, subsections MLP and "
                             "MLP beams")};
    return table;
  }

  const SceneEntry &scene_named(const std::string &name)
  {
    for (const SceneEntry &s : scenes())
      if (s.name == name)
        return s;
    throw std::logic_error("scene_named: no scene '" + name + "' (Simulation/Scene's Selection allowed it)");
  }

  void declare_scene_entry(dealii::ParameterHandler &prm)
  {
    std::string names, text = "What to simulate: ";
    for (const SceneEntry &s : scenes())
      {
        names += (names.empty() ? "" : "|") + s.name;
        text += (&s == &scenes().front() ? "'" : "; '") + s.name + "' (" + s.description + ")";
      }
    prm.declare_entry("Scene", "shear", dealii::Patterns::Selection(names), text + ".");
  }

  void declare_scene_subsections(dealii::ParameterHandler &prm)
  {
    std::vector<void (*)(dealii::ParameterHandler &)> declared;
    for (const SceneEntry &s : scenes())
      if (s.declare && std::find(declared.begin(), declared.end(), s.declare) == declared.end())
        {
          s.declare(prm);
          declared.push_back(s.declare);
        }
  }
} // namespace tribo::app
