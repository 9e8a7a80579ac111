#include "app/sample_file.h"

#include "app/scenes.h"
#include "core/errors.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

namespace tribo::app
{
  namespace
  {
    std::vector<std::string> split_cells(const std::string &line)
    {
      std::vector<std::string> cells;
      std::stringstream        in(line);
      std::string              cell;
      while (std::getline(in, cell, ','))
        {
          cell.erase(0, cell.find_first_not_of(" \t\r"));
          cell.erase(cell.find_last_not_of(" \t\r") + 1);
          cells.push_back(cell);
        }
      if (!line.empty() && line.back() == ',')
        cells.emplace_back();
      return cells;
    }
  } // namespace

  std::string sample_text(const dem::ParticleSystem &s, unsigned int lower, unsigned int upper)
  {
    std::ostringstream os;
    os.precision(17);
    os << "x,y,r,body,vx,vy,spin\n";
    for (std::size_t d = 0; d < s.discs.size(); ++d)
      {
        const unsigned int     b = s.discs[d].body;
        const dem::RigidBody  &body = s.bodies[b];
        dem::Vec2              x    = s.wrap(s.disc_centre(d));
        if (s.period > 0 && x.x() >= s.period) // a tiny negative x wraps to period itself
          x.x() = 0;
        os << x.x() << ',' << x.y() << ',' << s.discs[d].radius << ','
           << (b == lower ? "lower_wall" : b == upper ? "upper_wall" : "grain") << ','
           << body.velocity.x() << ',' << body.velocity.y() << ',' << body.spin << '\n';
      }
    return os.str();
  }

  std::vector<SampleDisc> read_sample(const std::string &path, double length)
  {
    std::ifstream in(path);
    if (!in)
      throw InputError(path + ": cannot open the sample file (Shear cell/Sample file)");
    const std::vector<std::string> required = {"x", "y", "r", "body"};
    const std::vector<std::string> optional = {"vx", "vy", "spin"};
    std::string                    line;
    std::getline(in, line);
    const std::vector<std::string> header = split_cells(line);
    const bool with_velocity = header.size() == 7;
    std::vector<std::string> expected = required;
    if (with_velocity)
      expected.insert(expected.end(), optional.begin(), optional.end());
    if (header != expected)
      throw InputError(path + ":1: expected the header 'x,y,r,body' or 'x,y,r,body,vx,vy,spin', got '" +
                       line + "'");

    std::vector<SampleDisc> discs;
    unsigned int            number = 1;
    while (std::getline(in, line))
      {
        ++number;
        if (line.find_first_not_of(" \t\r") == std::string::npos)
          continue;
        const std::string              where = path + ":" + std::to_string(number) + ": ";
        const std::vector<std::string> cells = split_cells(line);
        if (cells.size() != expected.size())
          throw InputError(where + "expected " + std::to_string(expected.size()) + " cells (" +
                           (with_velocity ? "x,y,r,body,vx,vy,spin" : "x,y,r,body") + "), got " +
                           std::to_string(cells.size()));
        auto number_in = [&](std::size_t column) {
          const std::string &cell = cells[column];
          std::size_t        used = 0;
          double             v    = std::numeric_limits<double>::quiet_NaN();
          try
            {
              v = std::stod(cell, &used);
            }
          catch (const std::exception &)
            {
              used = 0;
            }
          if (used != cell.size() || cell.empty() || !std::isfinite(v))
            throw InputError(where + "column '" + expected[column] + "': expected a finite number, got '" +
                             cell + "'");
          return v;
        };
        SampleDisc d;
        d.centre = {number_in(0), number_in(1)};
        d.radius = number_in(2);
        if (d.radius <= 0)
          throw InputError(where + "column 'r': expected a positive radius in m, got '" + cells[2] + "'");
        const std::string &body = cells[3];
        if (body == "grain")
          d.body = SampleDisc::Body::grain;
        else if (body == "lower_wall")
          d.body = SampleDisc::Body::lower_wall;
        else if (body == "upper_wall")
          d.body = SampleDisc::Body::upper_wall;
        else
          throw InputError(where + "column 'body': expected grain, lower_wall or upper_wall, got '" + body + "'");
        if (with_velocity)
          {
            d.velocity = {number_in(4), number_in(5)};
            d.spin     = number_in(6);
          }
        if (d.body == SampleDisc::Body::grain && (d.centre.x() < 0 || d.centre.x() >= length))
          throw InputError(where + "column 'x': expected a grain inside the period [0, " + to_text(length) +
                           ") m (Shear cell/Length), got '" + cells[0] + "'");
        discs.push_back(d);
      }

    auto count = [&](SampleDisc::Body b) {
      return std::count_if(discs.begin(), discs.end(), [&](const SampleDisc &d) { return d.body == b; });
    };
    if (count(SampleDisc::Body::grain) == 0)
      throw InputError(path + ": no grain rows (body = grain): the sample has no third body");
    const auto lower = count(SampleDisc::Body::lower_wall), upper = count(SampleDisc::Body::upper_wall);
    if (lower == 0 && upper > 0)
      throw InputError(path + ": rows for the upper wall only: give the lower wall too, or neither "
                       "(then both are generated)");
    if (lower > 0)
      {
        double lower_top = -std::numeric_limits<double>::infinity();
        double upper_bottom = std::numeric_limits<double>::infinity();
        for (const SampleDisc &d : discs)
          if (d.body == SampleDisc::Body::lower_wall)
            lower_top = std::max(lower_top, d.centre.y() + d.radius);
          else if (d.body == SampleDisc::Body::upper_wall)
            upper_bottom = std::min(upper_bottom, d.centre.y() - d.radius);
        if (upper_bottom <= lower_top)
          throw InputError(path + ": the walls overlap: the upper wall reaches down to y = " +
                           to_text(upper_bottom) + " m, the lower wall up to y = " + to_text(lower_top) + " m");
      }
    return discs;
  }

  std::string sample_snapshot_path(const std::string &fields_dir, unsigned int index)
  {
    char name[32];
    std::snprintf(name, sizeof name, "sample_%05u.csv", index);
    return (std::filesystem::path(fields_dir) / name).string();
  }

  SampleSnapshot sample_snapshot(const std::string &run_dir, double time)
  {
    namespace fs         = std::filesystem;
    const fs::path index = fs::path(run_dir) / "fields" / "discs.pvd";
    std::ifstream  in(index);
    if (!in)
      throw InputError("tribo sample " + run_dir + ": no snapshot index " + index.string() +
                       " (expected the output directory of a run)");
    // One snapshot per <DataSet timestep="T" ... file="discs_NNNNN.vtu"/>, in time order.
    std::vector<std::pair<double, std::string>> snapshots;
    std::string                                 line;
    while (std::getline(in, line))
      {
        const auto t = line.find("timestep=\""), f = line.find("file=\"");
        if (t == std::string::npos || f == std::string::npos)
          continue;
        const std::string file = line.substr(f + 6, line.find('"', f + 6) - f - 6);
        snapshots.emplace_back(std::stod(line.substr(t + 10)), file);
      }
    if (snapshots.empty())
      throw InputError("tribo sample " + run_dir + ": " + index.string() + " lists no snapshot");
    auto chosen = snapshots.end() - 1;
    if (!std::isnan(time))
      chosen = std::min_element(snapshots.begin(), snapshots.end(), [&](const auto &a, const auto &b) {
        return std::abs(a.first - time) < std::abs(b.first - time);
      });
    const std::string number = chosen->second.substr(chosen->second.rfind('_') + 1, 5);
    SampleSnapshot    s{sample_snapshot_path((fs::path(run_dir) / "fields").string(), std::stoul(number)),
                     chosen->first, ""};
    if (!fs::is_regular_file(s.path))
      throw InputError("tribo sample " + run_dir + ": no sample next to the snapshot at t = " +
                       to_text(chosen->first) + " s (" + s.path + " not found: only shear runs whose upper "
                       "body is a wall of discs write them)");
    const RunRecord run = read_run_record(run_dir);
    if (run.length <= 0)
      throw InputError("tribo sample " + run_dir + ": cannot read the run's Shear cell/Length from " +
                       (fs::path(run_dir) / "parameters.prm").string());
    read_sample(s.path, run.length);
    std::ifstream      file(s.path);
    std::ostringstream text;
    text << file.rdbuf();
    s.text = text.str();
    return s;
  }
} // namespace tribo::app
