#pragma once
/// @file VTU text of a point cloud (one vertex per particle) with point data, for the
/// particle modules (SPH, MLP) and the particle first bodies; through deal.II's
/// DataOutBase, as core/field_writer.cc does for discs. No deal.II in this header.

#include <array>
#include <string>
#include <vector>

namespace tribo
{
  /// One point-data field: @p components values per point, point-major
  /// (values[i * components + c]); 1 is a scalar, dim a vector (ParaView glyphs).
  struct PointField
  {
    std::string         name;
    unsigned int        components = 1;
    std::vector<double> values;
  };

  /// The VTU file text of the points @p points (m; the first @p dim coordinates are
  /// used, dim = 2 or 3) with @p fields, compressed for speed. Throws std::logic_error if
  /// a field's size is not components times the number of points.
  std::string point_cloud_vtu(unsigned int dim, const std::vector<std::array<double, 3>> &points,
                              const std::vector<PointField> &fields);
} // namespace tribo
