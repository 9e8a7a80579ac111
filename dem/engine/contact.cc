#include "dem/engine/contact.h"

#include "core/errors.h"

#include <deal.II/base/parallel.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace tribo::dem
{
  namespace
  {
    /// The largest relative motion of two discs: twice the largest distance of a motion from
    /// the middle of their bounding box, at most @p cap largest radii (a few fast discs cannot
    /// widen the cells without bound; pairs further apart are missed as without motions, and
    /// the overlap guard of the step names the farthest mover), and never so much that a
    /// period which holds two reaches without motions would not hold two now. 0 without
    /// motions.
    double closing_reach(const ParticleSystem &system, const std::vector<Vec2> &motion, double cap)
    {
      double reach = 0;
      if (motion.empty())
        return reach;
      Vec2 low = motion[0], high = motion[0];
      for (const Vec2 &m : motion)
        {
          low  = low.cwiseMin(m);
          high = high.cwiseMax(m);
        }
      const Vec2 middle = 0.5 * (low + high);
      for (const Vec2 &m : motion)
        reach = std::max(reach, 2 * (m - middle).norm());
      reach = std::min(reach, cap * system.max_radius());
      if (system.period > 0)
        reach = std::min(reach, 0.5 * system.period - 2 * system.max_radius());
      return reach;
    }

    /// Cells at least one reach wide over the discs' bounding box (along x the period when
    /// the system is periodic), numbered by rows upwards.
    struct CellGrid
    {
      long   nx = 1, ny = 1;
      double xmin = 0, ymin = 0, wx = 0, wy = 0;
      bool   periodic = false;

      CellGrid(const ParticleSystem &system, const std::vector<Vec2> &centres, double reach)
        : periodic(system.period > 0)
      {
        double xmax = centres[0].x(), ymax = centres[0].y();
        xmin = xmax;
        ymin = ymax;
        for (const auto &c : centres)
          {
            xmin = std::min(xmin, c.x());
            xmax = std::max(xmax, c.x());
            ymin = std::min(ymin, c.y());
            ymax = std::max(ymax, c.y());
          }
        if (periodic)
          {
            if (system.period < 2 * reach)
              throw RunError("the period along x (" + to_text(system.period) +
                             " m) is shorter than two contact reaches (" + to_text(2 * reach) +
                             " m): enlarge the domain");
            xmin = 0;
            xmax = system.period;
          }
        const auto cells_along = [&](double length) {
          return std::max<long>(1, std::min<long>(long(length / reach), 1L << 20));
        };
        nx = cells_along(xmax - xmin);
        ny = cells_along(ymax - ymin);
        wx = periodic ? system.period / nx : std::max(reach, (xmax - xmin) / nx);
        wy = std::max(reach, (ymax - ymin) / ny);
      }

      /// The cell of a centre.
      long cell(const Vec2 &c) const
      {
        return std::clamp<long>(long((c.y() - ymin) / wy), 0, ny - 1) * nx +
               std::clamp<long>(long((c.x() - xmin) / wx), 0, nx - 1);
      }

      /// The distinct neighbour cells of cell (cx, cy), itself included (fewer than 9 when nx
      /// or ny < 3), into @p out; returns how many.
      int neighbours(long cx, long cy, long out[9]) const
      {
        int count = 0;
        for (long dy = -1; dy <= 1; ++dy)
          for (long dx = -1; dx <= 1; ++dx)
            {
              long x = cx + dx, y = cy + dy;
              if (y < 0 || y >= ny)
                continue;
              if (x < 0 || x >= nx)
                {
                  if (!periodic)
                    continue;
                  x = (x + nx) % nx;
                }
              const long c = y * nx + x;
              if (std::find(out, out + count, c) == out + count)
                out[count++] = c;
            }
        return count;
      }
    };

    /// Whether discs i < j of different bodies are a contact: closer than @p distance, or
    /// closed by their motions (@p motion, may be empty) until the next detection; if so,
    /// @p c describes it (branch across the period, normal, gap).
    bool pair_contact(const ParticleSystem &system, const std::vector<Vec2> &centres,
                      const std::vector<Vec2> &motion, double distance, unsigned int i, unsigned int j,
                      Contact &c)
    {
      Vec2 branch = centres[j] - centres[i];
      if (system.period > 0)
        branch.x() -= system.period * std::round(branch.x() / system.period);
      const double ri = system.discs[i].radius, rj = system.discs[j].radius;
      const Vec2   relative_motion = motion.empty() ? Vec2::Zero() : Vec2(motion[j] - motion[i]);
      const double reach_ij        = ri + rj + std::max(distance, relative_motion.norm());
      const double d2              = branch.squaredNorm();
      if (d2 > reach_ij * reach_ij)
        return false;
      const double dist = std::sqrt(d2);
      if (dist == 0)
        throw RunError("discs " + std::to_string(i) + " and " + std::to_string(j) +
                       " have the same centre: the contact normal is undefined");
      if (dist - ri - rj > distance && dist - ri - rj > -relative_motion.dot(branch) / dist)
        return false; // beyond the distance, and its motion does not close it
      c.disc[0] = i;
      c.disc[1] = j;
      c.body[0] = system.discs[i].body;
      c.body[1] = system.discs[j].body;
      c.branch  = branch;
      c.normal  = branch / dist;
      c.gap     = dist - ri - rj;
      return true;
    }
  } // namespace

  void ContactDetector::detect(const ParticleSystem &system, const std::vector<Vec2> &centres, double distance,
                               unsigned int threads, const std::vector<Vec2> &motion, std::vector<Contact> &contacts,
                               const std::optional<PairBand> &band)
  {
    contacts.clear();
    const std::size_t n = centres.size();
    if (n < 2)
      return;
    if (!motion.empty() && motion.size() != n)
      throw RunError("contact detection: " + std::to_string(motion.size()) + " disc motions for " +
                     std::to_string(n) + " discs");

    // Cell size: the largest centre distance that can still be a contact.
    const double reach =
      2 * system.max_radius() + std::max({distance, closing_reach(system, motion, max_motion_reach), 0.0});
    const CellGrid grid(system, centres, reach);

    // A pair is found from the cell of its first disc, whose centre lies within half a
    // reach of the pair's midpoint; one more cell on each side for the band's heights.
    long first_row = 0, end_row = grid.ny;
    if (band)
      {
        const auto row_of = [&](double y) { // the bands' outer edges are infinite
          const double row = (y - grid.ymin) / grid.wy;
          return row <= 0 ? 0L : row >= double(grid.ny - 1) ? grid.ny - 1 : long(row);
        };
        first_row = row_of(band->lowest - reach);
        end_row   = row_of(band->highest + reach) + 1;
      }

    // Counting sort by cell of the discs in the rows searched and their neighbour rows.
    const long first_cell = std::max(0L, first_row - 1) * grid.nx, end_cell = std::min(grid.ny, end_row + 1) * grid.nx;
    constexpr unsigned int elsewhere = ~0u;
    cell_start.assign(grid.nx * grid.ny + 1, 0);
    cell_of.resize(n);
    for (std::size_t i = 0; i < n; ++i)
      {
        const long c = grid.cell(centres[i]);
        cell_of[i]   = c >= first_cell && c < end_cell ? static_cast<unsigned int>(c) : elsewhere;
        if (cell_of[i] != elsewhere)
          ++cell_start[c + 1];
      }
    for (long c = 0; c < grid.nx * grid.ny; ++c)
      cell_start[c + 1] += cell_start[c];
    cell_items.resize(cell_start.back());
    {
      std::vector<unsigned int> fill(cell_start.begin(), cell_start.end() - 1);
      for (std::size_t i = 0; i < n; ++i)
        if (cell_of[i] != elsewhere)
          cell_items[fill[cell_of[i]]++] = i;
    }

    // The pairs found in rows [row_begin, row_end) of cells, in the serial order.
    const auto detect_rows = [&](long row_begin, long row_end, std::vector<Contact> &found) {
      Contact c;
      long    neighbours[9];
      for (long cy = row_begin; cy < row_end; ++cy)
        for (long cx = 0; cx < grid.nx; ++cx)
          {
            const int  n_neighbours = grid.neighbours(cx, cy, neighbours);
            const long here         = cy * grid.nx + cx;
            for (unsigned int a = cell_start[here]; a < cell_start[here + 1]; ++a)
              {
                const unsigned int i = cell_items[a];
                for (int k = 0; k < n_neighbours; ++k)
                  for (unsigned int b = cell_start[neighbours[k]]; b < cell_start[neighbours[k] + 1]; ++b)
                    {
                      const unsigned int j = cell_items[b];
                      if (j > i && system.discs[i].body != system.discs[j].body && (!band || band->holds(i, j)) &&
                          pair_contact(system, centres, motion, distance, i, j, c))
                        found.push_back(c);
                    }
              }
          }
    };

    // Rows of cells in chunks, each chunk's pairs found concurrently and joined in chunk
    // order: the same contacts in the same order as one pass over all rows.
    const long rows     = end_row - first_row;
    const long n_chunks = threads > 1 ? std::min<long>(rows, 4 * long(threads)) : 1;
    if (n_chunks <= 1)
      {
        detect_rows(first_row, end_row, contacts);
        return;
      }
    chunk_contacts.resize(n_chunks);
    dealii::parallel::apply_to_subranges(
      0L, n_chunks,
      [&](long begin, long end) {
        for (long k = begin; k < end; ++k)
          {
            chunk_contacts[k].clear();
            detect_rows(first_row + rows * k / n_chunks, first_row + rows * (k + 1) / n_chunks, chunk_contacts[k]);
          }
      },
      1);
    for (const auto &f : chunk_contacts)
      contacts.insert(contacts.end(), f.begin(), f.end());
  }
} // namespace tribo::dem
