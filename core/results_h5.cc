// results.h5 through deal.II's HDF5 wrappers (serial file access).
#include "core/errors.h"
#include "core/output.h"

#include <deal.II/base/hdf5.h>

#include <cstdio>

namespace tribo
{
  void write_results_h5(const std::string &path, const TimeSeries &statistics,
                        const std::map<std::string, TimeSeries> &tables,
                        const std::map<std::string, std::string> &parameters,
                        const std::map<std::string, double> &scalars)
  {
    const std::string tmp = path + ".tmp";
    try
      {
        dealii::HDF5::File file(tmp, dealii::HDF5::File::FileAccessMode::create);
        for (const auto &[name, value] : scalars)
          file.set_attribute(name, value);

        const auto write_table = [&](const std::string &name, const TimeSeries &table) {
          auto group = file.create_group(name);
          for (const auto &column : table.columns())
            {
              const std::vector<double> values = table.column(column);
              if (!values.empty()) // the wrapper cannot write empty datasets
                group.write_dataset(column, values);
            }
          group.set_attribute("n_rows", static_cast<unsigned int>(table.rows().size()));
        };
        write_table("statistics", statistics);
        for (const auto &[name, table] : tables)
          write_table(name, table);

        auto prm = file.create_group("parameters");
        for (const auto &[name, value] : parameters)
          prm.set_attribute(name, value);
      }
    catch (const std::exception &e)
      {
        std::remove(tmp.c_str());
        throw RunError("cannot write " + path + ": " + e.what());
      }
    if (std::rename(tmp.c_str(), path.c_str()) != 0)
      throw RunError("cannot rename " + tmp + " to " + path);
  }
} // namespace tribo
