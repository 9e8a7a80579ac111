#include "core/point_cloud.h"

#include <stdexcept>

#include <deal.II/base/data_out_base.h>

#include <sstream>
#include <tuple>

namespace tribo
{
  namespace
  {
    template <int dim>
    std::string write(const std::vector<std::array<double, 3>> &points, const std::vector<PointField> &fields)
    {
      using DCI = dealii::DataComponentInterpretation::DataComponentInterpretation;
      std::vector<std::string>                                                names;
      std::vector<std::tuple<unsigned int, unsigned int, std::string, DCI>> vectors;
      for (const auto &f : fields)
        {
          if (f.values.size() != f.components * points.size())
            throw std::logic_error("point field '" + f.name + "' has " + std::to_string(f.values.size()) +
                                " values for " + std::to_string(points.size()) + " points");
          if (f.components > 1)
            vectors.emplace_back(names.size(), names.size() + f.components - 1, f.name,
                                 dealii::DataComponentInterpretation::component_is_part_of_vector);
          names.insert(names.end(), f.components, f.name);
        }
      std::vector<dealii::DataOutBase::Patch<0, dim>> patches(points.size());
      for (std::size_t i = 0; i < points.size(); ++i)
        {
          auto &p = patches[i];
          for (int d = 0; d < dim; ++d)
            p.vertices[0][d] = points[i][d];
          p.patch_index = i;
          p.data.reinit(names.size(), 1);
          unsigned int row = 0;
          for (const auto &f : fields)
            for (unsigned int c = 0; c < f.components; ++c)
              p.data(row++, 0) = f.values[i * f.components + c];
        }
      dealii::DataOutBase::VtkFlags flags;
      flags.compression_level = dealii::DataOutBase::VtkFlags::best_speed;
      std::ostringstream os;
      dealii::DataOutBase::write_vtu(patches, names, vectors, flags, os);
      return os.str();
    }
  } // namespace

  std::string point_cloud_vtu(unsigned int dim, const std::vector<std::array<double, 3>> &points,
                              const std::vector<PointField> &fields)
  {
    if (dim == 2)
      return write<2>(points, fields);
    if (dim == 3)
      return write<3>(points, fields);
    throw std::logic_error("point_cloud_vtu: dim must be 2 or 3, got " + std::to_string(dim));
  }
} // namespace tribo
