#pragma once
/// @file Output files of a run: atomic writes, the statistics time series
/// (CSV and HDF5), summary.json, the log, and the ParaView field files.
/// Every file is written to "NAME.tmp" and renamed, so a file that exists is
/// complete as far as it goes (see docs/outputs.md).

#include "core/atomic_file.h"
#include "core/checkpoint.h"

#include <cstdio>
#include <fstream>
#include <map>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace tribo
{
  /// A table of named numeric columns, one row per output step.
  class TimeSeries
  {
  public:
    explicit TimeSeries(std::vector<std::string> columns = {});
    void add_row(const std::vector<double> &row);
    const std::vector<std::string> &columns() const { return names; }
    const std::vector<std::vector<double>> &rows() const { return data; }
    /// Column @p name as a vector (InputError-free: throws std::out_of_range).
    std::vector<double> column(const std::string &name) const;
    /// CSV text: a header of the column names, then full-precision rows.
    std::string to_csv() const;
    /// Checkpoint: the columns and rows so far. A series made without columns takes the
    /// checkpoint's; one made with columns must have the same.
    void save(CheckpointOut &ar) const;
    void load(CheckpointIn &ar);

  private:
    std::vector<std::string>         names;
    std::vector<std::vector<double>> data;
  };

  /// An ordered JSON object of scalars, strings and nested objects.
  class JsonObject
  {
  public:
    void set(const std::string &key, double value);
    void set(const std::string &key, long value);
    void set(const std::string &key, const std::string &value);
    void set(const std::string &key, const char *value) { set(key, std::string(value)); }
    void set(const std::string &key, bool value);
    void set(const std::string &key, const JsonObject &value);
    std::string to_string(unsigned int indent = 0) const;

  private:
    struct Raw { std::string text; };
    void put(const std::string &key, std::string json_text);
    std::vector<std::pair<std::string, std::string>> items;
  };

  /// Messages of a run: to log.txt (always) and to the terminal (unless quiet).
  class Log
  {
  public:
    Log() = default;
    /// Append to @p path (none: "") and echo to the terminal or not.
    void open(const std::string &path, bool echo_to_terminal);
    void operator()(const std::string &message);
    /// "error: message" to log.txt and to stderr, quiet or not (a log opened with neither
    /// a file nor the terminal, another rank's, says nothing).
    void error(const std::string &message);

  private:
    std::ofstream file;
    bool          echo = true;
  };

  /// Write results.h5 (atomically): group "statistics" with one dataset per
  /// column, one group per extra table (e.g. "profiles") likewise, group
  /// "parameters" with every resolved entry as a string attribute (keyed by its
  /// path), and @p scalars as attributes of the root.
  void write_results_h5(const std::string &path, const TimeSeries &statistics,
                        const std::map<std::string, TimeSeries> &tables,
                        const std::map<std::string, std::string> &parameters,
                        const std::map<std::string, double> &scalars);

  /// Point data for a VTU file of discs (one vertex per disc).
  struct DiscField
  {
    std::vector<double> x, y, radius, vx, vy, spin, body;
  };

  /// Line data for a VTU file of contacts (one segment per contact, centre to centre).
  struct ContactField
  {
    std::vector<double> x0, y0, x1, y1, normal_force, tangential_force, gap;
  };

  /// Part @p index of @p count of a field snapshot that several processes (MPI ranks) write.
  struct FieldPiece
  {
    unsigned int index = 0, count = 1;
  };

  /// The fields/ directory: numbered VTU snapshots and their .pvd indices.
  class FieldWriter
  {
  public:
    explicit FieldWriter(std::string directory = "");
    /// Write discs_NNNNN.vtu and contacts_NNNNN.vtu for time @p t and rewrite
    /// discs.pvd and contacts.pvd. With @p piece.count > 1, this process's part only,
    /// discs_NNNNN.I.vtu and contacts_NNNNN.I.vtu (I = piece.index): the snapshot is
    /// indexed as discs_NNNNN.pvtu and contacts_NNNNN.pvtu, which write_piece_records()
    /// writes once every piece is on disk.
    void write(double t, const DiscField &discs, const ContactField &contacts, FieldPiece piece = {});
    /// Once every process has written its piece of the last snapshot (one process calls
    /// it): the .pvtu records of that snapshot, naming its @p count pieces, and the .pvd
    /// indices.
    void write_piece_records(unsigned int count) const;
    /// Add @p file (already written in the directory) at time @p t to the index
    /// SERIES.pvd, e.g. the snapshots of a deformable body next to the discs.
    void index(const std::string &series, double t, const std::string &file);
    unsigned int n_snapshots() const { return static_cast<unsigned int>(times.size()); }
    /// Number of files in the index SERIES.pvd (see index()).
    unsigned int n_indexed(const std::string &series) const;
    const std::string &directory() const { return dir; }
    /// Checkpoint: the snapshots indexed so far (the files themselves stay on disk).
    void save(CheckpointOut &ar) const;
    void load(CheckpointIn &ar);

  private:
    std::string                                 dir;
    std::vector<std::pair<double, std::string>> disc_files, contact_files;
    std::map<std::string, std::vector<std::pair<double, std::string>>> series_files;
    std::vector<double>                         times;
  };
} // namespace tribo
