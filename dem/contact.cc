#include "dem/contact.h"

#include "core/errors.h"

#include <deal.II/base/parallel.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace tribo::dem
{
  void ContactDetector::detect(const ParticleSystem &system, const std::vector<Vec2> &centres, double distance,
                               unsigned int threads, const std::vector<Vec2> &motion, std::vector<Contact> &contacts)
  {
    contacts.clear();
    const std::size_t n = centres.size();
    if (n < 2)
      return;
    if (!motion.empty() && motion.size() != n)
      throw RunError("contact detection: " + std::to_string(motion.size()) + " disc motions for " +
                     std::to_string(n) + " discs");

    // The largest relative motion of two discs: twice the largest distance of a motion from
    // the middle of their bounding box, at most max_motion_reach largest radii (a few fast
    // discs cannot widen the cells without bound; pairs further apart are missed as
    // without motions, and the overlap guard of the step names the fastest mover), and never
    // so much that a period which holds two reaches without motions would not hold two now.
    double closing_reach = 0;
    if (!motion.empty())
      {
        Vec2 low = motion[0], high = motion[0];
        for (const Vec2 &m : motion)
          {
            low  = low.cwiseMin(m);
            high = high.cwiseMax(m);
          }
        const Vec2 middle = 0.5 * (low + high);
        for (const Vec2 &m : motion)
          closing_reach = std::max(closing_reach, 2 * (m - middle).norm());
        closing_reach = std::min(closing_reach, max_motion_reach * system.max_radius());
        if (system.period > 0)
          closing_reach = std::min(closing_reach, 0.5 * system.period - 2 * system.max_radius());
      }
    // Cell size: the largest centre distance that can still be a contact.
    const double reach = 2 * system.max_radius() + std::max({distance, closing_reach, 0.0});
    double       xmin = centres[0].x(), xmax = xmin, ymin = centres[0].y(), ymax = ymin;
    for (const auto &c : centres)
      {
        xmin = std::min(xmin, c.x());
        xmax = std::max(xmax, c.x());
        ymin = std::min(ymin, c.y());
        ymax = std::max(ymax, c.y());
      }
    const bool periodic = system.period > 0;
    if (periodic)
      {
        if (system.period < 2 * reach)
          throw RunError("the period along x (" + to_text(system.period) +
                         " m) is shorter than two contact reaches (" +
                         to_text(2 * reach) + " m): enlarge the domain");
        xmin = 0;
        xmax = system.period;
      }
    const auto cells_along = [&](double length) {
      return std::max<long>(1, std::min<long>(long(length / reach), 1L << 20));
    };
    const long   nx = cells_along(xmax - xmin), ny = cells_along(ymax - ymin);
    const double wx = periodic ? system.period / nx : std::max(reach, (xmax - xmin) / nx);
    const double wy = std::max(reach, (ymax - ymin) / ny);
    const auto   cell_x = [&](double x) { return std::clamp<long>(long((x - xmin) / wx), 0, nx - 1); };
    const auto   cell_y = [&](double y) { return std::clamp<long>(long((y - ymin) / wy), 0, ny - 1); };

    // Counting sort of the discs by cell.
    cell_start.assign(nx * ny + 1, 0);
    cell_of.resize(n);
    for (std::size_t i = 0; i < n; ++i)
      {
        cell_of[i] = cell_y(centres[i].y()) * nx + cell_x(centres[i].x());
        ++cell_start[cell_of[i] + 1];
      }
    for (long c = 0; c < nx * ny; ++c)
      cell_start[c + 1] += cell_start[c];
    cell_items.resize(n);
    {
      std::vector<unsigned int> fill(cell_start.begin(), cell_start.end() - 1);
      for (std::size_t i = 0; i < n; ++i)
        cell_items[fill[cell_of[i]]++] = i;
    }

    // The pairs found in rows [row_begin, row_end) of cells, in the serial order.
    const auto detect_rows = [&](long row_begin, long row_end, std::vector<Contact> &found) {
      for (long cy = row_begin; cy < row_end; ++cy)
        for (long cx = 0; cx < nx; ++cx)
          {
            // The distinct neighbour cells (fewer than 9 when nx or ny < 3).
            long neighbours[9];
            int  n_neighbours = 0;
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
                  if (std::find(neighbours, neighbours + n_neighbours, c) == neighbours + n_neighbours)
                    neighbours[n_neighbours++] = c;
                }
            const long here = cy * nx + cx;
            for (unsigned int a = cell_start[here]; a < cell_start[here + 1]; ++a)
              {
                const unsigned int i = cell_items[a];
                for (int k = 0; k < n_neighbours; ++k)
                  for (unsigned int b = cell_start[neighbours[k]]; b < cell_start[neighbours[k] + 1]; ++b)
                    {
                      const unsigned int j = cell_items[b];
                      if (j <= i || system.discs[i].body == system.discs[j].body)
                        continue;
                      Vec2 branch = centres[j] - centres[i];
                      if (periodic)
                        branch.x() -= system.period * std::round(branch.x() / system.period);
                      const double ri = system.discs[i].radius, rj = system.discs[j].radius;
                      const Vec2   relative_motion = motion.empty() ? Vec2::Zero() : Vec2(motion[j] - motion[i]);
                      const double reach_ij = ri + rj + std::max(distance, relative_motion.norm());
                      const double d2       = branch.squaredNorm();
                      if (d2 > reach_ij * reach_ij)
                        continue;
                      const double dist = std::sqrt(d2);
                      if (dist == 0)
                        throw RunError("discs " + std::to_string(i) + " and " + std::to_string(j) +
                                       " have the same centre: the contact normal is undefined");
                      if (dist - ri - rj > distance && dist - ri - rj > -relative_motion.dot(branch) / dist)
                        continue; // beyond the distance, and its motion does not close it
                      Contact c;
                      c.disc[0] = i;
                      c.disc[1] = j;
                      c.body[0] = system.discs[i].body;
                      c.body[1] = system.discs[j].body;
                      c.branch  = branch;
                      c.normal  = branch / dist;
                      c.gap     = dist - ri - rj;
                      found.push_back(c);
                    }
              }
          }
    };

    // Rows of cells in chunks, each chunk's pairs found concurrently and joined in chunk
    // order: the same contacts in the same order as one pass over all rows.
    const long n_chunks = threads > 1 ? std::min<long>(ny, 4 * long(threads)) : 1;
    if (n_chunks == 1)
      {
        detect_rows(0, ny, contacts);
        return;
      }
    chunk_contacts.resize(n_chunks);
    dealii::parallel::apply_to_subranges(
      0L, n_chunks,
      [&](long begin, long end) {
        for (long k = begin; k < end; ++k)
          {
            chunk_contacts[k].clear();
            detect_rows(ny * k / n_chunks, ny * (k + 1) / n_chunks, chunk_contacts[k]);
          }
      },
      1);
    for (const auto &f : chunk_contacts)
      contacts.insert(contacts.end(), f.begin(), f.end());
  }
} // namespace tribo::dem
