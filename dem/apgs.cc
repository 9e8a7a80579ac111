#include "dem/apgs.h"

#include "dem/scaled_operator.h"

#include <deal.II/base/parallel.h>

#include <algorithm>
#include <cmath>
#include <utility>

namespace tribo::dem
{
  SolveReport ApgsSolver::solve_problem(std::vector<Contact> &contacts, BodyState &state)
  {
    SolveReport                 report;
    const FrictionlessProblem   lcp(contacts, state, true);
    const Eigen::Index          n      = lcp.size();
    FrictionlessProblem::Scaled scaled = lcp.scaled();
    const Eigen::VectorXd      &inv_root = scaled.inv_root;
    const Eigen::VectorXd      &b        = scaled.b;
    ScaledOperator              op(scaled);

    // The natural map at y over its mean loaded impulse (one product); each contact's
    // |min(y_j, g_j)| / sqrt(D_j) is kept in `error` and the mean in `mean_loaded` (N s/m).
    Eigen::VectorXd error(n);
    double          mean_loaded = lcp.scale;
    // Over fixed chunks (dem/scaled_operator.h), concurrently with Threads > 1, merged in
    // chunk order: the same bits on any number of threads. The chunks' sums are kept, so
    // that the check after a polish recomputes only the chunks that hold a changed row.
    struct MapSums
    {
      double worst = 0, loaded_sum = 0, loaded = 0;
      void   merge(const MapSums &p)
      {
        worst = std::max(worst, p.worst);
        loaded_sum += p.loaded_sum;
        loaded += p.loaded;
      }
    };
    std::vector<MapSums> chunk_sums;
    // The map of the rows [first, last) (with @p affected, only the marked rows' entries of
    // `error` are recomputed; the others are still those of y), op set to y.
    auto map_of_rows = [&](const Eigen::VectorXd &y, Eigen::Index first, Eigen::Index last,
                           const std::vector<char> *affected) {
      MapSums part;
      for (Eigen::Index j = first; j < last; ++j)
        {
          if (!affected || (*affected)[j])
            error[j] = std::abs(std::min(y[j], op.row_times(y, j) + b[j])) * inv_root[j];
          part.worst = std::max(part.worst, error[j]);
          if (y[j] > 0)
            {
              part.loaded_sum += y[j] * inv_root[j];
              ++part.loaded;
            }
        }
      return part;
    };
    auto merged_map = [&]() {
      const MapSums sums = merged_in_order(chunk_sums);
      mean_loaded        = sums.loaded > 0 ? sums.loaded_sum / sums.loaded : lcp.scale;
      return sums.worst / mean_loaded;
    };
    // A whole check: one pass.
    auto relative_map = [&](const Eigen::VectorXd &y) {
      ++report.iterations;
      op.set_vector(y);
      chunk_partials(n, prm.threads, [&](Eigen::Index first, Eigen::Index last) {
        return map_of_rows(y, first, last, nullptr);
      }, chunk_sums);
      return merged_map();
    };
    // The sweep's order: the contacts (in detection order, rows of cells upwards) cut into
    // slab_count slabs of consecutive contacts, the even slabs first, then the odd ones.
    // When no contact couples two slabs that are not neighbours and the walls' low-rank rows
    // lie in one slab, the slabs of one colour share nothing and run concurrently, with the
    // same bits on any number of threads; otherwise one slab holds every contact.
    std::vector<Eigen::Index> slab_start{0, n};
    {
      const Eigen::Index count = std::max<Eigen::Index>(1, std::min<Eigen::Index>(slab_count, n / 64) / 2 * 2);
      std::vector<Eigen::Index> start(count + 1);
      for (Eigen::Index q = 0; q <= count; ++q)
        start[q] = q * n / count;
      auto slab_of = [&](Eigen::Index j) {
        return Eigen::Index(std::upper_bound(start.begin(), start.end(), j) - start.begin()) - 1;
      };
      bool         separate = count >= 2;
      Eigen::Index low_rank_slab = -1;
      for (Eigen::Index j = 0; j < n && separate; ++j)
        {
          const Eigen::Index s = slab_of(j);
          for (Eigen::SparseMatrix<double>::InnerIterator a(scaled.A, j); a && separate; ++a)
            separate = std::abs(slab_of(a.row()) - s) <= 1;
          if (op.has_low_rank(j))
            {
              separate = separate && (low_rank_slab < 0 || low_rank_slab == s);
              low_rank_slab = s;
            }
        }
      if (separate)
        slab_start = start;
    }
    const Eigen::Index slabs = Eigen::Index(slab_start.size()) - 1;
    report.concurrent        = slabs > 1 && prm.threads > 1;
    // One projected Gauss-Seidel sweep of v in place (unit diagonal: A'_jj + |U'_j|^2 = 1).
    auto sweep_slab = [&](Eigen::VectorXd &v, Eigen::Index q) {
      for (Eigen::Index j = slab_start[q]; j < slab_start[q + 1]; ++j)
        {
          const double next = std::max(0.0, v[j] - (op.row_times(v, j) + b[j]));
          if (next != v[j])
            {
              op.add_to_low_rank(j, next - v[j]);
              v[j] = next;
            }
        }
    };
    auto sweep = [&](Eigen::VectorXd &v) {
      ++report.iterations;
      op.set_vector(v);
      for (const Eigen::Index colour : {0, 1})
        {
          const Eigen::Index count = (slabs - colour + 1) / 2; // slabs colour, colour + 2, ...
          auto work = [&](Eigen::Index first, Eigen::Index last) {
            for (Eigen::Index k = first; k < last; ++k)
              sweep_slab(v, colour + 2 * k);
          };
          if (prm.threads > 1 && count > 1)
            dealii::parallel::apply_to_subranges(Eigen::Index(0), count, work, 1);
          else
            work(0, count);
        }
    };

    // The local polish: projected Gauss-Seidel passes over the contacts above the target and
    // their neighbours up to polish_rings rings away in A' (ring 1: the rows of their
    // columns), y changed in place and z by the same amount (the momentum y - y_last kept).
    // False when nothing is above the target or the neighbourhood is too large to be local.
    // It marks in `affected` (listed in `affected_rows`) the rows whose map it changed: the
    // rows of the polished columns of A', and the walls' low-rank rows when a polished
    // contact is one of them. All of it costs O(the polished contacts + the chunks).
    std::vector<char>         marked(n, 0), affected(n, 0);
    std::vector<Eigen::Index> local, affected_rows;
    auto affect = [&](Eigen::Index j) {
      if (!affected[j])
        {
          affected[j] = 1;
          affected_rows.push_back(j);
        }
    };
    auto polish = [&](Eigen::VectorXd &y, Eigen::VectorXd &z) {
      const double threshold = prm.residual_target * mean_loaded;
      local.clear();
      for (Eigen::Index c = 0; c < Eigen::Index(chunk_sums.size()); ++c)
        if (chunk_sums[c].worst > threshold)
          for (Eigen::Index j = c * chunk_size; j < std::min(n, (c + 1) * chunk_size); ++j)
            if (error[j] > threshold)
              {
                marked[j] = 1;
                local.push_back(j);
              }
      std::size_t last_ring = 0; // local[last_ring, ...) is the outermost ring so far
      for (unsigned int ring = 0; ring < polish_rings && double(local.size()) <= polish_fraction * double(n); ++ring)
        {
          const std::size_t inner = local.size();
          for (std::size_t q = std::exchange(last_ring, inner); q < inner; ++q)
            for (Eigen::SparseMatrix<double>::InnerIterator a(scaled.A, local[q]); a; ++a)
              if (!marked[a.row()])
                {
                  marked[a.row()] = 1;
                  local.push_back(a.row());
                }
        }
      for (const Eigen::Index j : local)
        marked[j] = 0;
      std::sort(local.begin(), local.end()); // the sweep's order
      if (local.empty() || double(local.size()) > polish_fraction * double(n))
        return false;
      op.set_vector(y);
      for (unsigned int pass = 0; pass < polish_passes; ++pass)
        for (const Eigen::Index j : local)
          {
            const double next = std::max(0.0, y[j] - (op.row_times(y, j) + b[j]));
            if (next != y[j])
              {
                op.add_to_low_rank(j, next - y[j]);
                z[j] += next - y[j];
                y[j] = next;
              }
          }
      bool wall = false;
      for (const Eigen::Index j : local)
        {
          for (Eigen::SparseMatrix<double>::InnerIterator a(scaled.A, j); a; ++a)
            affect(a.row());
          affect(j);
          wall = wall || op.has_low_rank(j);
        }
      if (wall)
        for (const Eigen::Index j : op.low_rank_row_list())
          affect(j);
      return true;
    };
    // The check after a polish: the chunks that hold an affected row are recomputed, the
    // others keep their sums (y did not change there): the bits of a whole check, at the
    // polish's cost. Not counted as a pass.
    std::vector<char>         dirty(chunk_count(n), 0);
    std::vector<Eigen::Index> chunks; // the dirty chunks, in the order found
    auto recheck = [&](const Eigen::VectorXd &y) {
      op.set_vector(y);
      chunks.clear();
      for (const Eigen::Index j : affected_rows)
        if (!dirty[j / chunk_size])
          {
            dirty[j / chunk_size] = 1;
            chunks.push_back(j / chunk_size);
          }
      for (const Eigen::Index c : chunks)
        {
          chunk_sums[c] = map_of_rows(y, c * chunk_size, std::min(n, (c + 1) * chunk_size), &affected);
          dirty[c]      = 0;
        }
      for (const Eigen::Index j : affected_rows)
        affected[j] = 0;
      affected_rows.clear();
      return merged_map();
    };

    Eigen::VectorXd y = scaled.y.cwiseMax(0.0), y_last(n), z = y, next(n);
    double          t        = 1;
    // Polishes since the last block of sweeps, and since the lowest map among them.
    unsigned int polished = 0, since_lowest = 0;
    double       lowest   = INFINITY;
    double       map      = relative_map(y);
    while (map > prm.residual_target)
      {
        if (report.iterations >= prm.max_iterations)
          {
            report.converged = false;
            break;
          }
        if (polished < max_polishes && since_lowest < polish_patience && polish(y, z))
          {
            ++polished;
            map = recheck(y);
            since_lowest = map < lowest ? 0 : since_lowest + 1;
            lowest       = std::min(lowest, map);
            continue;
          }
        polished = since_lowest = 0;
        lowest                  = INFINITY;
        // The vector passes over fixed chunks, as the check (the same bits on any number of
        // threads); the next sweep's start (next = z) written with z.
        struct Sum
        {
          double value = 0;
          void   merge(const Sum &p) { value += p.value; }
        };
        next = z;
        for (unsigned int k = 0; k < check_interval; ++k)
          {
            sweep(next);
            const double opposed = over_chunks<Sum>(n, prm.threads, [&](Eigen::Index first, Eigen::Index last) {
              Sum part;
              for (Eigen::Index j = first; j < last; ++j)
                part.value += (z[j] - next[j]) * (next[j] - y[j]);
              return part;
            }).value;
            if (opposed > 0)
              t = 1;
            const double t_next = 0.5 * (1 + std::sqrt(1 + 4 * t * t));
            const double beta   = (t - 1) / t_next;
            y_last.swap(y);
            y.swap(next);
            over_chunks<NoSums>(n, prm.threads, [&](Eigen::Index first, Eigen::Index last) {
              for (Eigen::Index j = first; j < last; ++j)
                next[j] = z[j] = y[j] + beta * (y[j] - y_last[j]);
              return NoSums{};
            });
            t = t_next;
          }
        map = relative_map(y);
      }
    lcp.apply(y.cwiseProduct(inv_root), contacts, state);
    return report;
  }
} // namespace tribo::dem
