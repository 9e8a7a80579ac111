#include "dem/solvers/interior_point.h"

#include "dem/solvers/crossover.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace tribo::dem
{
  namespace
  {
    /// Gondzio's centrality correctors per iteration, at most (docs/performance.md: 2 cut
    /// the factorisations per step by 15 % on the 3800-grain benchmark).
    constexpr unsigned int centrality_correctors = 2;
    /// With walls as low-rank terms, a Newton direction gets Woodbury's step of iterative
    /// refinement only once the natural map is below this fraction of the mean impulse:
    /// farther out the direction needs no more digits than Woodbury keeps, and the
    /// refinement doubled the solves (docs/performance.md: 10 % of a step on the paper's
    /// sample, the same steps at the round-off floor).
    constexpr double refine_below = 1e-5;

    /// The crossover (dem/solvers/crossover.h): tried once the natural map is below this fraction
    /// of the mean impulse ...
    constexpr double crossover_below = 1e-4;
    /// ... and the closed set changed by at most this many contacts in the last iteration;
    constexpr unsigned int crossover_set_changes = 3;
    /// at most this many attempts per solve, each one factorisation.
    constexpr unsigned int crossover_attempts = 3;

    /// The largest alpha in (0, 1] with v + alpha dv >= 0, times @p fraction when limited.
    double step_to_boundary(const Eigen::VectorXd &v, const Eigen::VectorXd &dv, double fraction)
    {
      double alpha = 1;
      for (Eigen::Index i = 0; i < v.size(); ++i)
        if (dv[i] < 0)
          alpha = std::min(alpha, -fraction * v[i] / dv[i]);
      return alpha;
    }
  } // namespace

  namespace
  {
    /// One interior-point solve (the method is in dem/solvers/interior_point.h): the scaled
    /// problem, the iterate (y, s, g = A'y + b'), the factorised Newton matrix K, and the
    /// steps: the natural map, the crossover, one predictor-corrector iteration.
    class InteriorPointRun
    {
    public:
      InteriorPointRun(std::vector<Contact> &contacts, BodyState &state, const SolverParameters &prm,
                       SolveReport &report);
      /// Iterate to the target (or a stop), then apply the best iterate to the contacts and
      /// @p state.
      void solve(std::vector<Contact> &contacts, BodyState &state);

    private:
      const SolverParameters     &prm;
      SolveReport                &report;
      const FrictionlessProblem   lcp;
      const Eigen::Index          n;
      FrictionlessProblem::Scaled scaled; ///< the scaled problem (dem/solvers/mprgp.h)
      Eigen::VectorXd            &y;      ///< the iterate's impulses, scaled
      /// The warm start's mean loaded impulse (N s/m; 0 without one), for the crossover.
      const double                warm_mean;
      Eigen::VectorXd             g, s;
      ShiftedFactorisation        K;
      Eigen::VectorXd             r, rhs, dy, ds, dy_a, ds_a, dy_c, ds_c;
      Eigen::VectorXd             barrier;           ///< s / y + shift, K's diagonal beyond A'
      bool                        refine_now = true; ///< below refine_below of the mean impulse (walls only)
      double                      worst = 0;         ///< the iterate's natural map, N s/m
      std::vector<char>           closed;            ///< the closed set at the last crossover check
      unsigned int                attempts = 0;      ///< crossovers tried
      double                      last_worst = std::numeric_limits<double>::infinity();
      unsigned int                stalled    = 0;    ///< iterations in a row at the round-off floor
      /// The best iterate (smallest natural map) is the one applied: a diverging iteration
      /// cannot hand the bodies a worse solution than it had.
      double                      best_worst = 0;
      Eigen::VectorXd             best_y, best_g;

      /// The operator A' + U U^T (the walls as low-rank columns, dem/linalg/delassus.h).
      Eigen::VectorXd product(const Eigen::VectorXd &v) const { return scaled.product(v); }
      Eigen::VectorXd newton_solve(const Eigen::VectorXd &v) { return K.solve(v, refine_now); }
      double          natural_map() const;
      double          mean_loaded() const;
      bool            factorise();
      bool            crossover();
      bool            iterate();
    };

    /// The scale of y: the warm start's loaded impulses, or the free velocities' (A'y = -b' at
    /// a solution with unit diagonal), whichever is larger: a warm start of tiny impulses
    /// must not shrink the start (nor the target) step after step.
    double start_scale(const FrictionlessProblem &lcp, const FrictionlessProblem::Scaled &scaled)
    {
      return 1e-2 * std::max({(scaled.y.array() > 0).any() ? lcp.mean_loaded(scaled.y) : 0.0,
                              scaled.b.cwiseAbs().mean(), 1e-300});
    }

    /// With two threads, K in two halves split along an edge cut of the grains (on one core
    /// the split costs more than it saves: K whole, ordered by a dissection of the grains).
    ShiftedFactorisation newton_matrix(const FrictionlessProblem::Scaled &scaled, const std::vector<Contact> &contacts,
                                       const BodyState &state, const SolverParameters &prm, Eigen::Index n)
    {
      const bool halves = prm.threads > 1 && n >= BisectedCholesky::min_rows;
      return ShiftedFactorisation(scaled, halves ? grain_bisection(contacts, state) : std::vector<int>{},
                                  halves ? std::vector<int>{} : grain_dissection(contacts, state));
    }

    InteriorPointRun::InteriorPointRun(std::vector<Contact> &contacts, BodyState &state, const SolverParameters &prm,
                                       SolveReport &report)
      : prm(prm)
      , report(report)
      , lcp(contacts, state, true, prm.threads)
      , n(lcp.size())
      , scaled(lcp.scaled())
      , y(scaled.y)
      , warm_mean((lcp.x.array() > 0).any() ? lcp.mean_loaded(lcp.x) : 0.0)
      , K(newton_matrix(scaled, contacts, state, prm, n))
      , r(n), rhs(n), dy(n), ds(n), dy_a(n), ds_a(n), dy_c(n), ds_c(n), barrier(n)
      , closed(n, 0)
    {
      const double nu = start_scale(lcp, scaled);
      y               = y.cwiseMax(nu);
      g               = product(y) + scaled.b;
      s               = g.cwiseMax(nu);
      worst           = natural_map();
      best_worst      = worst;
      best_y          = y;
      best_g          = g;
    }

    /// The natural map in x units: max |min(y_i, g_i)| / sqrt(D_i), y projected on y >= 0.
    double InteriorPointRun::natural_map() const
    {
      double worst_map = 0;
      for (Eigen::Index i = 0; i < n; ++i)
        worst_map = std::max(worst_map, std::abs(std::min(y[i], g[i])) * scaled.inv_root[i]);
      return worst_map;
    }

    /// The iterate's mean loaded impulse: y is interior, so the contacts whose impulse
    /// exceeds their velocity (y_i > g_i in the scaled units; the others head for zero).
    double InteriorPointRun::mean_loaded() const
    {
      double sum = 0, count = 0;
      for (Eigen::Index i = 0; i < n; ++i)
        if (y[i] > g[i])
          {
            sum += y[i] * scaled.inv_root[i];
            ++count;
          }
      return count > 0 ? sum / count : lcp.scale;
    }

    bool InteriorPointRun::factorise()
    {
      const bool done       = K.factorise(barrier);
      report.factorizations = K.factorizations;
      return done;
    }

    /// The crossover (dem/solvers/crossover.h) once the natural map is below crossover_below of
    /// the mean impulse and the closed set has settled; true when it closed the solve.
    bool InteriorPointRun::crossover()
    {
    if (worst <= crossover_below * mean_loaded() && attempts < crossover_attempts && warm_mean > 0)
      {
        unsigned int changed = 0;
        for (Eigen::Index j = 0; j < n; ++j)
          {
            const char now = y[j] > g[j];
            changed += now != closed[j];
            closed[j] = now;
          }
        if (changed <= crossover_set_changes)
          {
            ++attempts;
            const double map = least_norm_crossover(
              scaled, K, closed, {prm.residual_target, mean_loaded(), warm_mean}, y, g);
            report.factorizations = K.factorizations;
            if (map >= 0)
              {
                worst      = map;
                best_worst = worst;
                best_y     = y;
                best_g     = g;
                return true;
              }
          }
      }
      return false;
    }

    /// One predictor-corrector iteration (with Gondzio's correctors) from the iterate; false
    /// when the solve stops here: at the round-off floor (below 1e-6 of the mean impulse, two
    /// iterations in a row that do not halve the natural map), out of factorisations, K not
    /// factorisable, or a non-finite map (each reported not converged).
    bool InteriorPointRun::iterate()
    {
      stalled    = worst <= 1e-6 * mean_loaded() && worst > 0.5 * last_worst ? stalled + 1 : 0;
      last_worst = worst;
      if (report.factorizations >= prm.max_factorizations || stalled >= 2)
        {
          report.converged = false;
          return false;
        }
      refine_now      = worst < refine_below * mean_loaded();
      r               = g - s;
      const double mu = y.dot(s) / n;
      // K is positive definite, but with A' singular (redundant contacts) and s_i / y_i
      // spanning many decades near the solution it can fail numerically: then the
      // Newton step of K + 1e-10 I, and if that fails too, the solve stops here.
      bool factorised = false;
      for (const double shift : {0.0, 1e-10})
        {
          for (Eigen::Index j = 0; j < n; ++j)
            barrier[j] = s[j] / y[j] + shift;
          if ((factorised = factorise()))
            break;
        }
      if (!factorised)
        {
          report.converged = false;
          return false;
        }
      // Predictor (affine scaling).
      rhs  = -r - s;
      dy_a = newton_solve(rhs);
      ds_a = product(dy_a) + r;
      const double alpha_a = std::min(step_to_boundary(y, dy_a, 1.0), step_to_boundary(s, ds_a, 1.0));
      const double mu_a    = (y + alpha_a * dy_a).dot(s + alpha_a * ds_a) / n;
      const double sigma   = std::pow(std::max(0.0, mu_a) / mu, 3);
      // Corrector.
      for (Eigen::Index j = 0; j < n; ++j)
        rhs[j] = -r[j] - s[j] + (sigma * mu - dy_a[j] * ds_a[j]) / y[j];
      dy = newton_solve(rhs);
      ds = product(dy) + r;
      double alpha = std::min(step_to_boundary(y, dy, 0.995), step_to_boundary(s, ds, 0.995));
      // Gondzio's centrality correctors: at a longer trial step alpha~, the products
      // (y_i + alpha~ dy_i)(s_i + alpha~ ds_i) outside [0.1, 10] sigma mu are pulled back
      // into it, K dc = t / y (t the pull, at most 10 sigma mu downwards), one more solve
      // with the same factorisation; the corrected direction dy + dc is kept while it
      // lengthens the step by a tenth of what was asked. Only while the natural map is above
      // 1e-3 of the mean impulse: closer in, they left a cohesive cluster's solve at a
      // higher round-off floor (unit test).
      for (unsigned int k = 0; k < centrality_correctors && alpha < 0.99 && worst > 1e-3 * mean_loaded(); ++k)
        {
          const double trial     = std::min(1.0, 1.5 * alpha + 0.1);
          const double target_mu = std::max(sigma * mu, std::numeric_limits<double>::min());
          for (Eigen::Index j = 0; j < n; ++j)
            {
              const double trial_product = (y[j] + trial * dy[j]) * (s[j] + trial * ds[j]);
              double       pull          = 0;
              if (trial_product < 0.1 * target_mu)
                pull = 0.1 * target_mu - trial_product;
              else if (trial_product > 10 * target_mu)
                pull = std::max(10 * target_mu - trial_product, -10 * target_mu);
              rhs[j] = pull / y[j];
            }
          dy_c = dy + newton_solve(rhs);
          ds_c = product(dy_c) + r;
          const double alpha_c =
            std::min(step_to_boundary(y, dy_c, 0.995), step_to_boundary(s, ds_c, 0.995));
          if (alpha_c < alpha + 0.1 * (trial - alpha))
            break;
          dy.swap(dy_c);
          ds.swap(ds_c);
          alpha = alpha_c;
        }
      y += alpha * dy;
      s += alpha * ds;
      g     = product(y) + scaled.b;
      worst = natural_map();
      if (!std::isfinite(worst))
        {
          report.converged = false;
          return false;
        }
      if (worst < best_worst)
        {
          best_worst = worst;
          best_y     = y;
          best_g     = g;
        }
      return true;
    }

    void InteriorPointRun::solve(std::vector<Contact> &contacts, BodyState &state)
    {
      while (worst > prm.residual_target * mean_loaded())
        if (crossover() || !iterate())
          break;
      // Contacts whose velocity exceeds their impulse are open: their interior impulse
      // (about mu / s) goes to zero rather than into the next step's warm start.
      for (Eigen::Index i = 0; i < n; ++i)
        best_y[i] = best_y[i] > best_g[i] ? best_y[i] * scaled.inv_root[i] : 0.0;
      lcp.apply(best_y, contacts, state);
    }
  } // namespace

  SolveReport InteriorPointSolver::solve_problem(std::vector<Contact> &contacts, BodyState &state, const ContactLaw &)
  {
    SolveReport report;
    InteriorPointRun(contacts, state, prm, report).solve(contacts, state);
    return report;
  }
} // namespace tribo::dem
