#pragma once
/// @file The one time loop of `tribo run`, for every scene: stop conditions (End time,
/// the scene's own end, SIGINT/SIGTERM), checkpoints and --resume, progress, the rows of
/// statistics.csv, field snapshots, summary.json, results.h5, extra tables, plots and the
/// log's last line. A scene family (the NSCD discs of app/nscd_simulation.h, the SPH and
/// MLP particle scenes) implements Simulation; the driver does the rest the same way for
/// all of them.

#include "core/checkpoint.h"
#include "core/output.h"

#include <mpi.h>

#include <chrono>
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace tribo::app
{
  /// The checkpoints of one run, written and read by the driver: where they go
  /// (DIR/checkpoint.bin), when one is due (every Output/Checkpoint interval seconds of wall
  /// time and every Output/Checkpoint step interval steps), what each starts with (the
  /// resolved parameters, which run_case() compares with the case through
  /// resume_changes() before anything is written, then the wall time of the run so far)
  /// and its removal once the run is complete. The loop saves and loads its own state
  /// after that header, in one order.
  class RunCheckpoint
  {
  public:
    /// @p interval wall seconds and @p step_interval steps between checkpoints (0: none of
    /// that kind); @p changes the log text of resume_changes() when @p resuming.
    RunCheckpoint(const std::string &dir, std::map<std::string, std::string> resolved,
                  double interval, unsigned long step_interval, bool resuming, std::string changes);

    /// True for a run continued with --resume: the loop loads its state with read().
    bool resuming() const { return resume; }
    /// True if a checkpoint is due after step @p step: the wall interval has passed since
    /// the last one (or the start), or @p step is a multiple of the step interval.
    bool due(unsigned long step) const;
    /// Write the checkpoint (atomically): the header, then @p save. Restarts the timer.
    void write(const std::function<void(CheckpointOut &)> &save);
    /// Read the checkpoint: the header (logged as "resuming from FILE" and the changes),
    /// then @p load; the wall time of the run before it goes on in wall_time().
    void read(Log &log, const std::function<void(CheckpointIn &)> &load);
    /// Wall time of the run so far, s: this process's plus that of the processes before
    /// the resumption.
    double wall_time() const;
    /// Remove the checkpoint: call once the run is complete.
    void remove() const;

  private:
    using Clock = std::chrono::steady_clock;
    std::string                        path;
    std::map<std::string, std::string> parameters;
    double                             interval;
    unsigned long                      step_interval;
    bool                               resume;
    std::string                        changes;
    Clock::time_point                  start, last;
    double                             wall_before = 0; ///< s, of the processes before
  };

  /// One row of statistics.csv: the columns as (name, value) pairs, in order. The driver
  /// puts "time" and "step" first; every row of a run has the same names.
  class Row
  {
  public:
    /// Append column @p name with @p value.
    Row &operator()(const std::string &name, double value)
    {
      entries.emplace_back(name, value);
      return *this;
    }
    const std::vector<std::pair<std::string, double>> &columns() const { return entries; }

  private:
    std::vector<std::pair<std::string, double>> entries;
  };

  /// What the driver needs to know when the run ends, for summarize().
  struct RunEnd
  {
    std::string        status;    ///< complete, interrupted or failed
    double             wall_time; ///< s, of the whole run (resumptions included)
    unsigned long      step;      ///< the last step done
    const TimeSeries  &statistics;
    const FieldWriter &fields;
    Log               &log;
  };

  /// What a run's outputs hold beyond the driver's own entries (summary.json "status",
  /// "scene", "steps", "simulated_time", "wall_time", "n_field_snapshots"; results.h5
  /// scalars "steps", "simulated_time", "wall_time", "complete").
  struct RunOutputs
  {
    JsonObject                        results;  ///< summary.json "results"
    std::map<std::string, double>     scalars;  ///< results.h5 /scalars (beyond steps, times)
    std::map<std::string, TimeSeries> tables;   ///< NAME.csv and the HDF5 group NAME
    std::string                       final_sample; ///< sample_final.csv ("" for none)
    std::string                       last_line; ///< the log's last line after "status S: "
    /// scripts/NAME, run on the directory unless the run failed ("" for no plots).
    std::string                       plot_script;
  };

  /// A scene as the driver runs it. Steps are counted from first_step() (0 unless the run
  /// goes on from a state); time() is the simulated time after the last step.
  class Simulation
  {
  public:
    virtual ~Simulation() = default;
    /// The step the run starts at.
    virtual unsigned long first_step() const { return 0; }
    /// Simulated time now, s.
    virtual double time() const = 0;
    /// The simulated time the run ends at, s (for the progress line and the end test).
    virtual double end_time() const = 0;
    /// True when End time is reached.
    virtual bool reached_end(unsigned long step) const = 0;
    /// True when the scene's own event is over (the run ends, complete, before End time).
    virtual bool finished() const { return false; }
    /// One time step (step number @p step + 1 when it returns). A RunError ends the run as
    /// failed; @p warn logs a warning without breaking the progress line.
    virtual void advance(unsigned long step, const std::function<void(const std::string &)> &warn) = 0;
    /// The columns of a row now, after "time" and "step"; false when there is nothing to
    /// report yet (no step measured).
    virtual bool row(Row &row) = 0;
    /// True when a row of statistics.csv is due after step @p step (the last step of a
    /// run always gets one); a scene on a time interval moves its next row time on.
    virtual bool row_due(unsigned long step) = 0;
    /// True when the run's first row is the state before the first step.
    virtual bool row_at_start() const { return false; }
    /// True when a field snapshot is due after step @p step (the first and last are
    /// always written); a scene on a time interval moves its next snapshot time on.
    virtual bool snapshot_due(unsigned long step) = 0;
    /// Write a field snapshot of the state now into @p fields.
    virtual void write_snapshot(FieldWriter &fields) = 0;
    /// True when every MPI rank of the run writes its piece of a snapshot (write_snapshot()
    /// is then collective); otherwise only the first rank calls it.
    virtual bool snapshot_on_every_rank() const { return false; }
    /// False when a failed run's last state is not worth a snapshot (a body flown apart).
    virtual bool snapshot_a_failed_state() const { return true; }
    /// Number of snapshots written (summary.json "n_field_snapshots").
    virtual unsigned int n_snapshots(const FieldWriter &fields) const = 0;
    /// The log line after a resumption (the state is loaded).
    virtual std::string resumed_line(unsigned long step) const = 0;
    /// Results of the run (called once, after the last row and snapshot): the scene's
    /// entries of summary.json into @p summary, the rest into @p out.
    virtual void summarize(const RunEnd &end, JsonObject &summary, RunOutputs &out) = 0;
    /// Collective on the run's MPI ranks, before every checkpoint, which the first rank
    /// writes alone: gather onto it what save() needs from the others.
    virtual void prepare_checkpoint() {}
    /// Checkpoint: the scene's state between steps (the driver saves the step number,
    /// the statistics and the field index around it).
    virtual void save(CheckpointOut &ar) const = 0;
    /// Load what save() wrote, the state after step @p step.
    virtual void load(CheckpointIn &ar, unsigned long step) = 0;
  };

  /// How the driver writes a run.
  struct DriverSettings
  {
    std::string scene;        ///< Simulation/Scene, for summary.json
    std::string dir;          ///< the output directory, prepared by run_case()
    bool        quiet = false;
    /// Every resolved entry of the case, for results.h5 "parameters".
    std::map<std::string, std::string> parameters;
    /// The ranks the case runs on (CaseParameters::ranks): each steps the whole run, only
    /// the first writes (outputs, snapshots, checkpoints), and a stop signal seen by any of
    /// them stops all of them after the same step.
    MPI_Comm ranks = MPI_COMM_SELF;
  };

  /// Run @p sim to its end into @p settings.dir (statistics.csv, fields/, summary.json
  /// starting from @p summary, results.h5, tables, plots, the log); returns the exit code
  /// (0 complete, 1 failed, 128 + signal interrupted).
  int drive(Simulation &sim, const DriverSettings &settings, JsonObject summary, Log &log,
            RunCheckpoint &checkpoint);
} // namespace tribo::app
