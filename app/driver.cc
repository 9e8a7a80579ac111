#include "app/driver.h"

#include "app/case_parameters.h"
#include "core/errors.h"
#include "core/serialization.h"
#include "core/run_control.h"

#include <deal.II/base/mpi.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>

namespace tribo::app
{
  RunCheckpoint::RunCheckpoint(const std::string &dir, std::map<std::string, std::string> resolved,
                               double interval, unsigned long step_interval, bool resuming,
                               std::string changes)
    : path((std::filesystem::path(dir) / "checkpoint.bin").string())
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

  void RunCheckpoint::remove() const { std::filesystem::remove(path); }

  namespace
  {
    /// The end of every scene's run: log the error or the signal and return the exit code
    /// (0 complete, 1 failed with @p failure, 128 + signal interrupted).
  int finish_run(Log &log, const std::string &status, const std::string &failure);

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

    /// statistics.csv as rows of "time", "step" and the simulation's columns; the column
    /// names are those of the first row (a resumed run's come from its checkpoint).
    class Statistics
    {
    public:
      /// Add the row of the state now, after step @p step; false if the simulation has
      /// none yet.
      bool add(Simulation &sim, unsigned long step)
      {
        Row row;
        row("time", sim.time())("step", double(step));
        if (!sim.row(row))
          return false;
        if (table.rows().empty() && table.columns().empty())
          {
            std::vector<std::string> names;
            for (const auto &c : row.columns())
              names.push_back(c.first);
            table = TimeSeries(names);
          }
        if (row.columns().size() != table.columns().size())
          throw RunError("statistics row: " + std::to_string(row.columns().size()) + " columns where the "
                         "first row (or the checkpoint resumed) has " + std::to_string(table.columns().size()) +
                         " (a checkpoint of another version of tribo?)");
        std::vector<double> values;
        for (std::size_t c = 0; c < row.columns().size(); ++c)
          {
            if (row.columns()[c].first != table.columns()[c])
              throw RunError("statistics row: column " + std::to_string(c + 1) + " is '" +
                             row.columns()[c].first + "' where the first row (or the checkpoint "
                             "resumed) has '" + table.columns()[c] + "' (a checkpoint of another "
                             "version of tribo?)");
            values.push_back(row.columns()[c].second);
          }
        table.add_row(values);
        return true;
      }
      /// True if the last row is of step @p step.
      bool has_row_of(unsigned long step) const
      {
        return !table.rows().empty() && table.rows().back()[1] == double(step);
      }
      TimeSeries table;
    };
  } // namespace

  int drive(Simulation &sim, const DriverSettings &settings, JsonObject summary, Log &log,
            RunCheckpoint &checkpoint)
  {
    namespace fs = std::filesystem;
    const fs::path dir = settings.dir;
    install_stop_handlers();
    const bool writes = rank_in(settings.ranks) == 0;
    // The signal any rank received (collective): every rank stops after the same step.
    const auto stop_agreed = [&]() {
      return rank_count(settings.ranks) > 1
               ? dealii::Utilities::MPI::max(stop_requested(), settings.ranks)
               : stop_requested();
    };
    Statistics    stats;
    FieldWriter   fields((dir / "fields").string());
    unsigned long step = sim.first_step();

    // After the header (RunCheckpoint): the step, the scene's state, the statistics and
    // the field index, in this order (core/checkpoint.h).
    const auto save_checkpoint = [&]() {
      sim.prepare_checkpoint();
      if (writes)
        checkpoint.write([&](CheckpointOut &ar) {
        ar << step;
        sim.save(ar);
        stats.table.save(ar);
        fields.save(ar);
      });
    };
    if (checkpoint.resuming())
      {
        checkpoint.read(log, [&](CheckpointIn &ar) {
          ar >> step;
          sim.load(ar, step);
          stats.table.load(ar);
          fields.load(ar);
        });
        log(sim.resumed_line(step));
      }
    else
      {
        if (sim.row_at_start())
          stats.add(sim, step);
        if (writes || sim.snapshot_on_every_rank())
          sim.write_snapshot(fields);
      }

    std::string  status = "complete", failure;
    ProgressLine progress(sim.end_time(), !settings.quiet);
    const auto   warn = [&](const std::string &text) {
      progress.finish();
      log(text);
    };
    auto last_flush = std::chrono::steady_clock::now();
    try
      {
        while (!sim.reached_end(step))
          {
            if (stop_agreed())
              {
                save_checkpoint();
                status = "interrupted";
                break;
              }
            sim.advance(step, warn);
            ++step;
            const bool last = sim.reached_end(step) || sim.finished();
            if (last || sim.row_due(step))
              stats.add(sim, step);
            if ((writes || sim.snapshot_on_every_rank()) && !last && sim.snapshot_due(step))
              sim.write_snapshot(fields);
            const auto now = std::chrono::steady_clock::now();
            if (writes && std::chrono::duration<double>(now - last_flush).count() > 10)
              {
                atomic_write((dir / "statistics.csv").string(), stats.table.to_csv());
                last_flush = now;
              }
            progress.update(sim.time(), step);
            const bool stopping = stop_agreed() != 0;
            if (stopping || (!last && checkpoint.due(step)))
              save_checkpoint();
            if (stopping)
              {
                status = "interrupted";
                break;
              }
            if (sim.finished())
              break;
          }
      }
    catch (const RunError &e)
      {
        status  = "failed";
        failure = e.what();
      }
    progress.finish();
    // The last step done gets its row, whatever the interval, and its snapshot.
    if (!stats.has_row_of(step))
      stats.add(sim, step);
    if ((writes || sim.snapshot_on_every_rank()) && (status != "failed" || sim.snapshot_a_failed_state()))
      sim.write_snapshot(fields);

    const double wall = checkpoint.wall_time();
    summary.set("status", status);
    if (!failure.empty())
      summary.set("error", failure);
    if (status == "interrupted")
      summary.set("signal", long(stop_requested()));
    summary.set("scene", settings.scene);
    summary.set("steps", long(step - sim.first_step()));
    summary.set("simulated_time", sim.time());
    summary.set("wall_time", wall);
    summary.set("n_field_snapshots", long(sim.n_snapshots(fields)));
    RunOutputs out;
    sim.summarize(RunEnd{status, wall, step, stats.table, fields, log}, summary, out);
    summary.set("results", out.results);

    out.scalars["steps"]          = double(step - sim.first_step());
    out.scalars["simulated_time"] = sim.time();
    out.scalars["wall_time"]      = wall;
    out.scalars["complete"]       = status == "complete" ? 1.0 : 0.0;
    if (!writes)
      return finish_run(log, status, failure);
    atomic_write((dir / "statistics.csv").string(), stats.table.to_csv());
    for (const auto &[name, table] : out.tables)
      atomic_write((dir / (name + ".csv")).string(), table.to_csv());
    // The last state as a sample, unless the run failed (its state may be what failed).
    if (status != "failed" && !out.final_sample.empty())
      atomic_write((dir / "sample_final.csv").string(), out.final_sample);
    write_results_h5((dir / "results.h5").string(), stats.table, out.tables, settings.parameters, out.scalars);
    atomic_write((dir / "summary.json").string(), summary.to_string());
    if (status == "complete")
      checkpoint.remove();

    if (!out.plot_script.empty() && status != "failed" && !stats.table.rows().empty())
      {
        // Plots are a convenience: a missing matplotlib is a warning, not a failure.
        const std::string command = std::string(TRIBO_PYTHON) + " " + TRIBO_SOURCE_DIR + "/scripts/" +
                                    out.plot_script + " " + shell_quote(dir.string()) + " >> " +
                                    shell_quote((dir / "log.txt").string()) + " 2>&1";
        if (std::system(command.c_str()) != 0)
          log("warning: the plots could not be made (" + command + ")");
      }
    log("status " + status + ": " + out.last_line);
    return finish_run(log, status, failure);
  }
} // namespace tribo::app
