#include "app/run.h"

#include "app/case_parameters.h"
#include "app/particle_scenes.h"
#include "app/scene.h"
#include "core/checkpoint.h"
#include "core/errors.h"
#include "core/output.h"
#include "core/parameter_file.h"
#include "core/run_control.h"
#include "core/serialization.h"

#include <boost/property_tree/json_parser.hpp>
#include <boost/property_tree/ptree.hpp>

#include <cctype>
#include <cstdlib>
#include <chrono>
#include <iostream>
#include <map>
#include <cmath>
#include <filesystem>
#include <sstream>

#include <sys/resource.h>

namespace tribo::app
{
  namespace fs = std::filesystem;

  namespace
  {
    const std::vector<std::string> common_columns = {
      "time", "step", "n_contacts", "n_active_contacts", "nlgs_iterations", "nlgs_residual",
      "nlgs_converged", "law_residual", "gap_violation", "epsilon", "max_overlap", "kinetic_energy", "power_external",
      "power_free", "power_contacts"};

    void write_fields(FieldWriter &writer, double t, const dem::ParticleSystem &s,
                      const dem::MoreauJean &mj, double h, const Scene &scene)
    {
      DiscField discs;
      for (std::size_t d = 0; d < s.discs.size(); ++d)
        {
          const auto &b   = s.bodies[s.discs[d].body];
          const auto  x   = s.wrap(s.disc_centre(d));
          const auto  arm = dem::rotate(s.discs[d].offset, b.angle);
          discs.x.push_back(x.x());
          discs.y.push_back(x.y());
          discs.radius.push_back(s.discs[d].radius);
          discs.vx.push_back(b.velocity.x() - b.spin * arm.y());
          discs.vy.push_back(b.velocity.y() + b.spin * arm.x());
          discs.spin.push_back(b.spin);
          discs.body.push_back(s.discs[d].body);
        }
      ContactField contacts;
      for (const auto &c : mj.contacts())
        {
          if (c.r.x() == 0 && c.r.y() == 0)
            continue;
          const auto x0 = s.wrap(s.disc_centre(c.disc[0]));
          contacts.x0.push_back(x0.x());
          contacts.y0.push_back(x0.y());
          contacts.x1.push_back(x0.x() + c.branch.x());
          contacts.y1.push_back(x0.y() + c.branch.y());
          contacts.normal_force.push_back(c.r.x() / h);
          contacts.tangential_force.push_back(c.r.y() / h);
          contacts.gap.push_back(c.gap);
        }
      writer.write(t, discs, contacts);
      // The discs as a sample file next to the snapshot (`tribo sample DIR --time T`),
      // exact where the VTU's Float32 is not.
      if (const std::string sample = scene.sample(s); !sample.empty())
        atomic_write(sample_snapshot_path(writer.directory(), writer.n_snapshots() - 1), sample);
      // The scene's own fields, SERIES_NNNNN.vtu, indexed in SERIES.pvd.
      for (const std::string &file : scene.write_fields(writer.directory(), writer.n_snapshots() - 1))
        writer.index(file.substr(0, file.rfind('_')), t, file);
    }

    /// Peak resident memory of the process so far, MB (getrusage; Linux reports KiB).
    double peak_memory_mb()
    {
      rusage usage{};
      getrusage(RUSAGE_SELF, &usage);
      return usage.ru_maxrss / 1024.0;
    }

    /// Where the steps' wall time goes, over the steps of this process (since the start
    /// or the last resumption: not checkpointed), for summary.json "timing".
    struct StepTiming
    {
      unsigned long steps = 0, sweeps = 0, check_passes = 0;
      double        step = 0, detection = 0, boundary_body = 0, solver = 0;
      /// Sum over steps of (sweeps + check passes) x contacts: a check pass solves every
      /// contact's law like a sweep.
      double contact_updates = 0;

      void add(const dem::StepReport &r)
      {
        ++steps;
        sweeps += r.solver.iterations;
        check_passes += r.solver.check_passes;
        step += r.time_step;
        detection += r.time_detection;
        boundary_body += r.time_boundary_body;
        solver += r.time_solver;
        contact_updates += double(r.solver.iterations + r.solver.check_passes) * r.n_contacts;
      }

      /// Means per step, s, and the NLGS cost per contact update, ns.
      JsonObject to_json() const
      {
        JsonObject j;
        const double n = std::max(1ul, steps);
        j.set("steps", long(steps));
        j.set("step_mean_s", step / n);
        j.set("detection_mean_s", detection / n);
        j.set("boundary_body_mean_s", boundary_body / n);
        j.set("nlgs_mean_s", solver / n);
        j.set("other_mean_s", (step - detection - boundary_body - solver) / n);
        j.set("nlgs_sweeps_mean", double(sweeps) / n);
        j.set("nlgs_check_passes_mean", double(check_passes) / n);
        j.set("nlgs_ns_per_contact_update", contact_updates > 0 ? 1e9 * solver / contact_updates : 0.0);
        return j;
      }
    };
  } // namespace

  bool may_change_on_resume(const std::string &entry)
  {
    return entry.rfind("Solver/", 0) == 0 || entry.rfind("Output/", 0) == 0 ||
           entry == "Simulation/End time";
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
                           "may change only Solver/*, Output/* and Simulation/End time");
        changed += (changed.empty() ? "" : ", ") + entry + " " + before + " -> " + value;
      }
    return (changed.empty() ? "" : "; changed: " + changed) +
           (defaulted.empty() ? "" : "; not in the checkpoint, at their defaults: " + defaulted);
  }

  RunCheckpoint::RunCheckpoint(const std::string &dir, std::map<std::string, std::string> resolved,
                               double interval, unsigned long step_interval, bool resuming,
                               std::string changes)
    : path((fs::path(dir) / "checkpoint.bin").string())
    , parameters(std::move(resolved))
    , interval(interval)
    , step_interval(step_interval)
    , resume(resuming)
    , changes(std::move(changes))
    , start(Clock::now())
    , last(start)
  {}

  bool RunCheckpoint::due(unsigned long step) const
  {
    const bool timer = interval > 0 && std::chrono::duration<double>(Clock::now() - last).count() > interval;
    return timer || (step_interval > 0 && step % step_interval == 0);
  }

  void RunCheckpoint::write(const std::function<void(CheckpointOut &)> &save)
  {
    const double wall = wall_time();
    write_checkpoint(path, [&](CheckpointOut &ar) {
      ar << parameters << wall;
      save(ar);
    });
    last = Clock::now();
  }

  void RunCheckpoint::read(Log &log, const std::function<void(CheckpointIn &)> &load)
  {
    read_checkpoint(path, [&](CheckpointIn &ar) {
      std::map<std::string, std::string> saved; // checked by run_case() already
      ar >> saved >> wall_before;
      log("resuming from " + path + changes);
      load(ar);
    });
  }

  double RunCheckpoint::wall_time() const
  {
    return wall_before + std::chrono::duration<double>(Clock::now() - start).count();
  }

  void RunCheckpoint::remove() const { fs::remove(path); }

  bool is_sph_scene(const std::string &scene) { return scene.rfind("sph_", 0) == 0; }
  bool is_mlp_scene(const std::string &scene) { return scene.rfind("mlp_", 0) == 0; }

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
    const CaseParameters p = read_case_parameters(file);
    // The sample file by its absolute path in parameters.prm: a resumed run, or one
    // started from that file elsewhere, finds it.
    if (!p.shear.sample_file.empty())
      file.set("Shear cell/Sample file=" + p.shear.sample_file);
    if (!p.shear.initial_state.empty())
      file.set("Shear cell/Initial state=" + p.shear.initial_state);
#ifndef TRIBO_WITH_SPH_SCENES
    if (is_sph_scene(p.scene))
      throw InputError(o.case_file + ": Simulation/Scene = " + p.scene +
                       " is not in this build (the SPH scenes need TRIBO_WITH_SPH=ON)");
#else
    if (is_sph_scene(p.scene))
      check_sph_scene(file);
#endif
#ifndef TRIBO_WITH_MLP_SCENES
    if (is_mlp_scene(p.scene))
      throw InputError(o.case_file + ": Simulation/Scene = " + p.scene +
                       " is not in this build (the MLP scenes need TRIBO_WITH_MLP=ON)");
#else
    if (is_mlp_scene(p.scene))
      check_mlp_scene(file);
#endif
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
    if (!resuming)
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
          throw InputError("--output " + dir.string() + ": cannot prepare the directory (" +
                           e.code().message() + ")");
        }

    JsonObject summary;
    summary.set("status", "running");
    summary.set("case", o.case_file);
    atomic_write((dir / "summary.json").string(), summary.to_string());
    atomic_write((dir / "original.prm").string(), file.original_text());
    {
      std::ostringstream os;
      prm.print_parameters(os, dealii::ParameterHandler::PRM);
      atomic_write((dir / "parameters.prm").string(), os.str());
    }

    Log log;
    log.open((dir / "log.txt").string(), !o.quiet);
    log("tribo run " + o.case_file + " -> " + dir.string());

    RunCheckpoint checkpoint(dir.string(), resolved, p.checkpoint_interval, p.checkpoint_step_interval,
                             resuming, changes);
    // The explicit particle modules run their own time loop (app/particle_scenes.h).
#ifdef TRIBO_WITH_SPH_SCENES
    if (is_sph_scene(p.scene))
      return run_sph_scene(file, dir.string(), log, o, checkpoint);
#endif
#ifdef TRIBO_WITH_MLP_SCENES
    if (is_mlp_scene(p.scene))
      return run_mlp_scene(file, dir.string(), log, o, checkpoint);
#endif

    install_stop_handlers();
    const auto wall_start = std::chrono::steady_clock::now();

    std::unique_ptr<Scene> scene = make_scene(p);
    dem::ParticleSystem    system;
    scene->build(system);
    const double h        = scene->time_step(system);
    const double distance = p.detection_distance > 0 ? p.detection_distance : 0.1 * system.min_radius();
    dem::SolverParameters solver = p.solver;
    solver.gap_tolerance       = p.gap_tolerance * system.min_radius();
    dem::MoreauJean mj(p.theta, p.law, solver, distance);
    scene->attach(mj);
    const unsigned long n_steps = std::max(1L, std::lround(std::ceil(p.end_time / h - 1e-9)));
    // A run that goes on from an initial state starts at its step (a whole number of steps,
    // checked with the parameters).
    const unsigned long first_step = std::lround(p.start_time / h);
    {
      std::ostringstream os;
      os << "scene " << p.scene << ": " << system.bodies.size() << " bodies, " << system.discs.size()
         << " discs; h = " << h << " s, " << n_steps << " steps, detection distance " << mj.detection_distance() << " m";
      log(os.str());
      if (!scene->description().empty())
        log(scene->description());
      if (first_step > 0)
        {
          std::ostringstream state;
          state << "starting from the state of " << p.shear.initial_state << " at t = " << first_step * h
                << " s (step " << first_step << "; its sample_final.csv, without contact impulses)";
          log(state.str());
        }
      if (p.solver.method != dem::SolverParameters::Method::nlgs && p.law.friction > 0)
        log("Solver/Method = " + dem::method_name(p.solver.method) +
            " solves frictionless problems only: with Coulomb friction (mu = " +
            std::to_string(p.law.friction) + ") every step uses NLGS");
    }
    // What building the case cost: the modules a case does not use are not built (a rigid
    // wall builds no deal.II, SPH or MLP object).
    const double setup_time   = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    const double setup_memory = peak_memory_mb();
    {
      std::ostringstream os;
      os << "set-up " << setup_time << " s, peak memory " << setup_memory << " MB";
      log(os.str());
    }

    std::vector<std::string> columns = common_columns;
    for (const auto &c : scene->columns())
      columns.push_back(c);
    TimeSeries  stats(columns);
    FieldWriter fields((dir / "fields").string());

    std::string   status = "complete", failure;
    unsigned long step = first_step, total_iterations = 0, non_converged = 0, max_iterations = 0;
    double        worst_overlap = 0, t = first_step * h, max_residual = 0;
    // The law residual (dem/law_residual.h) over the steps, and the active set's work.
    double        max_law_residual = 0, sum_law_residual = 0, max_gap_violation = 0;
    unsigned long total_factorizations = 0, fallbacks = 0;
    StepTiming    timing;          ///< the steps since the start or the last resumption

    // After the header (RunCheckpoint), the loop's counters and every object's state, in
    // this order (core/checkpoint.h).
    const auto save_checkpoint = [&]() {
      checkpoint.write([&](CheckpointOut &ar) {
        ar << step << total_iterations << non_converged << max_iterations << worst_overlap << max_residual
           << max_law_residual << sum_law_residual << max_gap_violation << total_factorizations << fallbacks;
        system.save(ar);
        mj.save(ar);
        scene->save(ar);
        stats.save(ar);
        fields.save(ar);
      });
    };
    if (resuming)
      {
        checkpoint.read(log, [&](CheckpointIn &ar) {
          ar >> step >> total_iterations >> non_converged >> max_iterations >> worst_overlap >> max_residual >>
            max_law_residual >> sum_law_residual >> max_gap_violation >> total_factorizations >> fallbacks;
          system.load(ar);
          mj.load(ar);
          scene->load(ar);
          stats.load(ar);
          fields.load(ar);
        });
        t = step * h;
        std::ostringstream os;
        os << "resumed at step " << step << " (t = " << t << " s) of " << n_steps;
        log(os.str());
      }
    else
      write_fields(fields, t, system, mj, h, *scene);

    ProgressLine  progress(n_steps * h, !o.quiet);
    auto          last_flush = std::chrono::steady_clock::now();
    std::vector<double> last_row;
    try
      {
        for (; step < n_steps; )
          {
            if (stop_requested())
              {
                save_checkpoint();
                status = "interrupted";
                break;
              }
            scene->before_step(system, step);
            const dem::StepReport r = mj.step(system, h);
            ++step;
            t = step * h;
            total_iterations += r.solver.iterations;
            timing.add(r);
            max_iterations = std::max<unsigned long>(max_iterations, r.solver.iterations);
            max_residual   = std::max(max_residual, r.solver.residual);
            max_law_residual  = std::max(max_law_residual, r.solver.law_residual);
            sum_law_residual += r.solver.law_residual;
            max_gap_violation = std::max(max_gap_violation, r.solver.gap_violation);
            total_factorizations += r.solver.factorizations;
            fallbacks += r.solver.fell_back ? 1 : 0;
            worst_overlap  = std::max(worst_overlap, r.max_overlap);
            if (!r.solver.converged && ++non_converged <= 10)
              {
                std::ostringstream os;
                os << "warning: step " << step << " (t = " << t << " s): NLGS did not converge in "
                   << r.solver.iterations << " sweeps, residual " << r.solver.residual
                   << (non_converged == 10 ? " (further warnings only counted)" : "");
                progress.finish();
                log(os.str());
              }
            const std::vector<double> extra = scene->measure(system, mj, r);
            const bool stopping = stop_requested() != 0;
            const bool last     = step == n_steps || scene->finished() || stopping;
            last_row = {t, double(step), double(r.n_contacts), double(r.n_active),
                        double(r.solver.iterations), r.solver.residual,
                        r.solver.converged ? 1.0 : 0.0, r.solver.law_residual,
                        r.solver.gap_violation, r.epsilon, r.max_overlap,
                        r.kinetic_energy, r.power_external, r.power_free, r.power_contacts};
            last_row.insert(last_row.end(), extra.begin(), extra.end());
            if (step % p.statistics_interval == 0 || last)
              stats.add_row(last_row);
            if (p.field_interval > 0 && step % p.field_interval == 0 && !last)
              write_fields(fields, t, system, mj, h, *scene);
            const auto now = std::chrono::steady_clock::now();
            if (std::chrono::duration<double>(now - last_flush).count() > 10)
              {
                atomic_write((dir / "statistics.csv").string(), stats.to_csv());
                last_flush = now;
              }
            if (stopping || (!last && checkpoint.due(step)))
              save_checkpoint();
            progress.update(t, step);
            if (stopping)
              {
                status = "interrupted";
                break;
              }
            if (scene->finished())
              break;
          }
      }
    catch (const RunError &e)
      {
        status  = "failed";
        failure = e.what();
        // The last completed step gets its row, whatever the interval.
        if (!last_row.empty() && (stats.rows().empty() || stats.rows().back()[1] != last_row[1]))
          stats.add_row(last_row);
      }
    progress.finish();
    write_fields(fields, t, system, mj, h, *scene);

    const double wall = checkpoint.wall_time();
    summary.set("status", status);
    if (!failure.empty())
      summary.set("error", failure);
    if (status == "interrupted")
      summary.set("signal", long(stop_requested()));
    summary.set("scene", p.scene);
    summary.set("time_step", h);
    // Steps run by this case: from its start (0, or an initial state's step) on.
    const unsigned long steps_run = step - first_step;
    summary.set("steps", long(steps_run));
    summary.set("steps_planned", long(n_steps - first_step));
    summary.set("start_time", first_step * h);
    summary.set("simulated_time", t);
    summary.set("wall_time", wall);
    summary.set("nlgs_iterations_total", long(total_iterations));
    summary.set("nlgs_iterations_mean", steps_run ? double(total_iterations) / steps_run : 0.0);
    summary.set("nlgs_iterations_max", long(max_iterations));
    summary.set("nlgs_residual_max", max_residual);
    summary.set("nlgs_non_converged_steps", long(non_converged));
    summary.set("law_residual_max", max_law_residual);
    summary.set("law_residual_mean", steps_run ? sum_law_residual / steps_run : 0.0);
    summary.set("gap_violation_max", max_gap_violation);
    summary.set("solver_method", dem::method_name(p.solver.method));
    summary.set("factorizations_mean", steps_run ? double(total_factorizations) / steps_run : 0.0);
    summary.set("active_set_fallbacks", long(fallbacks));
    summary.set("max_overlap", worst_overlap);
    summary.set("max_overlap_over_min_radius", worst_overlap / system.min_radius());
    summary.set("n_bodies", long(system.bodies.size()));
    summary.set("n_discs", long(system.discs.size()));
    summary.set("n_field_snapshots", long(fields.n_snapshots()));
    summary.set("timing", timing.to_json());
    summary.set("setup_time", setup_time);
    summary.set("setup_peak_memory", setup_memory);
    summary.set("peak_memory", peak_memory_mb());
    JsonObject scene_results;
    if (!stats.rows().empty())
      {
        scene->summarize(system, stats, scene_results);
        if (const std::string note = scene->averaging_note(); !note.empty())
          log(note);
      }
    summary.set("results", scene_results);

    std::map<std::string, double> scalars = {{"time_step", h}, {"steps", double(steps_run)},
                                             {"simulated_time", t}, {"wall_time", wall},
                                             {"complete", status == "complete" ? 1.0 : 0.0}};
    atomic_write((dir / "statistics.csv").string(), stats.to_csv());
    const auto tables = scene->tables();
    for (const auto &[name, table] : tables)
      atomic_write((dir / (name + ".csv")).string(), table.to_csv());
    // The last state as a sample, unless the run failed (its state may be what failed).
    if (const std::string sample = status == "failed" ? "" : scene->sample(system); !sample.empty())
      atomic_write((dir / "sample_final.csv").string(), sample);
    write_results_h5((dir / "results.h5").string(), stats, tables, resolved, scalars);
    atomic_write((dir / "summary.json").string(), summary.to_string());
    if (status == "complete")
      checkpoint.remove();

    if (p.plots && p.scene == "shear" && status != "failed" && !stats.rows().empty())
      {
        // Plots are a convenience: a missing matplotlib is a warning, not a failure.
        const std::string command = std::string(TRIBO_PYTHON) + " " + TRIBO_SOURCE_DIR +
                                    "/scripts/plot_run.py " + shell_quote(dir.string()) + " >> " +
                                    shell_quote((dir / "log.txt").string()) + " 2>&1";
        if (std::system(command.c_str()) != 0)
          log("warning: the plots could not be made (" + command + ")");
      }

    std::ostringstream os;
    os << "status " << status << ": " << steps_run << " steps in " << wall << " s, "
       << (steps_run ? double(total_iterations) / steps_run : 0.0)
       << (p.solver.method == dem::SolverParameters::Method::mprgp ? " NLGS sweeps and MPRGP products"
                                                                   : " NLGS sweeps")
       << " per step, "
       << non_converged << " steps not converged, law residual mean "
       << (steps_run ? sum_law_residual / steps_run : 0.0) << " max " << max_law_residual
       << ", worst overlap " << worst_overlap << " m";
    if (p.solver.method == dem::SolverParameters::Method::active_set ||
        p.solver.method == dem::SolverParameters::Method::interior_point)
      os << ", " << (steps_run ? double(total_factorizations) / steps_run : 0.0) << " factorisations per step";
    if (p.solver.method == dem::SolverParameters::Method::active_set)
      os << ", " << fallbacks << " NLGS fallbacks";
    if (timing.steps > 0)
      {
        const double n = timing.steps;
        os << "; per step " << 1e3 * timing.step / n << " ms: solver " << 1e3 * timing.solver / n
           << " ms, detection " << 1e3 * timing.detection / n << " ms, upper body "
           << 1e3 * timing.boundary_body / n << " ms";
      }
    log(os.str());
    return finish_run(log, status, failure);
  }

  int finish_run(Log &log, const std::string &status, const std::string &failure)
  {
    if (status == "failed")
      {
        log.error(failure);
        return exit_run_error;
      }
    if (status == "interrupted")
      {
        log("interrupted by signal " + std::to_string(stop_requested()) +
            ": outputs hold the steps done so far");
        return 128 + stop_requested();
      }
    return exit_ok;
  }
} // namespace tribo::app
