#include "app/run.h"

#include "app/case_parameters.h"
#include "app/driver.h"
#include "app/scenes.h"
#include "core/checkpoint.h"
#include "core/errors.h"
#include "core/output.h"
#include "core/parameter_file.h"
#include "core/run_control.h"
#include "core/serialization.h"
#include "coupling/first_body_models.h"
#include "dem/solvers/methods.h"

#include <boost/property_tree/json_parser.hpp>
#include <boost/property_tree/ptree.hpp>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <chrono>
#include <iostream>
#include <map>
#include <cmath>
#include <filesystem>
#include <sstream>

namespace tribo::app
{
  namespace fs = std::filesystem;

  namespace
  {
    /// The upper first body's entries a resumed run may change, with their subsection.
    std::vector<std::string> first_body_entries_that_may_change()
    {
      std::vector<std::string> entries;
      for (const std::string &e : coupling::entries_that_may_change_on_resume())
        entries.push_back("Shear cell/" + e);
      return entries;
    }

    /// "Solver/*, Output/*, Simulation/End time and ..." for the refusal's message.
    std::string changeable_entries()
    {
      std::string text = "Solver/*, Output/*, Simulation/End time, Simulation/Most substeps, Simulation/Most substeps on retake";
      const auto  first_body = first_body_entries_that_may_change();
      for (std::size_t i = 0; i < first_body.size(); ++i)
        text += (i + 1 == first_body.size() ? " and " : ", ") + first_body[i];
      return text;
    }
  } // namespace

  bool may_change_on_resume(const std::string &entry)
  {
    const auto first_body = first_body_entries_that_may_change();
    return entry.rfind("Solver/", 0) == 0 || entry.rfind("Output/", 0) == 0 || entry == "Simulation/End time" ||
           entry == "Simulation/Most substeps" || entry == "Simulation/Most substeps on retake" ||
           std::find(first_body.begin(), first_body.end(), entry) != first_body.end();
  }

  std::string resume_changes(const std::map<std::string, std::string> &saved,
                             const ParameterFile &now, const std::string &dir)
  {
    std::string changed, defaulted;
    for (const auto &[entry, value] : now.resolved())
      {
        const auto        it     = saved.find(entry);
        const std::string before = it == saved.end() ? "(absent)" : it->second;
        if (before == value)
          continue;
        if (it == saved.end() && now.is_default(entry))
          {
            defaulted += (defaulted.empty() ? "" : ", ") + entry + " = " + value;
            continue;
          }
        if (!may_change_on_resume(entry))
          throw InputError("--resume " + dir + ": entry '" + entry + "' is '" + value +
                           "' in the case but '" + before + "' in the checkpoint; a resumed run "
                           "may change only " + changeable_entries());
        changed += (changed.empty() ? "" : ", ") + entry + " " + before + " -> " + value;
      }
    return (changed.empty() ? "" : "; changed: " + changed) +
           (defaulted.empty() ? "" : "; not in the checkpoint, at their defaults: " + defaulted);
  }

  std::string run_status(const std::string &dir)
  {
    try
      {
        boost::property_tree::ptree tree;
        boost::property_tree::read_json((fs::path(dir) / "summary.json").string(), tree);
        return tree.get<std::string>("status", "");
      }
    catch (const std::exception &)
      {
        return "";
      }
  }

  std::string parameter_reference()
  {
    dealii::ParameterHandler prm;
    declare_case_parameters(prm);
    std::ostringstream json;
    prm.print_parameters(json, dealii::ParameterHandler::JSON);
    boost::property_tree::ptree tree;
    std::istringstream          is(json.str());
    boost::property_tree::read_json(is, tree);

    // A case file with every entry at its default, documented, and its allowed values.
    std::ostringstream os;
    os << "# tribo parameters: every entry with its default; units in the text.\n"
       << "# Copy this file, keep the entries you change.\n";
    for (const auto &[section, entries] : tree)
      {
        os << "\nsubsection " << demangle_parameter_name(section) << "\n";
        for (const auto &[name, entry] : entries)
          {
            os << "  # " << entry.get<std::string>("documentation") << "\n"
               << "  # Allowed: " << entry.get<std::string>("pattern_description") << "\n"
               << "  set " << demangle_parameter_name(name) << " = " << entry.get<std::string>("default_value")
               << "\n\n";
          }
        os << "end\n";
      }
    return os.str();
  }

  int run_case(const RunOptions &o)
  {
    dealii::ParameterHandler prm;
    declare_case_parameters(prm);
    ParameterFile file(prm);
    file.parse(o.case_file);
    for (const auto &s : o.overrides)
      file.set(s);
    CaseParameters p = read_case_parameters(file);
    p.ranks          = o.ranks;
    const unsigned int ranks  = rank_count(o.ranks);
    const bool         writes = rank_in(o.ranks) == 0;
    // The scene's own entries are checked before anything is written, and its paths made
    // absolute in parameters.prm: a resumed run, or one started from it elsewhere, finds them.
    const SceneEntry &scene = scene_named(p.scene);
    if (!scene.hooks.make)
      throw InputError(o.case_file + ": Simulation/Scene = " + p.scene + " is not in this build (it needs " +
                       scene.build_option + "=ON)");
    if (scene.hooks.check)
      scene.hooks.check(file);
    if (scene.hooks.resolve)
      scene.hooks.resolve(file);
    if (ranks > 1 && !scene.build_option.empty())
      throw InputError(o.case_file + ": Simulation/Scene = " + p.scene + " runs in one process; only the disc "
                       "scenes split their contact solve over MPI ranks (docs/scaling.md): run it without mpirun");
    using Method = dem::SolverParameters::Method;
    if (ranks > 1 && p.solver.method != Method::apgs && p.solver.method != Method::nlgs)
      throw InputError(o.case_file + ": " + p.solver.section.entry("Method") + " = " + dem::method_name(p.solver.method) +
                       ": on " + std::to_string(ranks) + " MPI ranks the contact solve is APGS's or NLGS's sweeps "
                       "split into bands (docs/scaling.md); set it to apgs or nlgs, or run the case without mpirun");
    if (ranks > 1 && p.solver.method == Method::nlgs &&
        (p.solver.order != dem::SolverParameters::Order::fixed || p.solver.streams > 1))
      throw InputError(o.case_file + ": " + p.solver.section.entry("Contact order") + " and " +
                       p.solver.section.entry("Streams") + ": on " + std::to_string(ranks) +
                       " MPI ranks NLGS sweeps each rank's contacts in detection order (docs/scaling.md); "
                       "set them to fixed and 1, or run the case without mpirun");
    if (o.check_only)
      {
        if (!o.quiet)
          std::cout << o.case_file << ": OK (scene " << p.scene << ")" << std::endl;
        return exit_ok;
      }

    // The output directory: emptied of a previous run's files, or the one being resumed.
    const bool resuming = !o.resume_dir.empty();
    if (resuming && !o.output_dir.empty() && fs::path(o.output_dir) != fs::path(o.resume_dir))
      throw InputError("--output " + o.output_dir + " and --resume " + o.resume_dir +
                       " name different directories: a resumed run writes where it started");
    const fs::path dir = resuming ? fs::path(o.resume_dir)
                         : o.output_dir.empty() ? fs::path("output") / fs::path(o.case_file).stem()
                                                : fs::path(o.output_dir);
    const fs::path checkpoint_file = dir / "checkpoint.bin";
    if (resuming && !fs::exists(checkpoint_file))
      throw InputError("--resume " + dir.string() + ": no checkpoint.bin there" +
                       (run_status(dir.string()) == "complete"
                          ? std::string(" (the run is complete: nothing to resume)")
                          : std::string(" (none was written: Output/Checkpoint interval and "
                                        "Checkpoint step interval were 0, or the run stopped "
                                        "before the first one)")));
    const std::map<std::string, std::string> resolved = file.resolved();
    // A resumption is checked before anything is written: a refused one changes nothing.
    std::string changes;
    if (resuming)
      read_checkpoint(
        checkpoint_file.string(),
        [&](CheckpointIn &ar) {
          std::map<std::string, std::string> saved;
          ar >> saved;
          changes = resume_changes(saved, file, o.resume_dir);
        },
        false);
    std::string not_prepared;
    if (!resuming && writes)
      try
        {
          fs::create_directories(dir / "fields");
          for (const char *name : {"statistics.csv", "results.h5", "summary.json", "log.txt",
                                   "original.prm", "parameters.prm", "profiles.csv", "mu.png",
                                   "power.png", "profiles.png", "checkpoint.bin", "sample_final.csv"})
            fs::remove(dir / name);
          for (const auto &entry : fs::directory_iterator(dir / "fields"))
            fs::remove(entry.path());
        }
      catch (const fs::filesystem_error &e)
        {
          not_prepared = "--output " + dir.string() + ": cannot prepare the directory (" + e.code().message() + ")";
        }
    // On several ranks the others write their pieces of the fields into dir/fields: they wait
    // until rank 0 has prepared it (or failed to).
    if (ranks > 1)
      {
        int failed = !not_prepared.empty();
        MPI_Bcast(&failed, 1, MPI_INT, 0, o.ranks);
        if (failed && not_prepared.empty())
          not_prepared = "--output " + dir.string() + ": rank 0 could not prepare the directory";
      }
    if (!not_prepared.empty())
      throw InputError(not_prepared);

    JsonObject summary;
    summary.set("status", "running");
    summary.set("case", o.case_file);
    if (writes)
      {
        atomic_write((dir / "summary.json").string(), summary.to_string());
        atomic_write((dir / "original.prm").string(), file.original_text());
        std::ostringstream os;
        prm.print_parameters(os, dealii::ParameterHandler::PRM);
        atomic_write((dir / "parameters.prm").string(), os.str());
      }

    // The other ranks of a case run on several log nothing.
    Log log;
    log.open(writes ? (dir / "log.txt").string() : std::string(), writes && !o.quiet);
    log("tribo run " + o.case_file + " -> " + dir.string());

    RunCheckpoint checkpoint(dir.string(), resolved, p.checkpoint_interval, p.checkpoint_step_interval,
                             resuming, changes);
    // The scene, built by its family; an input error found while building it ends the
    // run before its first step, and the summary says why.
    std::unique_ptr<Simulation> simulation;
    try
      {
        simulation = scene.hooks.make(file, p, log);
      }
    catch (const InputError &e)
      {
        summary.set("status", "failed");
        summary.set("error", e.what());
        if (writes)
          atomic_write((dir / "summary.json").string(), summary.to_string());
        log(std::string("error: ") + e.what());
        throw;
      }
    DriverSettings settings;
    settings.scene      = p.scene;
    settings.dir        = dir.string();
    settings.quiet      = o.quiet || !writes;
    settings.parameters = resolved;
    settings.ranks      = o.ranks;
    return drive(*simulation, settings, summary, log, checkpoint);
  }

} // namespace tribo::app
