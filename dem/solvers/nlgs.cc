#include "dem/solvers/nlgs.h"

#include "core/parameter_file.h"
#include "core/serialization.h"

#include <deal.II/base/parallel.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>

namespace tribo::dem
{
  NlgsSolver::NlgsSolver(const SolverParameters &p)
    : ContactSolver(p)
    , rng(p.seed)
  {}

  std::string NlgsSolver::random_state() const { return engine_state(rng); }

  void NlgsSolver::set_random_state(const std::string &state) { set_engine_state(rng, state); }

  void NlgsSolver::declare(dealii::ParameterHandler &prm)
  {
    using dealii::Patterns::Double;
    using dealii::Patterns::Integer;
    using dealii::Patterns::Selection;
    prm.declare_entry("Tolerance", "1e-4", Double(), "NLGS tolerance, > 0 (relative, see Norm).");
    prm.declare_entry("Norm", "Quad", Selection("Quad|Maxm"),
                      "Convergence norm of the established NSCD code: 'Quad' (mean-square) or "
                      "'Maxm' (maximum over contacts).");
    prm.declare_entry("Relaxation", "1", Double(), "Relaxation omega in (0, 1]: r = omega r_law + (1 - omega) r_old.");
    prm.declare_entry("Check interval", "10", Integer(1), "Sweeps between convergence checks, >= 1.");
    prm.declare_entry("Contact order", "fixed", Selection("fixed|alternating|random"),
                      "Order of the local solves: 'fixed' (detection order: cells by rows, bottom to "
                      "top), 'alternating' (that order and its reverse in turn, a symmetric Gauss-Seidel) "
                      "or 'random' (shuffled every sweep).");
    prm.declare_entry("Seed", "1", Integer(0), "Seed of the random contact order.");
    prm.declare_entry("Streams", "1", Integer(1),
                      "With Contact order = fixed: windows of 64 x Streams consecutive contacts, "
                      "each cut into this many streams solved one contact from each in turn, >= 1 "
                      "(1: the detection order itself). Contacts 64 apart rarely share a body, so "
                      "the processor overlaps their updates: 4 streams do 1.2-1.5 times more contact "
                      "updates per second for about 3 % more sweeps, and change the trajectory "
                      "(docs/performance.md).");
    prm.declare_entry("Gap tolerance", "0", Double(),
                      "NLGS and APGS: extra IQS convergence criterion, as a fraction of the smallest radius "
                      "(>= 0): every contact's gap violation theta h max(0, -(u_n + shift)) must be below it. "
                      "Limits the overlaps that a loose solve lets accumulate under high pressure, at the price "
                      "of more sweeps. 0: NLGS's norms alone; APGS then solves to Solver/Gap target, which a "
                      "converged step must meet anyway.");
  }

  void NlgsSolver::parse(const ParameterFile &f, SolverParameters &p)
  {
    const auto entry = [&](const std::string &name) { return p.section.entry(name); };
    p.tolerance      = f.get_checked(entry("Tolerance"), is_positive, "a positive tolerance");
    p.norm           = f.get(entry("Norm")) == "Quad" ? SolverParameters::Norm::quad : SolverParameters::Norm::maxm;
    p.relaxation     = f.get_checked(entry("Relaxation"), [](double v) { return v > 0 && v <= 1; },
                                     "a relaxation in (0, 1]");
    p.check_interval = f.get_integer(entry("Check interval"));
    const std::string order = f.get(entry("Contact order"));
    p.order   = order == "random"        ? SolverParameters::Order::random
                : order == "alternating" ? SolverParameters::Order::alternating
                                         : SolverParameters::Order::fixed;
    p.seed    = f.get_integer(entry("Seed"));
    p.streams = f.get_integer(entry("Streams"));
    if (p.threads > 1 && p.order != SolverParameters::Order::fixed)
      f.fail(entry("Threads"), "1 with " + entry("Contact order") + " = " + order +
                                 " (bands solved at once need the fixed order)");
    p.relative_gap_tolerance =
      f.get_checked(entry("Gap tolerance"), is_non_negative, "a fraction >= 0 of the smallest radius");
    if (p.method != SolverParameters::Method::nlgs)
      for (const char *name : {"Tolerance", "Norm", "Check interval", "Gap tolerance"})
        if (!f.is_default(entry(name)) &&
            !(p.method == SolverParameters::Method::apgs && std::string(name) == "Gap tolerance"))
          p.unused_nlgs_entries += std::string(p.unused_nlgs_entries.empty() ? "" : ", ") + entry(name) +
                                   " (" + f.where(entry(name)) + ")";
  }

  void NlgsCheckSums::add(const Eigen::Matrix2d &W, const Eigen::Vector2d &r_old, const Eigen::Vector2d &r_new)
  {
    const Eigen::Vector2d r_bar = 0.5 * (r_old + r_new);
    if (r_bar.x() == 0 && r_bar.y() == 0)
      return;
    ++active;
    const Eigen::Vector2d dv     = W * (r_new - r_old);
    const Eigen::Vector2d wr_old = W * r_old, wr_new = W * r_new;
    const double          d2     = dv.squaredNorm();
    wrwr += 0.5 * (wr_old.squaredNorm() + wr_new.squaredNorm());
    wrr += 0.5 * (wr_old.dot(r_old) + wr_new.dot(r_new));
    dvdv += d2;
    dvdvrr += d2 * r_bar.squaredNorm();
    dvor += r_bar.dot(dv);
    max_dvdv   = std::max(max_dvdv, d2);
    max_dvdvrr = std::max(max_dvdvrr, d2 * r_bar.squaredNorm());
  }

  void NlgsCheckSums::merge(const NlgsCheckSums &o)
  {
    wrwr += o.wrwr;
    wrr += o.wrr;
    dvdv += o.dvdv;
    dvdvrr += o.dvdvrr;
    dvor += o.dvor;
    max_dvdv   = std::max(max_dvdv, o.max_dvdv);
    max_dvdvrr = std::max(max_dvdvrr, o.max_dvdvrr);
    active += o.active;
  }

  double NlgsCheckSums::criterion(SolverParameters::Norm norm, double tol) const
  {
    const double N         = active;
    const double quad_wr   = std::sqrt(wrwr / N);
    const double mean_wrr  = wrr / N;
    const double mean_dvor = wrr > 0 ? dvor / (wrr * tol) : 0;
    const bool   quad      = norm == SolverParameters::Norm::quad;
    const double dv_norm   = quad_wr > 0 ? std::sqrt(quad ? dvdv / N : max_dvdv) / (quad_wr * tol) : 0;
    const double dvr_norm  = mean_wrr > 0 ? std::sqrt(quad ? dvdvrr / N : max_dvdvrr) / (mean_wrr * tol) : 0;
    return std::max({std::abs(mean_dvor), dv_norm, dvr_norm});
  }

  double NlgsCheckSums::check(const Contact &c, const BodyState &state, const ContactLaw &law)
  {
    const Eigen::Vector2d   u_now = state.local_velocity(c);
    const ContactLaw::Terms terms{c.cohesion_impulse, c.shift, c.compliance};
    add(c.W, c.r, law.solve(c.W, u_now - c.W * c.r, terms));
    return -(u_now.x() + c.shift);
  }

  namespace
  {
    /// Whether the bands [begin[k], begin[k+1]) of each phase (k even, k odd) touch
    /// disjoint bodies, the boundary bodies' nodes counting as one more body (all of them:
    /// a body's compliance couples all its nodes).
    bool bands_independent(const std::vector<Contact> &contacts, const std::vector<unsigned int> &begin,
                           std::size_t n_bodies)
    {
      std::vector<int> owner(n_bodies + 1);
      for (unsigned int phase = 0; phase < 2; ++phase)
        {
          std::fill(owner.begin(), owner.end(), -1);
          for (unsigned int k = phase; k + 1 < begin.size(); k += 2)
            for (unsigned int i = begin[k]; i < begin[k + 1]; ++i)
              {
                const Contact &c     = contacts[i];
                const std::size_t ids[2] = {c.on_boundary() ? n_bodies : c.body[0], c.body[1]};
                for (const std::size_t b : ids)
                  {
                    if (owner[b] >= 0 && owner[b] != int(k))
                      return false;
                    owner[b] = int(k);
                  }
              }
        }
      return true;
    }
  } // namespace

  SolveReport NlgsSolver::solve(std::vector<Contact> &contacts, BodyState &state,
                               const ContactLaw &law, double theta_h)
  {
    SolveReport report;
    report.solved_by_nlgs = true;
    const std::size_t n = contacts.size();
    if (n == 0)
      return report;
    order.resize(n);
    std::iota(order.begin(), order.end(), 0u);

    const double tol   = prm.tolerance;
    const double omega = prm.relaxation;
    const bool   iqs   = law.type == ContactLaw::Type::iqs;
    report.converged   = false;

    // Bands: [begin[k], begin[k + 1]) in the order; one band for the serial sweep (and for
    // the orders that move contacts between bands: random, alternating).
    const bool         banded  = prm.threads > 1 && n >= 2 * prm.threads && prm.order == SolverParameters::Order::fixed;
    const unsigned int n_bands = banded ? 2 * prm.threads : 1;
    std::vector<unsigned int> begin(n_bands + 1);
    for (unsigned int k = 0; k <= n_bands; ++k)
      begin[k] = static_cast<unsigned int>(n * k / n_bands);
    report.concurrent = n_bands > 1 && bands_independent(contacts, begin, state.velocity.size());
    if (prm.order == SolverParameters::Order::fixed && prm.streams > 1)
      for (unsigned int k = 0; k < n_bands; ++k)
        {
          // Band k in windows of streams x spacing contacts; a window's contacts in
          // streams of `chunk` (spacing, or less in the band's last window), one from each
          // stream in turn.
          const unsigned int streams = prm.streams, window = streams * std::max(1U, prm.stream_spacing);
          unsigned int       i       = begin[k];
          for (unsigned int start = begin[k]; start < begin[k + 1]; start += window)
            {
              const unsigned int size  = std::min(window, begin[k + 1] - start);
              const unsigned int chunk = (size + streams - 1) / streams;
              for (unsigned int j = 0; j < chunk; ++j)
                for (unsigned int s = 0; s < streams; ++s)
                  if (s * chunk + j < size)
                    order[i++] = start + s * chunk + j;
            }
        }

    auto solve_band = [&](unsigned int k) {
      for (unsigned int i = begin[k]; i < begin[k + 1]; ++i)
        gauss_seidel_update(contacts[order[i]], state, law, omega);
    };
    // The check pass over band k: every contact's local solve against the state the
    // sweeps left, nothing applied (as the established code does: a sweep's own changes
    // would measure where the sweep went, not how far the state is from the solution).
    std::vector<NlgsCheckSums> band_sums(n_bands);
    std::vector<double>    band_violation(n_bands);
    auto check_band = [&](unsigned int k) {
      NlgsCheckSums sums;
      double        violation = 0;
      for (unsigned int i = begin[k]; i < begin[k + 1]; ++i)
        {
          const double closing = sums.check(contacts[order[i]], state, law);
          if (iqs)
            violation = std::max(violation, closing);
        }
      band_sums[k]      = sums;
      band_violation[k] = violation;
    };
    // Bands k = first, first + 2, ...: concurrently when they share no body.
    auto over_bands = [&](unsigned int first, unsigned int step, const auto &work) {
      const unsigned int count = (n_bands - first + step - 1) / step;
      if (report.concurrent && count > 1)
        dealii::parallel::apply_to_subranges(
          0u, count, [&](unsigned int b, unsigned int e) {
            for (unsigned int j = b; j < e; ++j)
              work(first + j * step);
          },
          1);
      else
        for (unsigned int j = 0; j < count; ++j)
          work(first + j * step);
    };

    for (unsigned int sweep = 1; sweep <= prm.max_iterations; ++sweep)
      {
        if (prm.order == SolverParameters::Order::random)
          std::shuffle(order.begin(), order.end(), rng);
        else if (prm.order == SolverParameters::Order::alternating && sweep > 1)
          std::reverse(order.begin(), order.end());
        if (n_bands == 1)
          solve_band(0);
        else
          {
            over_bands(0, 2, solve_band);
            over_bands(1, 2, solve_band);
          }
        report.iterations = sweep;
        if (sweep % prm.check_interval != 0 && sweep != prm.max_iterations)
          continue;
        ++report.check_passes;
        over_bands(0, 1, check_band);
        NlgsCheckSums sums;
        double        max_violation = 0;
        for (unsigned int k = 0; k < n_bands; ++k)
          {
            sums.merge(band_sums[k]);
            max_violation = std::max(max_violation, band_violation[k]);
          }
        report.gap_violation = theta_h * std::max(0.0, max_violation);
        const bool gaps_ok   = prm.gap_tolerance <= 0 || report.gap_violation <= prm.gap_tolerance;
        if (sums.active == 0)
          {
            report.converged = true;
            report.residual  = 0;
            break;
          }
        const double criterion = sums.criterion(prm.norm, tol);
        report.residual        = criterion * tol;
        if (criterion < 1 && gaps_ok)
          {
            report.converged = true;
            break;
          }
      }
    return report;
  }
} // namespace tribo::dem
