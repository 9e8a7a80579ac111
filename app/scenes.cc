#include "app/scenes.h"

#include "app/case_parameters.h"
#include "app/scene_hooks.h"
#include "core/errors.h"
#include "core/parameter_file.h"

#include <boost/property_tree/json_parser.hpp>
#include <boost/property_tree/ptree.hpp>

#include <algorithm>
#include <filesystem>

namespace tribo::app
{
  namespace
  {
    /// Gives the row of scene @p name (a module's scene, in this build) its @p hooks.
    void attach(std::vector<SceneEntry> &table, const std::string &name, const SceneHooks &hooks)
    {
      for (SceneEntry &row : table)
        if (row.name == name)
          row.hooks = hooks;
    }

    /// The rows of every scene; those of the particle modules get their hooks only when
    /// built (app/scene_hooks.h).
    std::vector<SceneEntry> make_table()
    {
      std::vector<SceneEntry> table = {
        {"collision", "two discs, Cao et al. 2011 Fig. 8", "", collision_hooks()},
        {"shear",
         "the third-body shear cell of Cao et al. 2011: a periodic layer of discs compacted, then sheared, "
         "between two rough walls",
         "", shear_hooks()},
        {"sph_slider", "the SPH slider on a substrate of Maveyraud et al. 1999, subsection SPH slider",
         "TRIBO_WITH_SPH", {}},
        {"sph_plate", "the SPH cantilever-plate check, subsection SPH plate", "TRIBO_WITH_SPH", {}},
        {"mlp_ordering",
         "movable lattice particles of Popov and Filippov 2006 ordering from random positions, "
         "subsections MLP and MLP ordering",
         "TRIBO_WITH_MLP", {}},
        {"mlp_compression", "an MLP slab compressed between two tractions, subsections MLP and MLP compression",
         "TRIBO_WITH_MLP", {}},
        {"mlp_beams", "two MLP beams in contact under a transverse traction, subsections MLP and MLP beams",
         "TRIBO_WITH_MLP", {}}};
#ifdef TRIBO_WITH_SPH_SCENES
      attach(table, "sph_slider", sph_slider_hooks());
      attach(table, "sph_plate", sph_plate_hooks());
#endif
#ifdef TRIBO_WITH_MLP_SCENES
      attach(table, "mlp_ordering", mlp_ordering_hooks());
      attach(table, "mlp_compression", mlp_compression_hooks());
      attach(table, "mlp_beams", mlp_beams_hooks());
#endif
      return table;
    }
  } // namespace

  const std::vector<SceneEntry> &scenes()
  {
    static const std::vector<SceneEntry> table = make_table();
    return table;
  }

  const SceneEntry &scene_named(const std::string &name)
  {
    for (const SceneEntry &s : scenes())
      if (s.name == name)
        return s;
    throw std::logic_error("scene_named: no scene '" + name + "' (Simulation/Scene's Selection allowed it)");
  }

  namespace
  {
    /// The entry Scene (Selection and documentation from scenes()) in the current
    /// subsection (Simulation).
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
  } // namespace

  void declare_case_parameters(dealii::ParameterHandler &prm)
  {
    declare_common_parameters(prm);
    prm.enter_subsection("Simulation");
    declare_scene_entry(prm);
    prm.leave_subsection();
    std::vector<void (*)(dealii::ParameterHandler &)> declared;
    for (const SceneEntry &s : scenes())
      for (const auto declare : s.hooks.declare)
        if (std::find(declared.begin(), declared.end(), declare) == declared.end())
          {
            declare(prm);
            declared.push_back(declare);
          }
  }

  RunRecord read_run_record(const std::string &dir)
  {
    namespace fs = std::filesystem;
    RunRecord r;
    try
      {
        boost::property_tree::ptree tree;
        boost::property_tree::read_json((fs::path(dir) / "summary.json").string(), tree);
        r.status         = tree.get<std::string>("status", "");
        r.scene          = tree.get<std::string>("scene", "");
        r.simulated_time = tree.get<double>("simulated_time", 0.0);
      }
    catch (const std::exception &)
      {} // status "": no readable summary
    try
      {
        dealii::ParameterHandler prm;
        declare_case_parameters(prm);
        ParameterFile parameters(prm);
        parameters.parse((fs::path(dir) / "parameters.prm").string());
        r.length = parameters.get_double("Shear cell/Length");
      }
    catch (const std::exception &)
      {} // length 0: no readable parameters
    return r;
  }
} // namespace tribo::app
