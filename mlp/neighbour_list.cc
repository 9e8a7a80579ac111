#include "mlp/neighbour_list.h"

#include "core/errors.h"
#include "core/serialization.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace tribo::mlp
{
  NeighbourList::NeighbourList(double cutoff, double skin) : range(cutoff), skin_width(skin)
  {
    if (!(cutoff > 0) || !(skin >= 0))
      throw InputError("MLP neighbour list: cutoff must be > 0 and skin >= 0, got cutoff " +
                       to_text(cutoff) + " m, skin " + to_text(skin) + " m");
  }

  namespace
  {
    /// Cell coordinates along one axis: origin, cell size, count, periodicity.
    struct Axis
    {
      double lo    = 0;
      double size  = 1;
      int    count = 1;
      bool   periodic = false;

      int index(double s) const
      {
        int k = static_cast<int>(std::floor((s - lo) / size));
        if (periodic)
          {
            k %= count;
            if (k < 0)
              k += count;
          }
        return std::clamp(k, 0, count - 1);
      }
    };

    Axis make_axis(double lo, double hi, double min_size, bool periodic)
    {
      Axis a;
      a.lo       = lo;
      a.periodic = periodic;
      const double extent = std::max(hi - lo, 0.0);
      a.count = std::max(1, static_cast<int>(std::floor(extent / min_size)));
      a.count = std::min(a.count, 1 << 20);
      a.size  = a.count > 1 ? extent / a.count : std::max(extent, min_size);
      if (!(a.size > 0))
        a.size = min_size;
      return a;
    }
  } // namespace

  void NeighbourList::build(const Particles &particles, const Box &box)
  {
    box.validate();
    const double       r_list = range + skin_width;
    const unsigned int n      = particles.size();
    if (box.periodic_x && box.lx < 2 * r_list)
      throw InputError("MLP neighbour list: period lx = " + to_text(box.lx) +
                       " m is shorter than 2 (cutoff + skin) = " + to_text(2 * r_list) + " m");
    if (box.periodic_y && box.ly < 2 * r_list)
      throw InputError("MLP neighbour list: period ly = " + to_text(box.ly) +
                       " m is shorter than 2 (cutoff + skin) = " + to_text(2 * r_list) + " m");

    // Binning coordinates: wrapped, and sheared (x - tilt y / ly) in a tilted
    // box, where the periodic cell is a plain rectangle. A pair within r_list
    // differs by at most r_list (1 + |tilt|/ly) in the sheared x.
    const double   shear = box.periodic_y ? box.tilt / box.ly : 0.0;
    std::vector<Vec2> s(n);
    Vec2 lo = Vec2::Constant(std::numeric_limits<double>::max());
    Vec2 hi = -lo;
    for (unsigned int i = 0; i < n; ++i)
      {
        const Vec2 w = box.wrap(particles.position[i]);
        s[i]         = Vec2(w.x() - shear * w.y(), w.y());
        lo           = lo.cwiseMin(s[i]);
        hi           = hi.cwiseMax(s[i]);
      }
    if (n == 0)
      lo = hi = Vec2::Zero();
    const Axis ax = box.periodic_x ? make_axis(0, box.lx, r_list * (1 + std::abs(shear)), true) :
                                     make_axis(lo.x(), hi.x(), r_list, false);
    const Axis ay = box.periodic_y ? make_axis(0, box.ly, r_list, true) :
                                     make_axis(lo.y(), hi.y(), r_list, false);

    // Counting sort of the particles into cells (stable: increasing index).
    const std::size_t         n_cells = static_cast<std::size_t>(ax.count) * ay.count;
    std::vector<unsigned int> cell_of(n), cell_start(n_cells + 1, 0), cell_members(n);
    for (unsigned int i = 0; i < n; ++i)
      {
        cell_of[i] = static_cast<unsigned int>(ay.index(s[i].y()) * ax.count + ax.index(s[i].x()));
        ++cell_start[cell_of[i] + 1];
      }
    for (std::size_t c = 0; c < n_cells; ++c)
      cell_start[c + 1] += cell_start[c];
    {
      std::vector<unsigned int> fill(cell_start.begin(), cell_start.end() - 1);
      for (unsigned int i = 0; i < n; ++i)
        cell_members[fill[cell_of[i]]++] = i;
    }

    pair_list.clear();
    const double r2 = r_list * r_list;
    for (unsigned int i = 0; i < n; ++i)
      {
        const int cx = static_cast<int>(cell_of[i] % ax.count);
        const int cy = static_cast<int>(cell_of[i] / ax.count);
        // The distinct cells of the 3x3 stencil (fewer when an axis has < 3 cells).
        std::array<unsigned int, 9> stencil;
        unsigned int                n_stencil = 0;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx)
            {
              int kx = cx + dx, ky = cy + dy;
              if (ax.periodic)
                kx = (kx + ax.count) % ax.count;
              if (ay.periodic)
                ky = (ky + ay.count) % ay.count;
              if (kx < 0 || kx >= ax.count || ky < 0 || ky >= ay.count)
                continue;
              stencil[n_stencil++] = static_cast<unsigned int>(ky * ax.count + kx);
            }
        std::sort(stencil.begin(), stencil.begin() + n_stencil);
        n_stencil = static_cast<unsigned int>(
          std::unique(stencil.begin(), stencil.begin() + n_stencil) - stencil.begin());
        for (unsigned int k = 0; k < n_stencil; ++k)
          for (unsigned int m = cell_start[stencil[k]]; m < cell_start[stencil[k] + 1]; ++m)
            {
              const unsigned int j = cell_members[m];
              if (j <= i)
                continue;
              const Vec2 d =
                box.minimum_image(particles.position[j] - particles.position[i]);
              if (d.squaredNorm() < r2)
                pair_list.emplace_back(i, j);
            }
      }

    // Incidence lists (CSR): pairs of particle i in increasing pair order.
    incidence_offset.assign(n + 1, 0);
    for (const auto &p : pair_list)
      {
        ++incidence_offset[p.first + 1];
        ++incidence_offset[p.second + 1];
      }
    for (unsigned int i = 0; i < n; ++i)
      incidence_offset[i + 1] += incidence_offset[i];
    incidences.resize(2 * pair_list.size());
    std::vector<unsigned int> fill(incidence_offset.begin(), incidence_offset.end() - 1);
    for (unsigned int p = 0; p < pair_list.size(); ++p)
      {
        incidences[fill[pair_list[p].first]++]  = {p, +1};
        incidences[fill[pair_list[p].second]++] = {p, -1};
      }

    build_positions = particles.position;
    build_box       = box;
    ++builds;
  }

  bool NeighbourList::needs_rebuild(const Particles &particles, const Box &box) const
  {
    if (builds == 0 || build_positions.size() != particles.size())
      return true;
    if (box.periodic_x != build_box.periodic_x || box.periodic_y != build_box.periodic_y)
      return true;
    const double box_change = std::abs(box.lx - build_box.lx) + std::abs(box.ly - build_box.ly) +
                              std::abs(box.tilt - build_box.tilt);
    double max2 = 0;
    for (unsigned int i = 0; i < particles.size(); ++i)
      max2 = std::max(max2, box.minimum_image(particles.position[i] - build_positions[i])
                              .squaredNorm());
    return 2 * std::sqrt(max2) + box_change > skin_width;
  }

  bool NeighbourList::update(const Particles &particles, const Box &box)
  {
    if (!needs_rebuild(particles, box))
      return false;
    build(particles, box);
    return true;
  }

  void NeighbourList::save(CheckpointOut &ar) const
  {
    ar << pair_list << incidence_offset << incidences << build_positions << builds;
    ar << build_box.periodic_x << build_box.lx << build_box.periodic_y << build_box.ly << build_box.tilt;
  }

  void NeighbourList::load(CheckpointIn &ar)
  {
    ar >> pair_list >> incidence_offset >> incidences >> build_positions >> builds;
    ar >> build_box.periodic_x >> build_box.lx >> build_box.periodic_y >> build_box.ly >> build_box.tilt;
  }
} // namespace tribo::mlp
