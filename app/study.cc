#include "app/study.h"

#include "app/case_parameters.h"
#include "app/scenes.h"
#include "app/run.h"
#include "core/errors.h"
#include "core/output.h"
#include "core/parameter_file.h"
#include "core/run_control.h"

#include <deal.II/base/mpi.h>

#include <boost/property_tree/json_parser.hpp>
#include <boost/property_tree/ptree.hpp>

#include <algorithm>
#include <filesystem>
#include <map>
#include <memory>
#include <fstream>
#include <iostream>
#include <sstream>

namespace tribo::app
{
  namespace fs = std::filesystem;

  namespace
  {
    std::string trim(const std::string &s)
    {
      const auto b = s.find_first_not_of(" \t");
      const auto e = s.find_last_not_of(" \t");
      return b == std::string::npos ? "" : s.substr(b, e - b + 1);
    }

    std::vector<std::string> split(const std::string &s, char sep)
    {
      std::vector<std::string> parts;
      std::string              item;
      std::istringstream       is(s);
      while (std::getline(is, item, sep))
        if (!trim(item).empty())
          parts.push_back(trim(item));
      return parts;
    }

    /// One varied entry: its path and its values.
    struct Axis
    {
      std::string              path;
      std::vector<std::string> values;
    };

    /// "path = v1, v2; path = ..." -> axes (or fixed assignments with one value each).
    std::vector<Axis> parse_axes(const std::string &text, const std::string &where)
    {
      std::vector<Axis> axes;
      for (const auto &item : split(text, ';'))
        {
          const auto eq = item.find('=');
          if (eq == std::string::npos || trim(item.substr(0, eq)).empty())
            throw InputError(where + ": '" + item + "': expected \"Subsection/Entry = value, value, ...\"");
          Axis a{trim(item.substr(0, eq)), split(item.substr(eq + 1), ',')};
          if (a.values.empty())
            throw InputError(where + ": '" + item + "': no value given");
          axes.push_back(a);
        }
      return axes;
    }

    std::string read_file(const fs::path &p)
    {
      std::ifstream      in(p);
      std::ostringstream os;
      os << in.rdbuf();
      return os.str();
    }

    /// @p v as one CSV field: quoted (with doubled quotes, newlines as blanks) if it holds
    /// a comma, a quote or a newline.
    std::string csv_field(const std::string &v)
    {
      if (v.find_first_of(",\"\n") == std::string::npos)
        return v;
      std::string q;
      for (const char ch : v)
        q += (ch == '"' ? std::string("\"\"") : std::string(1, ch == '\n' ? ' ' : ch));
      return "\"" + q + "\"";
    }

    /// The entry of an override "Subsection/Entry=value".
    std::string entry_of(const std::string &assignment) { return trim(assignment.substr(0, assignment.find('='))); }

    /// The case file @p base with @p overrides, resolved.
    std::unique_ptr<ParameterFile> resolved_case(dealii::ParameterHandler &prm, const fs::path &base,
                                                 const std::vector<std::string> &overrides)
    {
      declare_case_parameters(prm);
      auto file = std::make_unique<ParameterFile>(prm);
      file->parse(base.string());
      for (const auto &o : overrides)
        file->set(o);
      return file;
    }

    /// The compaction the case of @p base with @p overrides starts from, as the overrides
    /// of a compaction-only run: its scene's answer (SceneHooks::compaction_of), none for a
    /// scene without one.
    std::vector<std::string> preparation_of(const fs::path &base, const std::vector<std::string> &overrides,
                                            const std::vector<std::string> &shear_phase)
    {
      struct Resolved
      {
        dealii::ParameterHandler       prm;
        std::unique_ptr<ParameterFile> file;
      };
      std::map<std::vector<std::string>, std::unique_ptr<Resolved>> resolved;
      StudyCase c{overrides, {}, [&](const std::vector<std::string> &o, const std::string &entry) {
                    auto &r = resolved[o];
                    if (!r)
                      {
                        r       = std::make_unique<Resolved>();
                        r->file = resolved_case(r->prm, base, o);
                      }
                    return r->file->get(entry);
                  }};
      for (const auto &o : overrides)
        c.entries.push_back(entry_of(o));
      const auto &hooks = scene_named(c.value(overrides, "Simulation/Scene")).hooks;
      return hooks.compaction_of ? hooks.compaction_of(c, shear_phase) : std::vector<std::string>{};
    }

    /// Number @p v with @p digits significant digits (v itself if it is not wholly a number).
    std::string significant(const std::string &v, int digits)
    {
      try
        {
          std::size_t        used = 0;
          const double       x    = std::stod(v, &used);
          std::ostringstream os;
          os.precision(digits);
          os << x;
          return used == v.size() ? os.str() : v;
        }
      catch (const std::exception &)
        {
          return v;
        }
    }

    /// A value of summary.json "results" (or the top level), or "" if absent/null.
    std::string value_of(const boost::property_tree::ptree &tree, const std::string &key)
    {
      for (const std::string prefix : {"results.", ""})
        if (auto v = tree.get_optional<std::string>(prefix + key))
          return *v == "null" ? "" : *v;
      return "";
    }

    /// A study file, read and checked: the base case, the varied, fixed and reference
    /// entries, and how compactions are shared.
    struct StudyDefinition
    {
      fs::path                 base;
      std::vector<Axis>        axes, fixed, reference;
      bool                     tradeoff = false, share_compaction = true;
      std::vector<std::string> shear_phase;
    };

    /// Declare, parse and check the Study subsection of @p o.study_file (errors name the
    /// file, line and entry).
    StudyDefinition read_study(const StudyOptions &o)
    {
      dealii::ParameterHandler prm;
      prm.enter_subsection("Study");
      prm.declare_entry("Base case", "", dealii::Patterns::Anything(),
                        "The case file every combination starts from (relative to the study file).");
      prm.declare_entry("Parameters", "", dealii::Patterns::Anything(),
                        "Varied entries: \"Subsection/Entry = v1, v2, ...; Subsection/Entry = ...\".");
      prm.declare_entry("Fixed", "", dealii::Patterns::Anything(),
                        "Overrides for every case: \"Subsection/Entry = value; ...\".");
      prm.declare_entry("Design", "combinations", dealii::Patterns::Selection("combinations|tradeoff"),
                        "'combinations': every combination of the Parameters lists; 'tradeoff': the "
                        "Reference case, then each Parameters list as a ladder varied alone from the base "
                        "case, with cost and error against the Reference (scripts/tradeoff.py).");
      prm.declare_entry("Shear-phase entries", "", dealii::Patterns::Anything(),
                        "Entries (\"Subsection/Entry; ...\") the study applies from Shear start on only: the "
                        "shared compaction runs with the base case's values of them (e.g. Contact "
                        "law/Cohesion for a study of cohesion in shear from one compacted sample).");
      prm.declare_entry("Share compaction", "true", dealii::Patterns::Bool(),
                        "Shear cases that differ only in entries acting after Shear start (End time, "
                        "Sliding velocity, Profile samples, Layer thickness, Output/*, the Shear-phase "
                        "entries) run their compaction once and shear from its state (Shear cell/Initial "
                        "state, docs/outputs.md 'Studies').");
      prm.declare_entry("Reference", "", dealii::Patterns::Anything(),
                        "Design = tradeoff: the finest setting, \"Subsection/Entry = value; ...\" (each "
                        "entry one of the Parameters).");
      prm.leave_subsection();
      ParameterFile file(prm);
      file.parse(o.study_file);

      StudyDefinition study;
      study.base = fs::path(o.study_file).parent_path() / file.get("Study/Base case");
      if (file.get("Study/Base case").empty() || !fs::is_regular_file(study.base))
        throw InputError(file.where("Study/Base case") + ": entry 'Study/Base case' = '" +
                         file.get("Study/Base case") + "': expected an existing case file (" +
                         study.base.string() + " not found)");
      study.axes  = parse_axes(file.get("Study/Parameters"), file.where("Study/Parameters"));
      study.fixed = parse_axes(file.get("Study/Fixed"), file.where("Study/Fixed"));
      for (const auto &f : study.fixed)
        if (f.values.size() != 1)
          throw InputError(file.where("Study/Fixed") + ": '" + f.path + "' has several values: vary it in Parameters");

      study.tradeoff = file.get("Study/Design") == "tradeoff";
      if (o.require_tradeoff && !study.tradeoff)
        throw InputError(file.where("Study/Design") + ": entry 'Study/Design' = '" + file.get("Study/Design") +
                         "': expected 'tradeoff' for `tribo tradeoff` (or run the file with `tribo study`)");
      study.reference = parse_axes(file.get("Study/Reference"), file.where("Study/Reference"));
      if (study.tradeoff)
        {
          if (study.reference.empty() || study.axes.empty())
            throw InputError(file.where("Study/Reference") + ": a tradeoff needs Parameters (the ladders) and "
                             "Reference (the finest setting of each)");
          for (const auto &r : study.reference)
            {
              if (r.values.size() != 1)
                throw InputError(file.where("Study/Reference") + ": '" + r.path + "' has several values: the "
                                 "reference is one setting");
              if (std::none_of(study.axes.begin(), study.axes.end(), [&](const Axis &a) { return a.path == r.path; }))
                throw InputError(file.where("Study/Reference") + ": '" + r.path + "' is not one of the "
                                 "Parameters (the ladders)");
            }
        }

      study.shear_phase      = split(file.get("Study/Shear-phase entries"), ';');
      study.share_compaction = file.get_bool("Study/Share compaction");
      for (const auto &e : study.shear_phase)
        {
          dealii::ParameterHandler check;
          declare_case_parameters(check);
          ParameterFile entries(check);
          try
            {
              entries.get(e);
            }
          catch (const std::exception &)
            {
              throw InputError(file.where("Study/Shear-phase entries") + ": '" + e +
                               "' is not an entry of a case (expected \"Subsection/Entry; ...\")");
            }
        }
      return study;
    }

    /// The cases of a study as --set overrides, and what its table shows of each.
    struct CaseList
    {
      std::vector<std::vector<std::string>> overrides, columns;
      std::vector<std::string>              headers;
    };

    /// The Fixed entries as overrides.
    std::vector<std::string> fixed_overrides(const StudyDefinition &study)
    {
      std::vector<std::string> common;
      for (const auto &f : study.fixed)
        common.push_back(f.path + "=" + f.values[0]);
      return common;
    }

    /// Every combination of the Parameters lists, the last one varying fastest.
    CaseList every_combination(const StudyDefinition &study)
    {
      CaseList list;
      list.overrides = {fixed_overrides(study)};
      list.columns   = {{}};
      for (const auto &a : study.axes)
        {
          list.headers.push_back(a.path);
          std::vector<std::vector<std::string>> next, next_columns;
          for (std::size_t c = 0; c < list.overrides.size(); ++c)
            for (const auto &v : a.values)
              {
                next.push_back(list.overrides[c]);
                next.back().push_back(a.path + "=" + v);
                next_columns.push_back(list.columns[c]);
                next_columns.back().push_back(v);
              }
          list.overrides = next;
          list.columns   = next_columns;
        }
      return list;
    }

    /// A tradeoff: the reference first, then each ladder alone (a rung equal to the
    /// reference is not run twice).
    CaseList reference_and_ladders(const StudyDefinition &study)
    {
      const auto  common = fixed_overrides(study);
      CaseList    list;
      std::string reference_text;
      list.overrides = {common};
      for (const auto &r : study.reference)
        {
          list.overrides[0].push_back(r.path + "=" + r.values[0]);
          reference_text += (reference_text.empty() ? "" : "; ") + r.path + " = " + r.values[0];
        }
      list.headers = {"knob", "value"};
      list.columns = {{"reference", reference_text}};
      for (const auto &a : study.axes)
        for (const auto &v : a.values)
          {
            auto c = common;
            c.push_back(a.path + "=" + v);
            if (c == list.overrides[0])
              continue;
            list.overrides.push_back(c);
            list.columns.push_back({a.path, v});
          }
      return list;
    }

    /// The compactions the cases share: each distinct one as overrides, which one each
    /// case starts from (-1: its own), and a sentence for the table.
    struct SharedCompactions
    {
      std::vector<std::vector<std::string>> preparations;
      std::vector<int>                      of_case;
      std::string                           note;
    };

    /// One compaction per distinct preparation, when the cases share one (a tradeoff's
    /// ladders judge the whole run, compaction included: they never share).
    SharedCompactions shared_compactions(const StudyDefinition &study, const CaseList &list)
    {
      SharedCompactions shared;
      shared.of_case.assign(list.overrides.size(), -1);
      if (study.tradeoff || !study.share_compaction)
        {
          shared.note = study.tradeoff ? "no shared compaction: a tradeoff measures whole runs"
                                       : "no shared compaction: Study/Share compaction = false";
          return shared;
        }
      std::map<std::vector<std::string>, int> index;
      bool                                    all = true;
      for (std::size_t i = 0; i < list.overrides.size() && all; ++i)
        {
          const auto prep = preparation_of(study.base, list.overrides[i], study.shear_phase);
          all             = !prep.empty();
          if (all && !index.count(prep))
            {
              index[prep] = int(shared.preparations.size());
              shared.preparations.push_back(prep);
            }
          shared.of_case[i] = all ? index[prep] : -1;
        }
      if (!all || shared.preparations.size() == list.overrides.size())
        {
          shared.note = !all ? "no shared compaction: not every case is a shear case with an upper wall of "
                               "discs, a compaction (0 < Shear start < End time) and no initial state"
                             : "no shared compaction: every case compacts differently";
          shared.preparations.clear();
          std::fill(shared.of_case.begin(), shared.of_case.end(), -1);
        }
      else
        shared.note = std::to_string(list.overrides.size()) + " cases shear from " +
                      std::to_string(shared.preparations.size()) + " shared compaction" +
                      (shared.preparations.size() > 1 ? "s" : "") +
                      " (preparation_NNN/, Shear cell/Initial state): they differ only in entries that act "
                      "after Shear start" + (study.shear_phase.empty() ? "" : " or in the Shear-phase entries");
      return shared;
    }

    /// Check one case (@p label) of @p base with @p overrides without running it: bad input
    /// fails fast (exit 2), the message naming the study file and the case.
    void check_case(const std::string &study_file, const std::string &label, const fs::path &base,
                    const std::vector<std::string> &overrides)
    {
      RunOptions check;
      check.case_file  = base.string();
      check.overrides  = overrides;
      check.check_only = true;
      check.quiet      = true;
      try
        {
          run_case(check);
        }
      catch (const InputError &e)
        {
          std::string entries;
          for (const auto &a : overrides)
            entries += (entries.empty() ? "" : "; ") + a;
          throw InputError(study_file + ": " + label + " (" + entries + "): " + e.what());
        }
    }

    /// Whether every case (@p overrides of @p base) and preparation may run on several MPI
    /// ranks: `tribo check` of each on all of them passes run_case()'s refusals (a Solver/Method
    /// other than apgs and nlgs, NLGS in another order, a scene that is not split).
    bool every_case_splits(const fs::path &base, const std::vector<std::vector<std::string>> &overrides,
                           const std::vector<std::vector<std::string>> &preparations)
    {
      for (const auto *list : {&overrides, &preparations})
        for (const auto &o : *list)
          {
            RunOptions check;
            check.case_file  = base.string();
            check.overrides  = o;
            check.check_only = true;
            check.quiet      = true;
            check.ranks      = MPI_COMM_WORLD;
            try
              {
                run_case(check);
              }
            catch (const InputError &)
              {
                return false;
              }
          }
      return true;
    }

    /// OUTPUT/STEM_NNN.
    fs::path numbered_dir(const fs::path &dir, const char *stem, std::size_t i)
    {
      char name[48];
      std::snprintf(name, sizeof name, "%s_%03zu", stem, i);
      return dir / name;
    }

    /// Run one case (or preparation) of @p base into @p cd, or skip it when complete with
    /// the same overrides, or resume it from its checkpoint; false when interrupted by a
    /// signal.
    bool run_into(const fs::path &cd, const fs::path &base, const std::vector<std::string> &overrides,
                  const std::string &label, bool quiet, MPI_Comm ranks)
    {
      // The case's ranks (one, or a group of them): the first decides and writes.
      const bool leader = rank_in(ranks) == 0;
      std::string text = "# tribo study: base case " + base.string() + "\n";
      for (const auto &a : overrides)
        text += a + "\n";
      const bool same = fs::exists(cd / "study.prm") && read_file(cd / "study.prm") == text;
      // 0: skip (complete with the same overrides), 1: run, 2: resume from its checkpoint.
      int what = !same || run_status(cd.string()) != "complete" ? 1 : 0;
      if (what == 1 && same && fs::exists(cd / "checkpoint.bin") && run_status(cd.string()) != "failed")
        what = 2;
      MPI_Bcast(&what, 1, MPI_INT, 0, ranks);
      if (what == 0)
        {
          if (!quiet && leader)
            std::cout << label << ": complete, skipped" << std::endl;
          return true;
        }
      const bool resume = what == 2;
      if (leader)
        {
          fs::create_directories(cd);
          atomic_write((cd / "study.prm").string(), text);
        }
      RunOptions run;
      run.case_file = base.string();
      run.overrides = overrides;
      (resume ? run.resume_dir : run.output_dir) = cd.string();
      run.quiet = true;
      run.ranks = ranks;
      const unsigned int n_ranks = rank_count(ranks);
      if (!quiet && leader)
        std::cout << label << " (rank " << dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD)
                  << (n_ranks > 1 ? " and " + std::to_string(n_ranks - 1) + " more" : std::string()) << "): "
                  << (resume ? "resuming" : "running") << std::endl;
      try
        {
          run_case(run);
        }
      catch (const std::exception &e)
        {
          // Recorded for the table; the other cases go on.
          if (leader)
            {
              JsonObject failed;
              failed.set("status", "failed");
              failed.set("error", e.what());
              atomic_write((cd / "summary.json").string(), failed.to_string());
            }
        }
      if (!quiet && leader)
        std::cout << label << ": " << run_status(cd.string()) << std::endl;
      if (n_ranks > 1 ? dealii::Utilities::MPI::max(stop_requested(), ranks) : stop_requested())
        {
          // Ctrl-C or SIGTERM: the running case was closed as interrupted; stop here,
          // a rerun resumes from it.
          std::cout << "study interrupted by signal " << stop_requested() << std::endl;
          return false;
        }
      return true;
    }

    /// study_summary.csv and .md from every case's summary.json: a time-averaged figure
    /// with its batch-means standard error (the next key), written "mean +/- stderr" in the
    /// .md. Returns the number of cases not complete.
    unsigned int write_study_table(const fs::path &dir, const CaseList &list, const SharedCompactions &shared)
    {
      const std::vector<std::string> keys = {
        "status", "mu_mean", "mu_stderr", "mu_std", "power_balance_ratio", "power_balance_ratio_stderr",
        "power_lower_wall_mean", "power_dissipated_mean", "normal_force_mean", "normal_force_stderr",
        "sigma_xx_mean", "sigma_xx_stderr", "sigma_yy_mean", "sigma_yy_stderr", "sigma_xy_mean",
        "sigma_xy_stderr", "inertial_number", "cohesion_number", "steady_state_reached", "wall_time", "error"};
      const auto is_stderr = [](const std::string &k) { return k.size() > 7 && k.substr(k.size() - 7) == "_stderr"; };
      std::ostringstream csv, md;
      csv << "case";
      md << "| case";
      for (const auto &h : list.headers)
        {
          csv << ",\"" << h << "\"";
          md << " | " << h;
        }
      unsigned int md_columns = 0;
      for (const auto &k : keys)
        {
          csv << "," << k;
          if (!is_stderr(k))
            {
              md << " | " << k;
              ++md_columns;
            }
        }
      csv << ",preparation,directory\n";
      md << " |\n|---";
      for (std::size_t c = 0; c < list.headers.size() + md_columns; ++c)
        md << "|---";
      md << "|\n";
      unsigned int n_failed = 0;
      for (std::size_t i = 0; i < list.overrides.size(); ++i)
        {
          boost::property_tree::ptree tree;
          try
            {
              boost::property_tree::read_json((numbered_dir(dir, "case", i) / "summary.json").string(), tree);
            }
          catch (const std::exception &)
            {
              tree.put("status", "missing");
            }
          if (tree.get<std::string>("status", "") != "complete")
            ++n_failed;
          csv << i;
          md << "| " << i;
          for (const std::string &value : list.columns[i])
            {
              csv << "," << csv_field(value);
              md << " | " << value;
            }
          for (std::size_t k = 0; k < keys.size(); ++k)
            {
              const std::string v = value_of(tree, keys[k]);
              csv << "," << csv_field(v);
              if (is_stderr(keys[k]))
                continue;
              const std::string se = k + 1 < keys.size() && is_stderr(keys[k + 1]) ? value_of(tree, keys[k + 1]) : "";
              md << " | " << (v.empty() ? v : se.empty() ? significant(v, 5) : significant(v, 5) + " +/- " + significant(se, 2));
            }
          csv << ","
              << (shared.of_case[i] >= 0 ? numbered_dir(dir, "preparation", shared.of_case[i]).filename().string() : "")
              << "," << numbered_dir(dir, "case", i).filename().string() << "\n";
          md << " |\n";
        }
      atomic_write((dir / "study_summary.csv").string(), csv.str());
      md << "\nCompaction: " << shared.note << ".\n";
      atomic_write((dir / "study_summary.md").string(), md.str());
      return n_failed;
    }

    /// The overlay plots of the profiles (a convenience: a failure is a warning) and, for
    /// a tradeoff, tradeoff.csv, .md and .png (the table is what a tradeoff is for: a
    /// failure is an error).
    void make_study_plots(const fs::path &dir, bool tradeoff, bool quiet)
    {
      const std::string command = std::string(TRIBO_PYTHON) + " " + TRIBO_SOURCE_DIR +
                                  "/scripts/plot_study.py " + shell_quote(dir.string()) + " > " +
                                  shell_quote((dir / "plots.log").string()) + " 2>&1";
      if (std::system(command.c_str()) != 0 && !quiet)
        std::cout << "warning: the study plots could not be made, see " << (dir / "plots.log").string() << std::endl;
      if (!tradeoff)
        return;
      const std::string t = std::string(TRIBO_PYTHON) + " " + TRIBO_SOURCE_DIR + "/scripts/tradeoff.py " +
                            shell_quote(dir.string()) + " > " + shell_quote((dir / "tradeoff.log").string()) +
                            " 2>&1";
      if (std::system(t.c_str()) != 0)
        throw RunError("the tradeoff table could not be made, see " + (dir / "tradeoff.log").string());
      if (!quiet)
        std::cout << "tradeoff: " << (dir / "tradeoff.md").string() << std::endl;
    }
  } // namespace

  int run_study(const StudyOptions &o)
  {
    const StudyDefinition study = read_study(o);
    CaseList              list  = study.tradeoff ? reference_and_ladders(study) : every_combination(study);
    for (std::size_t i = 0; i < list.overrides.size(); ++i)
      check_case(o.study_file, "case " + std::to_string(i), study.base, list.overrides[i]);
    const SharedCompactions shared = shared_compactions(study, list);
    for (std::size_t i = 0; i < shared.preparations.size(); ++i)
      check_case(o.study_file, "shared compaction " + std::to_string(i), study.base, shared.preparations[i]);

    const fs::path dir = o.output_dir.empty() ? fs::path("output") / fs::path(o.study_file).stem()
                                              : fs::path(o.output_dir);
    const unsigned int rank = dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD);
    const unsigned int size = dealii::Utilities::MPI::n_mpi_processes(MPI_COMM_WORLD);
    if (rank == 0)
      fs::create_directories(dir);
    MPI_Barrier(MPI_COMM_WORLD);
    // With more ranks than cases, each case runs on a group of ranks, its contact solve split
    // over them (docs/scaling.md), when every case and preparation can be; otherwise (and in
    // a tradeoff, whose costs compare one-rank runs) one rank per case. Group g holds the
    // ranks g, g + groups, ... and runs the cases g, g + groups, ...
    unsigned int groups = size;
    if (!study.tradeoff && size > list.overrides.size() && !list.overrides.empty() &&
        every_case_splits(study.base, list.overrides, shared.preparations))
      groups = static_cast<unsigned int>(list.overrides.size());
    MPI_Comm group;
    MPI_Comm_split(MPI_COMM_WORLD, int(rank % groups), int(rank), &group);
    const unsigned int g = rank % groups;
    if (rank == 0 && !o.quiet && groups < size)
      std::cout << "study: " << size << " MPI ranks for " << list.overrides.size() << " cases: each case on "
                << size / groups << (size % groups ? " or " + std::to_string(size / groups + 1) : std::string())
                << " ranks" << std::endl;
    // A case sharing a compaction starts from its state.
    for (std::size_t i = 0; i < list.overrides.size(); ++i)
      if (shared.of_case[i] >= 0)
        list.overrides[i].push_back("Shear cell/Initial state=" +
                                    fs::absolute(numbered_dir(dir, "preparation", shared.of_case[i])).string());

    if (rank == 0 && !o.quiet)
      std::cout << "study: " << shared.note << std::endl;
    // The shared compactions first, one per rank at a time, then the cases: rank r takes
    // r, r + size, ...
    for (std::size_t i = g; i < shared.preparations.size(); i += groups)
      if (!run_into(numbered_dir(dir, "preparation", i), study.base, shared.preparations[i],
                    "preparation " + std::to_string(i), o.quiet, group))
        return 128 + stop_requested();
    MPI_Barrier(MPI_COMM_WORLD);
    for (std::size_t i = g; i < list.overrides.size(); i += groups)
      if (!run_into(numbered_dir(dir, "case", i), study.base, list.overrides[i], "case " + std::to_string(i), o.quiet,
                    group))
        return 128 + stop_requested();
    MPI_Comm_free(&group);
    MPI_Barrier(MPI_COMM_WORLD);
    if (rank != 0)
      return exit_ok;

    const unsigned int n_failed = write_study_table(dir, list, shared);
    make_study_plots(dir, study.tradeoff, o.quiet);
    if (!o.quiet)
      std::cout << "study: " << list.overrides.size() << " cases, " << n_failed << " not complete; table "
                << (dir / "study_summary.csv").string() << std::endl;
    return exit_ok;
  }
} // namespace tribo::app
