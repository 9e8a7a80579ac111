#pragma once
/// @file Shear-cell samples as files (Shear cell/Sample file, docs/outputs.md "Sample files").
///
/// A CSV file, one disc per line after the header `x,y,r,body` (optionally followed by
/// `vx,vy,spin`): centre (m), radius (m), the body the disc belongs to (`grain`,
/// `lower_wall` or `upper_wall`), and optionally an initial velocity (m/s) and spin
/// (rad/s). Each wall is one rigid body made of its rows, moving as its first row says
/// (the lower wall's velocity is then imposed by the cell). Checks, each failing with the
/// file, the line and the column: a header other than these columns, a row with another
/// number of cells, a cell that is not a finite number, a radius <= 0, an unknown body, a
/// grain outside [0, L) in x; then no grain at all, rows for the upper wall without the
/// lower wall (lower wall rows alone are a sample of a run with a deformable upper body: the
/// upper wall or body then goes above the grains), and walls that overlap (the upper wall's
/// lowest point below the lower wall's highest).

#include "dem/engine/particle_system.h"

#include <string>
#include <vector>

namespace tribo::app
{
  struct SampleDisc
  {
    enum class Body
    {
      grain,
      lower_wall,
      upper_wall
    };
    dem::Vec2 centre   = dem::Vec2::Zero(); ///< m
    double    radius   = 0;                 ///< m
    Body      body     = Body::grain;
    dem::Vec2 velocity = dem::Vec2::Zero(); ///< m/s
    double    spin     = 0;                 ///< rad/s
  };

  /// The sample file text of @p s (header x,y,r,body,vx,vy,spin; 17 significant digits,
  /// so that reading it back gives the same doubles): the discs of body @p lower as
  /// lower_wall, of @p upper as upper_wall, every other disc a grain, each with its
  /// body's velocity and spin; x wrapped into [0, period).
  std::string sample_text(const dem::ParticleSystem &s, unsigned int lower, unsigned int upper);

  /// The discs of sample file @p path for a cell of period @p length (m); throws
  /// InputError naming the file, line and column (see the file comment).
  std::vector<SampleDisc> read_sample(const std::string &path, double length);

  /// The sample file written next to field snapshot @p index in @p fields_dir:
  /// FIELDS_DIR/sample_NNNNN.csv, numbered like discs_NNNNN.vtu.
  std::string sample_snapshot_path(const std::string &fields_dir, unsigned int index);

  /// A snapshot of a run as a sample file (`tribo sample`).
  struct SampleSnapshot
  {
    std::string path; ///< RUN/fields/sample_NNNNN.csv
    double      time; ///< s, the snapshot's time in fields/discs.pvd
    std::string text; ///< the file, checked with read_sample() against the run's Length
  };

  /// The snapshot of run directory @p run_dir whose time is nearest @p time (s), or the
  /// last one for a NaN @p time; InputError naming the directory when it has no
  /// snapshot index, no sample next to the snapshot (a scene without one), or the run's
  /// parameters.prm cannot be read.
  SampleSnapshot sample_snapshot(const std::string &run_dir, double time);
} // namespace tribo::app
