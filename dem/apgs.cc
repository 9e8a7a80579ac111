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
    // Over fixed chunks (dem/scaled_operator.h), concurrently with Threads > 1, the same
    // bits on any number of threads.
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
    // With @p affected, only the marked rows' map is recomputed (the others' entries of
    // `error` are still those of y): the check after a polish, which changed y on a few
    // contacts only. It gives the bits of a whole check and is not counted as a pass.
    auto relative_map = [&](const Eigen::VectorXd &y, const std::vector<char> *affected = nullptr) {
      if (!affected)
        ++report.iterations;
      op.set_vector(y);
      const MapSums sums = over_chunks<MapSums>(n, prm.threads, [&](Eigen::Index first, Eigen::Index last) {
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
      });
      mean_loaded = sums.loaded > 0 ? sums.loaded_sum / sums.loaded : lcp.scale;
      return sums.worst / mean_loaded;
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
          if (scaled.U.cols() > 0 && scaled.U.row(j).squaredNorm() > 0)
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
    // `affected` marks the rows whose map a polish changed: the rows of the polished
    // columns in A', and the walls' low-rank rows (`low_rank_rows`) when a polished contact
    // is one of them.
    std::vector<char>         marked(n, 0), affected(n, 0);
    std::vector<Eigen::Index> local, low_rank_rows;
    for (Eigen::Index j = 0; j < n; ++j)
      if (scaled.U.cols() > 0 && scaled.U.row(j).squaredNorm() > 0)
        low_rank_rows.push_back(j);
    auto polish = [&](Eigen::VectorXd &y, Eigen::VectorXd &z) {
      const double threshold = prm.residual_target * mean_loaded;
      local.clear();
      for (Eigen::Index j = 0; j < n; ++j)
        {
          marked[j] = error[j] > threshold;
          if (marked[j])
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
      std::fill(affected.begin(), affected.end(), 0);
      bool wall = false;
      for (const Eigen::Index j : local)
        {
          for (Eigen::SparseMatrix<double>::InnerIterator a(scaled.A, j); a; ++a)
            affected[a.row()] = 1;
          affected[j] = 1;
          wall = wall || (scaled.U.cols() > 0 && scaled.U.row(j).squaredNorm() > 0);
        }
      if (wall)
        for (const Eigen::Index j : low_rank_rows)
          affected[j] = 1;
      return true;
    };

    Eigen::VectorXd y = scaled.y.cwiseMax(0.0), y_last(n), z = y, next(n);
    double          t        = 1;
    unsigned int    polished = 0; // polishes since the last sweep
    double          map      = relative_map(y);
    while (map > prm.residual_target)
      {
        if (report.iterations >= prm.max_iterations)
          {
            report.converged = false;
            break;
          }
        if (polished < polishes_per_check && polish(y, z))
          {
            ++polished;
            map = relative_map(y, &affected);
            continue;
          }
        polished = 0;
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
