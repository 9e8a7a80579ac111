#include "dem/solvers/apgs.h"

#include "dem/linalg/scaled_operator.h"
#include "dem/solvers/sweep_problem.h"

#include <deal.II/base/parallel.h>

#include <algorithm>
#include <cmath>
#include <utility>

namespace tribo::dem
{
  namespace
  {
    /// The per-chunk sums of a check: the worst contact's map, and the loaded impulses'
    /// sum and count. Merged in chunk order: the same bits on any number of threads.
    struct MapSums
    {
      double worst = 0, loaded_sum = 0, loaded = 0, gap = 0;
      void   merge(const MapSums &p)
      {
        worst = std::max(worst, p.worst);
        gap   = std::max(gap, p.gap);
        loaded_sum += p.loaded_sum;
        loaded += p.loaded;
      }
    };

    /// One APGS solve (the method is in dem/solvers/apgs.h): its vectors and its steps, the
    /// contact's map and local solve, the sweep in slabs, the check, the local polish and
    /// its check, and the blocks of sweeps with momentum.
    class ApgsRun
    {
    public:
      ApgsRun(const SweepProblem &problem, const ContactLaw &law, const SolverParameters &prm, double theta_h,
              SolveReport &report);
      /// The solve's final iterate, in the scaled variables of @p problem.
      Eigen::VectorXd solve();

    private:
      const SweepProblem                 &problem;
      const FrictionlessProblem::Scaled  &scaled;
      const ContactLaw                   &law;
      const SolverParameters             &prm;
      SolveReport                        &report;
      const Eigen::Index                  n, w, rows; ///< contacts; rows per contact (w j, ..., w j + w - 1: contact j)
      ScaledOperator                      op;
      Eigen::VectorXd                     error;         ///< each contact's map at the last check, N s/m
      /// The gap violation a check passes with IQS (m; 0: no gap test),
      /// SolverParameters::apgs_gap_stop(); and theta h (s).
      const double                        gap_tolerance, theta_h;
      Eigen::VectorXd                     gap;           ///< each contact's gap violation at the last check, m
      double                              mean_loaded;   ///< the mean loaded impulse at the last check, N s/m
      double                              worst_gap = 0; ///< the largest gap violation at the last check, m
      std::vector<MapSums>                chunk_sums;    ///< the last check's sums per chunk
      std::vector<Eigen::Index>           slab_start;    ///< the sweep's slabs, in contacts
      std::vector<char>                   marked, affected, dirty;
      std::vector<Eigen::Index>           local, affected_rows, chunks;

      double contact_map(const Eigen::VectorXd &y, Eigen::Index j, double g_n) const;
      void   relax(Eigen::VectorXd &v, Eigen::Index j, Eigen::VectorXd *also);
      bool   on_low_rank(Eigen::Index j) const;
      MapSums map_of_rows(const Eigen::VectorXd &y, Eigen::Index first, Eigen::Index last,
                          const std::vector<char> *only);
      double merged_map();
      /// Whether the last check's gap violation is above the gap tolerance.
      bool   gaps_open() const { return gap_tolerance > 0 && worst_gap > gap_tolerance; }
      double relative_map(const Eigen::VectorXd &y);
      void   choose_slabs();
      void   sweep(Eigen::VectorXd &v);
      void   affect(Eigen::Index j);
      bool   polish(Eigen::VectorXd &y, Eigen::VectorXd &z);
      double recheck(const Eigen::VectorXd &y);
      void   sweeps_with_momentum(Eigen::VectorXd &y, Eigen::VectorXd &y_last, Eigen::VectorXd &z,
                                  Eigen::VectorXd &next, double &t);
    };

    ApgsRun::ApgsRun(const SweepProblem &problem, const ContactLaw &law, const SolverParameters &prm,
                     double theta_h, SolveReport &report)
      : problem(problem)
      , scaled(problem.scaled)
      , law(law)
      , prm(prm)
      , report(report)
      , n(problem.n_contacts())
      , w(problem.width)
      , rows(w * n)
      , op(scaled)
      , error(n)
      , gap_tolerance(law.type == ContactLaw::Type::iqs && theta_h > 0 ? prm.apgs_gap_stop() : 0.0)
      , theta_h(theta_h)
      , gap(n)
      , mean_loaded(problem.scale)
      , slab_start{0, n}
      , marked(n, 0)
      , affected(n, 0)
      , dirty(chunk_count(n), 0)
    {
      choose_slabs();
    }

    double ApgsRun::contact_map(const Eigen::VectorXd &y, Eigen::Index j, double g_n) const
    {
      return problem.contact_map(op, scaled.b, y, j, g_n);
    }

    void ApgsRun::relax(Eigen::VectorXd &v, Eigen::Index j, Eigen::VectorXd *also)
    {
      problem.relax(op, law, scaled.b, v, j, also);
    }

    /// Whether a row of contact j has low-rank entries (a wall's contact).
    bool ApgsRun::on_low_rank(Eigen::Index j) const
    {
      for (Eigen::Index k = w * j; k < w * j + w; ++k)
        if (op.has_low_rank(k))
          return true;
      return false;
    }

    /// The map of the contacts [first, last), op set to y; with @p only, just the marked
    /// contacts' entries of `error` are recomputed (the others are still those of y).
    MapSums ApgsRun::map_of_rows(const Eigen::VectorXd &y, Eigen::Index first, Eigen::Index last,
                                 const std::vector<char> *only)
    {
      MapSums part;
      for (Eigen::Index j = first; j < last; ++j)
        {
          if (!only || (*only)[j])
            {
              const Eigen::Index k   = w * j;
              const double       g_n = op.row_times(y, k) + scaled.b[k];
              error[j]               = contact_map(y, j, g_n);
              // u~_n = g_n sqrt(D) (m/s): its closing part times theta h.
              if (gap_tolerance > 0)
                gap[j] = theta_h * std::max(0.0, -g_n) / scaled.inv_root[k];
            }
          part.worst = std::max(part.worst, error[j]);
          if (gap_tolerance > 0)
            part.gap = std::max(part.gap, gap[j]);
          if (y[w * j] > 0)
            {
              part.loaded_sum += y[w * j] * scaled.inv_root[w * j];
              ++part.loaded;
            }
        }
      return part;
    }

    /// The worst map over the mean loaded impulse from the chunks' sums.
    double ApgsRun::merged_map()
    {
      const MapSums sums = merged_in_order(chunk_sums);
      mean_loaded        = sums.loaded > 0 ? sums.loaded_sum / sums.loaded : problem.scale;
      worst_gap          = sums.gap;
      return sums.worst / mean_loaded;
    }

    /// A whole check at y: one pass over fixed chunks (dem/linalg/scaled_operator.h),
    /// concurrently with Threads > 1; the chunks' sums are kept for the check after a polish.
    double ApgsRun::relative_map(const Eigen::VectorXd &y)
    {
      ++report.iterations;
      op.set_vector(y);
      chunk_partials(
        n, prm.threads, [&](Eigen::Index first, Eigen::Index last) { return map_of_rows(y, first, last, nullptr); },
        chunk_sums);
      return merged_map();
    }

    /// The sweep's order: the contacts (in detection order, rows of cells upwards) cut into
    /// slab_count slabs of consecutive contacts, the even slabs first, then the odd ones.
    /// When no contact couples two slabs that are not neighbours and the walls' low-rank rows
    /// lie in one slab, the slabs of one colour share nothing and run concurrently, with the
    /// same bits on any number of threads; otherwise one slab holds every contact.
    void ApgsRun::choose_slabs()
    {
      const Eigen::Index count =
        std::max<Eigen::Index>(1, std::min<Eigen::Index>(ApgsSolver::slab_count, n / 64) / 2 * 2);
      std::vector<Eigen::Index> start(count + 1);
      for (Eigen::Index q = 0; q <= count; ++q)
        start[q] = q * n / count;
      auto slab_of = [&](Eigen::Index j) {
        return Eigen::Index(std::upper_bound(start.begin(), start.end(), j) - start.begin()) - 1;
      };
      bool         separate      = count >= 2;
      Eigen::Index low_rank_slab = -1;
      for (Eigen::Index k = 0; k < rows && separate; ++k)
        {
          // A column's rows are sorted: its first and last tell the slabs it reaches.
          const Eigen::Index s = slab_of(k / w), begin = scaled.A.outerIndexPtr()[k],
                             end = scaled.A.outerIndexPtr()[k + 1];
          if (end > begin)
            separate = std::abs(slab_of(scaled.A.innerIndexPtr()[begin] / w) - s) <= 1 &&
                       std::abs(slab_of(scaled.A.innerIndexPtr()[end - 1] / w) - s) <= 1;
          if (op.has_low_rank(k))
            {
              separate      = separate && (low_rank_slab < 0 || low_rank_slab == s);
              low_rank_slab = s;
            }
        }
      if (separate)
        slab_start = start;
      report.concurrent = slab_start.size() > 2 && prm.threads > 1;
    }

    /// One projected Gauss-Seidel sweep of v in place, colour by colour.
    void ApgsRun::sweep(Eigen::VectorXd &v)
    {
      ++report.iterations;
      op.set_vector(v);
      const Eigen::Index slabs = Eigen::Index(slab_start.size()) - 1;
      for (const Eigen::Index colour : {0, 1})
        {
          const Eigen::Index count = (slabs - colour + 1) / 2; // slabs colour, colour + 2, ...
          auto work = [&](Eigen::Index first, Eigen::Index last) {
            for (Eigen::Index k = first; k < last; ++k)
              for (Eigen::Index j = slab_start[colour + 2 * k]; j < slab_start[colour + 2 * k + 1]; ++j)
                relax(v, j, nullptr);
          };
          if (prm.threads > 1 && count > 1)
            dealii::parallel::apply_to_subranges(Eigen::Index(0), count, work, 1);
          else
            work(0, count);
        }
    }

    /// Mark contact j's map as changed by the polish.
    void ApgsRun::affect(Eigen::Index j)
    {
      if (!affected[j])
        {
          affected[j] = 1;
          affected_rows.push_back(j);
        }
    }

    /// The local polish: projected Gauss-Seidel passes over the contacts above the target and
    /// their neighbours up to polish_rings rings away in A' (ring 1: the rows of their
    /// columns), y changed in place and z by the same amount (the momentum y - y_last kept).
    /// False when nothing is above the target or the neighbourhood is too large to be local.
    /// It marks (affect) the contacts whose map it changed: the rows of the polished columns
    /// of A', and the walls' low-rank rows when a polished contact is one of them. All of it
    /// costs O(the polished contacts + the chunks).
    bool ApgsRun::polish(Eigen::VectorXd &y, Eigen::VectorXd &z)
    {
      const double threshold = prm.residual_target * mean_loaded;
      local.clear();
      for (Eigen::Index c = 0; c < Eigen::Index(chunk_sums.size()); ++c)
        if (chunk_sums[c].worst > threshold || (gap_tolerance > 0 && chunk_sums[c].gap > gap_tolerance))
          for (Eigen::Index j = c * chunk_size; j < std::min(n, (c + 1) * chunk_size); ++j)
            if (error[j] > threshold || (gap_tolerance > 0 && gap[j] > gap_tolerance))
              {
                marked[j] = 1;
                local.push_back(j);
              }
      problem.add_rings(local, marked, ApgsSolver::polish_rings, ApgsSolver::polish_fraction * double(n));
      std::sort(local.begin(), local.end()); // the sweep's order
      if (local.empty() || double(local.size()) > ApgsSolver::polish_fraction * double(n))
        return false;
      op.set_vector(y);
      for (unsigned int pass = 0; pass < ApgsSolver::polish_passes; ++pass)
        for (const Eigen::Index j : local)
          relax(y, j, &z);
      bool wall = false;
      for (const Eigen::Index j : local)
        {
          for (Eigen::Index k = w * j; k < w * j + w; ++k)
            for (Eigen::SparseMatrix<double>::InnerIterator a(scaled.A, k); a; ++a)
              affect(a.row() / w);
          affect(j);
          wall = wall || on_low_rank(j);
        }
      if (wall)
        for (const Eigen::Index k : op.low_rank_row_list())
          affect(k / w);
      return true;
    }

    /// The check after a polish: the chunks that hold an affected contact are recomputed,
    /// the others keep their sums (y did not change there): the bits of a whole check, at
    /// the polish's cost. Not counted as a pass.
    double ApgsRun::recheck(const Eigen::VectorXd &y)
    {
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
    }

    /// check_interval sweeps with Nesterov's momentum and the gradient restart (the header's
    /// recursion): y_{k+1} = S(z_k), z_{k+1} = y_{k+1} + (t_k - 1) / t_{k+1} (y_{k+1} - y_k).
    /// The vector passes run over fixed chunks, as the check (the same bits on any number of
    /// threads); the next sweep's start (next = z) is written with z.
    void ApgsRun::sweeps_with_momentum(Eigen::VectorXd &y, Eigen::VectorXd &y_last, Eigen::VectorXd &z,
                                       Eigen::VectorXd &next, double &t)
    {
      struct Sum
      {
        double value = 0;
        void   merge(const Sum &p) { value += p.value; }
      };
      next = z;
      for (unsigned int k = 0; k < ApgsSolver::check_interval; ++k)
        {
          sweep(next);
          const double opposed = over_chunks<Sum>(rows, prm.threads, [&](Eigen::Index first, Eigen::Index last) {
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
          over_chunks<NoSums>(rows, prm.threads, [&](Eigen::Index first, Eigen::Index last) {
            for (Eigen::Index j = first; j < last; ++j)
              next[j] = z[j] = y[j] + beta * (y[j] - y_last[j]);
            return NoSums{};
          });
          t = t_next;
        }
    }

    Eigen::VectorXd ApgsRun::solve()
    {
      Eigen::VectorXd y = w == 1 ? Eigen::VectorXd(scaled.y.cwiseMax(0.0)) : scaled.y, y_last(rows), z = y,
                      next(rows);
      double t = 1;
      // Polishes since the last block of sweeps, and since the lowest map among them.
      unsigned int polished = 0, since_lowest = 0;
      double       lowest   = INFINITY;
      double       map      = relative_map(y);
      // With friction (width 2) the sweep is no gradient step of a potential (the law is not
      // associated) and the momentum has no guarantee: the safeguard keeps the best iterate
      // of the whole checks, drops the momentum when a block raises the map, and returns the
      // best iterate if the solve ends above it.
      Eigen::VectorXd best     = w == 2 ? y : Eigen::VectorXd();
      double          best_map = map, block_map = map;
      while (map > prm.residual_target || gaps_open())
        {
          if (report.iterations >= prm.max_iterations)
            {
              report.converged = false;
              break;
            }
          if (polished < ApgsSolver::max_polishes && since_lowest < ApgsSolver::polish_patience && polish(y, z))
            {
              ++polished;
              map          = recheck(y);
              since_lowest = map < lowest ? 0 : since_lowest + 1;
              lowest       = std::min(lowest, map);
              continue;
            }
          polished = since_lowest = 0;
          lowest                  = INFINITY;
          sweeps_with_momentum(y, y_last, z, next, t);
          map = relative_map(y);
          if (w == 2)
            {
              if (map < best_map)
                {
                  best     = y;
                  best_map = map;
                }
              else if (map > block_map)
                {
                  t = 1;
                  z = y;
                }
              block_map = map;
            }
        }
      if (w == 2 && best_map < map)
        y = best; // the safeguard's best iterate (its map is best_map)
      return y;
    }
  } // namespace

  SolveReport ApgsSolver::solve_problem(std::vector<Contact> &contacts, BodyState &state, const ContactLaw &law)
  {
    SolveReport        report;
    const SweepProblem problem(contacts, state, law, prm.threads);
    const Eigen::VectorXd y = ApgsRun(problem, law, prm, step_theta_h, report).solve();
    problem.apply(y, contacts, state);
    return report;
  }
} // namespace tribo::dem
