// VTU snapshots of discs and contacts through deal.II's DataOutBase, with .pvd indices.
#include "core/errors.h"
#include "core/output.h"

#include <deal.II/base/data_out_base.h>
#include <deal.II/grid/reference_cell.h>

#include <boost/archive/binary_iarchive.hpp>
#include <boost/archive/binary_oarchive.hpp>
#include <boost/serialization/map.hpp>
#include <boost/serialization/string.hpp>
#include <boost/serialization/utility.hpp>
#include <boost/serialization/vector.hpp>

#include <cstdio>
#include <sstream>
#include <tuple>

namespace tribo
{
  namespace
  {
    using Interpretation = dealii::DataComponentInterpretation::DataComponentInterpretation;
    using Ranges         = std::vector<std::tuple<unsigned int, unsigned int, std::string, Interpretation>>;

    /// A valid VTU with no points (deal.II writes no <Points> element for no patches).
    std::string empty_vtu(const std::vector<std::string> &names)
    {
      std::ostringstream os;
      os << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" "
            "byte_order=\"LittleEndian\">\n<UnstructuredGrid>\n<Piece NumberOfPoints=\"0\" "
            "NumberOfCells=\"0\">\n<Points><DataArray type=\"Float32\" NumberOfComponents=\"3\" "
            "format=\"ascii\"></DataArray></Points>\n<Cells>"
            "<DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\"></DataArray>"
            "<DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\"></DataArray>"
            "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\"></DataArray></Cells>\n<PointData>";
      for (const auto &n : names)
        os << "<DataArray type=\"Float32\" Name=\"" << n << "\" format=\"ascii\"></DataArray>";
      os << "</PointData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
      return os.str();
    }

    template <typename Patches>
    std::string vtu_text_of(const Patches &patches, const std::vector<std::string> &names,
                            const Ranges &ranges)
    {
      if (patches.empty())
        {
          std::vector<std::string> unique;
          for (const auto &n : names)
            if (unique.empty() || unique.back() != n)
              unique.push_back(n);
          return empty_vtu(unique);
        }
      dealii::DataOutBase::VtkFlags flags;
      flags.compression_level = dealii::DataOutBase::VtkFlags::best_speed;
      std::ostringstream os;
      dealii::DataOutBase::write_vtu(patches, names, ranges, flags, os);
      return os.str();
    }

    /// STEM_NNNNN.vtu, or with @p suffix STEM_NNNNN.SUFFIX (a piece "I.vtu", a record "pvtu").
    std::string numbered(const std::string &stem, std::size_t n, const std::string &suffix = "vtu")
    {
      char buf[32];
      std::snprintf(buf, sizeof buf, "_%05zu.", n);
      return stem + buf + suffix;
    }

    const std::vector<std::string> disc_names    = {"radius", "velocity", "velocity", "spin", "body"};
    const std::vector<std::string> contact_names = {"normal_force", "tangential_force", "gap"};
    const Ranges                   disc_ranges   = {
      {1, 2, "velocity", dealii::DataComponentInterpretation::component_is_part_of_vector}};

    std::string pvd_text(const std::vector<std::pair<double, std::string>> &files)
    {
      std::ostringstream os;
      dealii::DataOutBase::write_pvd_record(os, files);
      return os.str();
    }
  } // namespace

  FieldWriter::FieldWriter(std::string directory)
    : dir(std::move(directory))
  {}

  void FieldWriter::write(double t, const DiscField &discs, const ContactField &contacts, FieldPiece piece)
  {
    const std::size_t n = times.size();

    // Discs: one vertex patch per disc; data rows radius, vx, vy, spin, body.
    std::vector<dealii::DataOutBase::Patch<0, 2>> disc_patches(discs.x.size());
    for (std::size_t i = 0; i < disc_patches.size(); ++i)
      {
        auto &p       = disc_patches[i];
        p.vertices[0] = dealii::Point<2>(discs.x[i], discs.y[i]);
        p.patch_index = i;
        p.data.reinit(5, 1);
        p.data(0, 0) = discs.radius[i];
        p.data(1, 0) = discs.vx[i];
        p.data(2, 0) = discs.vy[i];
        p.data(3, 0) = discs.spin[i];
        p.data(4, 0) = discs.body[i];
      }

    // Contacts: one line patch per contact, from centre to centre.
    std::vector<dealii::DataOutBase::Patch<1, 2>> contact_patches(contacts.x0.size());
    for (std::size_t i = 0; i < contact_patches.size(); ++i)
      {
        auto &p       = contact_patches[i];
        p.vertices[0] = dealii::Point<2>(contacts.x0[i], contacts.y0[i]);
        p.vertices[1] = dealii::Point<2>(contacts.x1[i], contacts.y1[i]);
        p.patch_index    = i;
        p.reference_cell = dealii::ReferenceCells::Line; // not set by default in deal.II 9.4
        p.data.reinit(3, 2);
        for (unsigned int v = 0; v < 2; ++v)
          {
            p.data(0, v) = contacts.normal_force[i];
            p.data(1, v) = contacts.tangential_force[i];
            p.data(2, v) = contacts.gap[i];
          }
      }

    // One process: the snapshot's files; several: this one's piece, indexed by the records.
    const bool        whole       = piece.count <= 1;
    const std::string piece_name  = std::to_string(piece.index) + ".vtu";
    const std::string disc_file   = numbered("discs", n, whole ? "vtu" : piece_name);
    const std::string contact_file = numbered("contacts", n, whole ? "vtu" : piece_name);
    atomic_write(dir + "/" + disc_file, vtu_text_of(disc_patches, disc_names, disc_ranges));
    atomic_write(dir + "/" + contact_file, vtu_text_of(contact_patches, contact_names, {}));

    times.push_back(t);
    disc_files.emplace_back(t, whole ? disc_file : numbered("discs", n, "pvtu"));
    contact_files.emplace_back(t, whole ? contact_file : numbered("contacts", n, "pvtu"));
    if (whole)
      {
        atomic_write(dir + "/discs.pvd", pvd_text(disc_files));
        atomic_write(dir + "/contacts.pvd", pvd_text(contact_files));
      }
  }

  void FieldWriter::write_piece_records(unsigned int count) const
  {
    const std::size_t n = times.size() - 1;
    dealii::DataOutBase::VtkFlags flags;
    for (const auto &[stem, names, ranges] :
         {std::tuple{"discs", disc_names, disc_ranges}, std::tuple{"contacts", contact_names, Ranges{}}})
      {
        std::vector<std::string> pieces;
        for (unsigned int i = 0; i < count; ++i)
          pieces.push_back(numbered(stem, n, std::to_string(i) + ".vtu"));
        std::ostringstream os;
        dealii::DataOutBase::write_pvtu_record(os, pieces, names, ranges, flags);
        atomic_write(dir + "/" + numbered(stem, n, "pvtu"), os.str());
      }
    atomic_write(dir + "/discs.pvd", pvd_text(disc_files));
    atomic_write(dir + "/contacts.pvd", pvd_text(contact_files));
  }

  void FieldWriter::index(const std::string &series, double t, const std::string &file)
  {
    auto &files = series_files[series];
    files.emplace_back(t, file);
    atomic_write(dir + "/" + series + ".pvd", pvd_text(files));
  }
  unsigned int FieldWriter::n_indexed(const std::string &series) const
  {
    const auto it = series_files.find(series);
    return it == series_files.end() ? 0 : static_cast<unsigned int>(it->second.size());
  }

  void FieldWriter::save(CheckpointOut &ar) const
  {
    ar << disc_files << contact_files << series_files << times;
  }

  void FieldWriter::load(CheckpointIn &ar)
  {
    ar >> disc_files >> contact_files >> series_files >> times;
  }
} // namespace tribo
