#include "app/study.h"

#include "app/run.h"
#include "core/errors.h"
#include "core/output.h"
#include "core/parameter_file.h"
#include "core/run_control.h"

#include <deal.II/base/mpi.h>

#include <boost/property_tree/json_parser.hpp>
#include <boost/property_tree/ptree.hpp>

#include <filesystem>
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

    /// A value of summary.json "results" (or the top level), or "" if absent/null.
    std::string value_of(const boost::property_tree::ptree &tree, const std::string &key)
    {
      for (const std::string prefix : {"results.", ""})
        if (auto v = tree.get_optional<std::string>(prefix + key))
          return *v == "null" ? "" : *v;
      return "";
    }
  } // namespace

  int run_study(const StudyOptions &o)
  {
    // The study file: base case, varied and fixed entries.
    dealii::ParameterHandler prm;
    prm.enter_subsection("Study");
    prm.declare_entry("Base case", "", dealii::Patterns::Anything(),
                      "The case file every combination starts from (relative to the study file).");
    prm.declare_entry("Parameters", "", dealii::Patterns::Anything(),
                      "Varied entries: \"Subsection/Entry = v1, v2, ...; Subsection/Entry = ...\".");
    prm.declare_entry("Fixed", "", dealii::Patterns::Anything(),
                      "Overrides for every case: \"Subsection/Entry = value; ...\".");
    prm.leave_subsection();
    ParameterFile file(prm);
    file.parse(o.study_file);
    const fs::path base = fs::path(o.study_file).parent_path() / file.get("Study/Base case");
    if (file.get("Study/Base case").empty() || !fs::is_regular_file(base))
      throw InputError(file.where("Study/Base case") + ": entry 'Study/Base case' = '" +
                       file.get("Study/Base case") + "': expected an existing case file (" +
                       base.string() + " not found)");
    const auto axes  = parse_axes(file.get("Study/Parameters"), file.where("Study/Parameters"));
    const auto fixed = parse_axes(file.get("Study/Fixed"), file.where("Study/Fixed"));
    for (const auto &f : fixed)
      if (f.values.size() != 1)
        throw InputError(file.where("Study/Fixed") + ": '" + f.path + "' has several values: vary it in Parameters");

    // The combinations, as --set overrides (last axis fastest).
    std::vector<std::vector<std::string>> cases = {{}};
    for (const auto &f : fixed)
      cases[0].push_back(f.path + "=" + f.values[0]);
    for (const auto &a : axes)
      {
        std::vector<std::vector<std::string>> next;
        for (const auto &c : cases)
          for (const auto &v : a.values)
            {
              auto d = c;
              d.push_back(a.path + "=" + v);
              next.push_back(d);
            }
        cases = next;
      }

    // Check every combination before running any (bad input fails fast, exit 2).
    for (const auto &c : cases)
      {
        RunOptions check;
        check.case_file  = base.string();
        check.overrides  = c;
        check.check_only = true;
        check.quiet      = true;
        run_case(check);
      }

    const fs::path dir = o.output_dir.empty() ? fs::path("output") / fs::path(o.study_file).stem()
                                              : fs::path(o.output_dir);
    const unsigned int rank = dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD);
    const unsigned int size = dealii::Utilities::MPI::n_mpi_processes(MPI_COMM_WORLD);
    if (rank == 0)
      fs::create_directories(dir);
    MPI_Barrier(MPI_COMM_WORLD);

    const auto case_dir = [&](std::size_t i) {
      char name[32];
      std::snprintf(name, sizeof name, "case_%03zu", i);
      return dir / name;
    };
    const auto overrides_text = [&](std::size_t i) {
      std::string s = "# tribo study: base case " + base.string() + "\n";
      for (const auto &a : cases[i])
        s += a + "\n";
      return s;
    };

    // One case per rank at a time: rank r takes cases r, r + size, ...
    for (std::size_t i = rank; i < cases.size(); i += size)
      {
        const fs::path cd = case_dir(i);
        if (fs::exists(cd / "study.prm") && read_file(cd / "study.prm") == overrides_text(i) &&
            run_status(cd.string()) == "complete")
          {
            if (!o.quiet)
              std::cout << "case " << i << ": complete, skipped" << std::endl;
            continue;
          }
        // A case of this parameter set that stopped with a checkpoint goes on from it.
        const bool resume = fs::exists(cd / "study.prm") && read_file(cd / "study.prm") == overrides_text(i) &&
                            fs::exists(cd / "checkpoint.bin") && run_status(cd.string()) != "failed";
        fs::create_directories(cd);
        atomic_write((cd / "study.prm").string(), overrides_text(i));
        RunOptions run;
        run.case_file  = base.string();
        run.overrides  = cases[i];
        (resume ? run.resume_dir : run.output_dir) = cd.string();
        run.quiet      = true;
        if (!o.quiet)
          std::cout << "case " << i << " (rank " << rank << "): " << (resume ? "resuming" : "running") << std::endl;
        try
          {
            run_case(run);
          }
        catch (const std::exception &e)
          {
            // Recorded for the table; the other cases go on.
            JsonObject failed;
            failed.set("status", "failed");
            failed.set("error", e.what());
            atomic_write((cd / "summary.json").string(), failed.to_string());
          }
        if (!o.quiet)
          std::cout << "case " << i << ": " << run_status(cd.string()) << std::endl;
        if (stop_requested())
          {
            // Ctrl-C or SIGTERM: the running case was closed as interrupted; stop here,
            // a rerun resumes from it.
            std::cout << "study interrupted by signal " << stop_requested() << std::endl;
            return 128 + stop_requested();
          }
      }
    MPI_Barrier(MPI_COMM_WORLD);
    if (rank != 0)
      return exit_ok;

    // The summary table, from every case's summary.json.
    const std::vector<std::string> keys = {
      "status", "mu_mean", "mu_std", "power_balance_ratio", "power_lower_wall_mean",
      "power_dissipated_mean", "normal_force_mean", "sigma_xx_mean", "sigma_yy_mean",
      "sigma_xy_mean", "inertial_number", "cohesion_number", "steady_state_reached", "wall_time", "error"};
    std::ostringstream csv, md;
    csv << "case";
    md << "| case";
    for (const auto &a : axes)
      {
        csv << ",\"" << a.path << "\"";
        md << " | " << a.path;
      }
    for (const auto &k : keys)
      {
        csv << "," << k;
        md << " | " << k;
      }
    csv << ",directory\n";
    md << " |\n|---";
    for (std::size_t c = 0; c < axes.size() + keys.size(); ++c)
      md << "|---";
    md << "|\n";
    unsigned int n_failed = 0;
    for (std::size_t i = 0; i < cases.size(); ++i)
      {
        boost::property_tree::ptree tree;
        try
          {
            boost::property_tree::read_json((case_dir(i) / "summary.json").string(), tree);
          }
        catch (const std::exception &)
          {
            tree.put("status", "missing");
          }
        if (tree.get<std::string>("status", "") != "complete")
          ++n_failed;
        csv << i;
        md << "| " << i;
        const std::size_t n_fixed = fixed.size();
        for (std::size_t a = 0; a < axes.size(); ++a)
          {
            const std::string &assignment = cases[i][n_fixed + a];
            const std::string  value      = assignment.substr(assignment.find('=') + 1);
            csv << "," << value;
            md << " | " << value;
          }
        for (const auto &k : keys)
          {
            std::string v = value_of(tree, k);
            md << " | " << v;
            if (v.find_first_of(",\"\n") != std::string::npos)
              {
                std::string q;
                for (const char ch : v)
                  q += (ch == '"' ? std::string("\"\"") : std::string(1, ch == '\n' ? ' ' : ch));
                v = "\"" + q + "\"";
              }
            csv << "," << v;
          }
        csv << "," << case_dir(i).filename().string() << "\n";
        md << " |\n";
      }
    atomic_write((dir / "study_summary.csv").string(), csv.str());
    atomic_write((dir / "study_summary.md").string(), md.str());

    // Overlay plots of the profiles (a convenience: a failure is a warning).
    const std::string command = std::string(TRIBO_PYTHON) + " " + TRIBO_SOURCE_DIR +
                                "/scripts/plot_study.py " + shell_quote(dir.string()) + " > " +
                                shell_quote((dir / "plots.log").string()) + " 2>&1";
    if (std::system(command.c_str()) != 0 && !o.quiet)
      std::cout << "warning: the study plots could not be made, see " << (dir / "plots.log").string() << std::endl;
    if (!o.quiet)
      std::cout << "study: " << cases.size() << " cases, " << n_failed << " not complete; table "
                << (dir / "study_summary.csv").string() << std::endl;
    return exit_ok;
  }
} // namespace tribo::app
