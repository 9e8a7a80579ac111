#include "dem/engine/moreau_jean.h"

#include "core/errors.h"
#include "dem/laws/law_residual.h"

#include <boost/archive/binary_iarchive.hpp>
#include <boost/archive/binary_oarchive.hpp>
#include <boost/serialization/string.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <sstream>

namespace tribo::dem
{
  MoreauJean::MoreauJean(double theta, const ContactLaw &law, const SolverParameters &solver,
                         double detection_distance)
    : th(theta)
    , contact_law(law)
    , solver(make_contact_solver(solver))
    // The detection distance always covers the cohesion range.
    , distance(std::max(detection_distance, law.cohesion_range))
  {}

  void MoreauJean::attach(BoundaryBody &body, double half_disc_diameter, const Vec2 &outward,
                          double period)
  {
    auto               half_discs = std::make_unique<HalfDiscs>(body, half_disc_diameter, outward, period);
    const unsigned int first_half_disc =
      attached.empty() ? 0 : attached.back().first_half_disc + attached.back().half_discs->count();
    attached.push_back({&body, std::move(half_discs), n_nodes, first_half_disc});
    n_nodes += body.n_nodes();
    state.node_blocks.push_back({attached.back().first_node, nullptr});
  }

  namespace
  {
    /// A step too long for its motion (MoreauJean::allow_retakes()): check_overlaps()'s stop
    /// when the step's motion made the overlap, or check_foresight()'s; the mover's larger
    /// speed (m/s) and a short account for the log of a step taken again.
    class StepTooLong : public RunError
    {
    public:
      StepTooLong(const std::string &message, double fastest, std::string why)
        : RunError(message)
        , speed(fastest)
        , reason(std::move(why))
      {}
      double      speed;
      std::string reason;
    };

    /// Seconds since @p start.
    double seconds_since(const std::chrono::steady_clock::time_point &start)
    {
      return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
  } // namespace

  void MoreauJean::assess_solve(double h, SolveReport &report) const
  {
    LawResidual accuracy;
    if (report.law_assessed)
      {
        accuracy.relative      = report.law_residual;
        accuracy.gap_violation = report.gap_violation;
      }
    else
      accuracy = law_residual(current, state, contact_law, th * h);
    const SolverParameters &controls = solver->parameters();
    // A global method's step is converged only if the law residual it is reported with is
    // within the method's target, up to the round-off of recomputing it from the bodies'
    // velocities (1e-9: what converged solves to 1e-11 read in the unit tests): its own test
    // may stop on another scale (the scaled problem's, or the ranks' check of their shares)
    // when almost nothing stays loaded.
    if (!report.solved_by_nlgs && accuracy.relative > controls.residual_target + 1e-9)
      report.converged = false;
    if (controls.gap_target > 0 && accuracy.gap_violation > controls.gap_target)
      {
        // Closing velocities that the relative law residual, over an inflated mean impulse,
        // does not see: not converged, whatever the method's own test said.
        report.gap_exceeded = true;
        report.converged    = false;
      }
    report.law_residual  = accuracy.relative;
    report.gap_violation = accuracy.gap_violation;
    if (!report.solved_by_nlgs)
      report.residual = accuracy.relative;
  }

  unsigned int MoreauJean::substeps_needed(const ParticleSystem &system, double h) const
  {
    if (most_substeps <= 1 || !attached.empty() || system.discs.empty())
      return 1;
    double fastest = 0;
    for (std::size_t b = 0; b < system.bodies.size(); ++b)
      if (advances(b))
        fastest = std::max(fastest, system.bodies[b].velocity.norm());
    if (split_state())
      {
        double least[1] = {-fastest};
        split->min(least, 1);
        fastest = -least[0];
      }
    const double quarter = 0.25 * system.min_radius();
    return static_cast<unsigned int>(std::clamp(std::ceil(h * fastest / quarter), 1.0, double(most_substeps)));
  }

  StepReport MoreauJean::step(ParticleSystem &system, double h)
  {
    const unsigned int k = substeps_needed(system, h);
    if (most_retake_substeps <= 1 || !attached.empty() || system.discs.empty())
      return in_substeps(system, h, k);
    // Keep what a retake needs: the bodies' state (a few doubles each) and, when the step is
    // taken in sub-steps (each of which replaces it), the warm start; a single step replaces
    // the warm start only once it has passed its checks.
    const auto step_start = std::chrono::steady_clock::now();
    at_start.resize(system.bodies.size());
    for (std::size_t b = 0; b < system.bodies.size(); ++b)
      {
        const RigidBody &body = system.bodies[b];
        at_start[b]           = {body.position, body.velocity, body.angle, body.spin};
      }
    std::optional<WarmStart> impulse_at_start;
    if (k > 1)
      impulse_at_start = previous_impulse;
    if (split)
      split->keep();
    // Each attempt that a StepTooLong stops is followed by one in more sub-steps, from the
    // step's start, until one passes or the most sub-steps allowed have failed.
    for (unsigned int substeps = k;;)
      try
        {
          attempt_substeps  = substeps;
          StepReport report = in_substeps(system, h, substeps);
          attempt_substeps  = 0;
          if (substeps != k)
            {
              report.retaken   = true;
              report.time_step = seconds_since(step_start);
            }
          return report;
        }
      catch (const StepTooLong &fault)
        {
          attempt_substeps          = 0;
          const unsigned int needed = std::min<double>(
            most_retake_substeps, std::max(std::ceil(h * fault.speed / (0.25 * system.min_radius())), 2.0 * substeps));
          if (needed <= substeps) // only an overlap stops here (check_foresight() asks for more sub-steps)
            throw RunError(std::string(fault.what()) +
                           (substeps == k ? "; taking the step again would need more than " + retake_entry + " = " +
                                              std::to_string(most_retake_substeps) + " sub-steps"
                                          : "; this was the step taken again in " + std::to_string(substeps) +
                                              " sub-steps, the most " + retake_entry + " allows"));
          for (std::size_t b = 0; b < system.bodies.size(); ++b)
            {
              RigidBody &body = system.bodies[b];
              body.position   = at_start[b].position;
              body.velocity   = at_start[b].velocity;
              body.angle      = at_start[b].angle;
              body.spin       = at_start[b].spin;
            }
          if (split)
            split->go_back();
          // A single step that failed left the warm start as it was; sub-steps replaced it.
          if (!impulse_at_start)
            impulse_at_start = previous_impulse;
          else
            previous_impulse = *impulse_at_start;
          if (substeps == k)
            last_retake_reason = fault.reason;
          substeps = needed;
        }
  }

  void MoreauJean::check_foresight(const ParticleSystem &system, double h) const
  {
    // Detection found the pairs within the detection distance at the predicted configuration
    // and those that each disc's motion estimate (disc_motion) closes; a disc that ends the
    // step farther from the segment [0, estimate] than a quarter of the smallest radius plus
    // that distance may have closed a pair it did not see by more than a quarter radius.
    const double r_min = system.min_radius(), limit = 0.25 * r_min + distance;
    double       worst = limit;
    long         culprit = -1;
    for (std::size_t d = 0; d < system.discs.size(); ++d)
      {
        // x_end - x_pred of the disc's centre (its body's, and the offset's turn for a clump's disc).
        const Disc &disc  = system.discs[d];
        if (!advances(disc.body))
          continue;
        Vec2        moved = system.bodies[disc.body].position - x_pred[disc.body];
        if (disc.offset.x() != 0 || disc.offset.y() != 0)
          moved += rotate(disc.offset, system.bodies[disc.body].angle) - rotate(disc.offset, angle_pred[disc.body]);
        if (system.period > 0 && std::abs(moved.x()) > 0.5 * system.period) // wrapped in the step
          moved.x() -= system.period * std::round(moved.x() / system.period);
        if (moved.squaredNorm() <= worst * worst)
          continue; // within the limit whatever was foreseen
        const Vec2  &foreseen = disc_motion[d];
        const double along    = foreseen.squaredNorm() > 0 ? std::clamp(moved.dot(foreseen) / foreseen.squaredNorm(), 0.0, 1.0) : 0.0;
        if (const double unforeseen = (moved - along * foreseen).norm(); unforeseen > worst)
          worst = unforeseen, culprit = disc.body;
      }
    double speed = culprit < 0 ? 0.0 : std::max(system.bodies[culprit].velocity.norm(), v_begin[culprit].head<2>().norm());
    double worst_disc[3] = {double(culprit), speed, worst};
    take_largest(worst, worst_disc, 3);
    culprit = long(worst_disc[0]);
    speed   = worst_disc[1];
    worst   = worst_disc[2];
    if (culprit < 0)
      return;
    if (std::min<double>(most_retake_substeps, std::ceil(h * attempt_substeps * speed / (0.25 * r_min))) <= attempt_substeps)
      return;
    std::ostringstream why;
    why << "body " << culprit << " moved " << worst / r_min << " r_min farther than its contact detection foresaw ("
        << speed << " m/s)";
    throw StepTooLong(why.str(), speed, why.str());
  }

  StepReport MoreauJean::in_substeps(ParticleSystem &system, double h, unsigned int k)
  {
    if (k == 1)
      return single_step(system, h);
    const auto                   step_start = std::chrono::steady_clock::now();
    StepReport                   total;
    std::vector<Eigen::Vector3d> force_sum;
    std::vector<double>          power_sum;
    for (unsigned int i = 0; i < k; ++i)
      {
        const StepReport r = single_step(system, h / k);
        if (i == 0)
          {
            total = r;
            force_sum.assign(body_force.size(), Eigen::Vector3d::Zero());
            power_sum.assign(body_power.size(), 0.0);
          }
        else
          {
            SolveReport &s = total.solver;
            s.iterations += r.solver.iterations;
            s.factorizations += r.solver.factorizations;
            s.check_passes += r.solver.check_passes;
            s.time_exchange += r.solver.time_exchange;
            s.converged      = s.converged && r.solver.converged;
            s.fell_back      = s.fell_back || r.solver.fell_back;
            s.solved_by_nlgs = s.solved_by_nlgs || r.solver.solved_by_nlgs;
            s.gap_exceeded   = s.gap_exceeded || r.solver.gap_exceeded;
            s.concurrent     = s.concurrent && r.solver.concurrent;
            s.law_residual   = std::max(s.law_residual, r.solver.law_residual);
            s.residual       = std::max(s.residual, r.solver.residual);
            s.gap_violation  = std::max(s.gap_violation, r.solver.gap_violation);
            total.max_overlap = std::max(total.max_overlap, r.max_overlap);
            total.max_speed   = std::max(total.max_speed, r.max_speed);
            for (double StepReport::*sum : {&StepReport::power_external, &StepReport::power_free,
                                            &StepReport::power_contacts, &StepReport::boundary_dissipation,
                                            &StepReport::time_detection, &StepReport::time_boundary_body,
                                            &StepReport::time_solver})
              total.*sum += r.*sum;
            total.n_contacts          = r.n_contacts;
            total.n_active            = r.n_active;
            total.epsilon             = r.epsilon;
            total.kinetic_energy      = r.kinetic_energy;
            total.boundary_energy     = r.boundary_energy;
            total.n_boundary_contacts = r.n_boundary_contacts;
          }
        for (std::size_t b = 0; b < body_force.size(); ++b)
          force_sum[b] += body_force[b] / k;
        for (std::size_t b = 0; b < body_power.size(); ++b)
          power_sum[b] += body_power[b] / k;
      }
    // Forces and powers over the step: the means over its sub-steps.
    for (double StepReport::*mean : {&StepReport::power_external, &StepReport::power_free,
                                     &StepReport::power_contacts, &StepReport::boundary_dissipation})
      total.*mean /= k;
    body_force.swap(force_sum);
    body_power.swap(power_sum);
    total.substeps  = k;
    total.time_step = seconds_since(step_start);
    return total;
  }

  StepReport MoreauJean::single_step(ParticleSystem &system, double h)
  {
    const auto step_start = std::chrono::steady_clock::now();
    last_step_length      = h;
    StepReport report;
    predict(system, h);
    detect(system, h, report);
    set_up_local_problems(system, h, report);

    auto phase         = std::chrono::steady_clock::now();
    report.solver      = solver->solve(current, state, contact_law, th * h);
    report.time_solver = seconds_since(phase);
    assess_solve(h, report.solver);

    sum_contact_forces(h);
    if (own_share)
      join_shares();
    report.max_speed             = update_bodies(system, h, report);
    const double deepest_overlap = measure_gaps(h, report);
    if (!attached.empty())
      update_boundary_bodies(h, report);
    compute_contact_powers(h);
    check_overlaps(system, h, report, deepest_overlap);
    if (attempt_substeps > 0)
      check_foresight(system, h);
    // The next step's warm start, once the step stands (a step taken again starts from the last).
    previous_impulse.assign(next_impulse);
    report.kinetic_energy = 0;
    if (!split_state())
      report.kinetic_energy = system.kinetic_energy();
    else
      {
        for (const unsigned int b : *split->held())
          if (split->counts(b))
            report.kinetic_energy += system.bodies[b].kinetic_energy();
        split->sum(&report.kinetic_energy, 1);
        split->settle(system);
      }
    report.time_step      = seconds_since(step_start);
    return report;
  }

  void MoreauJean::predict(const ParticleSystem &system, double h, bool every)
  {
    // Free velocities (imposed loads over the step) and the predicted configuration
    // x + (1 - theta) h v, where contacts are detected and their geometry taken.
    const std::size_t nb = system.bodies.size();
    state.velocity.resize(nb);
    state.inverse_mass.resize(nb);
    v_begin.resize(nb);
    v_free.resize(nb);
    x_pred.resize(nb);
    angle_pred.resize(nb);
    const std::vector<unsigned int> *held = split_state() && !every ? split->held() : nullptr;
    for (std::size_t i = 0, n = held ? held->size() : nb; i < n; ++i)
      {
        const std::size_t b    = held ? (*held)[i] : i;
        const RigidBody  &body = system.bodies[b];
        v_begin[b]            = {body.velocity.x(), body.velocity.y(), body.spin};
        state.inverse_mass[b] = body.inverse_mass();
        Eigen::Vector3d v     = v_begin[b];
        for (int k = 0; k < 3; ++k)
          if (body.drive[k] == Drive::force)
            v[k] += h * state.inverse_mass[b][k] * body.load[k];
        state.velocity[b] = v;
        v_free[b]         = v;
        x_pred[b]         = body.position + (1 - th) * h * body.velocity;
        angle_pred[b]     = body.angle + (1 - th) * h * body.spin;
      }

  }

  void MoreauJean::place_discs(const ParticleSystem &system, double h, bool every)
  {
    // With a split state, the discs of the bodies this process holds (the others' are stale).
    const bool some = split_state() && !every;
    centres.resize(system.discs.size());
    for (std::size_t d = 0; d < system.discs.size(); ++d)
      {
        const Disc &disc = system.discs[d];
        if (some && !split->holds(disc.body))
          continue;
        centres[d] = system.wrap(x_pred[disc.body] + rotate(disc.offset, angle_pred[disc.body]));
      }
    // Each disc's motion until the next detection, estimated as lookahead steps at its
    // velocity at the start of the step (the centre velocity of its body, v + omega x
    // offset), plus one step of what its imposed load adds to it, h (v_free - v_begin) =
    // h^2 M^-1 F_ext. Not lookahead steps of the free velocity: a body pressed on its
    // neighbours by a load has its free velocity cancelled by its contacts every step, while
    // a fast grain keeps its velocity from one step to the next. The load's own step matters
    // for a wall released under its load (h^2 F / m = 3.4e-6 m in a first step of 2e-7 s at
    // 100 MPa), and is below 1e-9 m at the shear cells' step.
    disc_motion.resize(system.discs.size());
    for (std::size_t d = 0; d < system.discs.size(); ++d)
      {
        const Disc &disc = system.discs[d];
        if (some && !split->holds(disc.body))
          continue;
        const Eigen::Vector3d  v      = v_begin[disc.body] + (v_free[disc.body] - v_begin[disc.body]) / lookahead;
        const Vec2             offset = rotate(disc.offset, angle_pred[disc.body]);
        disc_motion[d] = lookahead * h * Vec2(v.x() - v.z() * offset.y(), v.y() + v.z() * offset.x());
      }
  }

  void MoreauJean::detect(ParticleSystem &system, double h, StepReport &report)
  {
    // Disc pairs at the predicted configuration.
    place_discs(system, h);
    auto                 phase = std::chrono::steady_clock::now();
    const unsigned int   threads = solver->parameters().threads;
    if (!split)
      detector.detect(system, centres, distance, threads, disc_motion, found);
    else
      {
        // This process's rows; every pair when the split asks (no share yet, or its bands
        // must be cut again), and then every process's warm start, whose owners may change.
        const auto own = split->own_band(system);
        detector.detect(system, centres, distance, threads, disc_motion, found, own);
        ContactSplit::Share share = split->divide(system, found, !own);
        const bool          all   = !own || share == ContactSplit::Share::search_all;
        if (share == ContactSplit::Share::search_all)
          {
            if (split->held())
              {
                // Every pair at the predicted configuration of the whole state.
                split->make_whole(system);
                predict(system, h, true);
                place_discs(system, h, true);
              }
            detector.detect(system, centres, distance, threads, disc_motion, found);
            share = split->divide(system, found, true);
          }
        if (all)
          gather_warm_start();
        own_share = share == ContactSplit::Share::own;
      }
    report.time_detection      = seconds_since(phase);

    // The boundary bodies: free states, predicted nodes, half-disc contacts, each body's
    // nodes and half-discs numbered after the previous bodies'.
    node_v_begin.resize(n_nodes);
    state.node_velocity.resize(2 * n_nodes);
    for (std::size_t k = 0; k < attached.size(); ++k)
      {
        BoundaryBody      &body = *attached[k].body;
        const unsigned int nn = body.n_nodes(), first = attached[k].first_node;
        phase                 = std::chrono::steady_clock::now();
        body.predict(h);
        report.time_boundary_body += seconds_since(phase);
        std::vector<Vec2> nodes(nn), node_motion(nn);
        for (unsigned int i = 0; i < nn; ++i)
          {
            const Vec2 v = body.node_velocity(i);
            node_v_begin[first + i] = v;
            nodes[i]                = body.node_position(i) + (1 - th) * h * v;
            node_motion[i]          = lookahead * h * v; // as the discs' motions
            state.node_velocity.segment<2>(2 * (first + i)) = body.node_free_velocity(i);
          }
        state.node_blocks[k].compliance = &body.compliance();
        phase            = std::chrono::steady_clock::now();
        auto on_boundary = attached[k].half_discs->detect(system, centres, angle_pred, nodes, distance, disc_motion,
                                                          node_motion);
        report.time_detection += seconds_since(phase);
        report.n_boundary_contacts += on_boundary.size();
        for (Contact &c : on_boundary)
          {
            c.boundary_body = k;
            c.half_disc += attached[k].first_half_disc;
            c.node[0] += first;
            c.node[1] += first;
          }
        // With a split state, the grains this process does not hold are stale: none of
        // their half-disc contacts is real.
        if (split_state())
          on_boundary.erase(std::remove_if(on_boundary.begin(), on_boundary.end(),
                                           [&](const Contact &c) { return !split->holds(c.body[1]); }),
                            on_boundary.end());
        if (!own_share || split->keeps_boundary_contacts())
          found.insert(found.end(), on_boundary.begin(), on_boundary.end());
      }
  }

  void MoreauJean::set_up_local_problems(const ParticleSystem &system, double h, StepReport &report)
  {
    // Geometry of H, the own Delassus blocks, law terms, free velocities, warm start;
    // the contacts to solve are compacted in place and become current (found takes the last
    // step's buffer: neither is copied nor allocated anew).
    std::size_t kept = 0;
    for (Contact &c : found)
      {
        const Vec2 t(-c.normal.y(), c.normal.x());
        if (!c.on_boundary())
        {
        // Contact point: middle of the gap (or overlap) on the line of centres;
        // arms from each body centre = the disc's offset + the point from the disc centre.
        const Vec2 point_from0 = (system.discs[c.disc[0]].radius + 0.5 * c.gap) * c.normal;
        const Vec2 arm0 = rotate(system.discs[c.disc[0]].offset, angle_pred[c.body[0]]) + point_from0;
        const Vec2 arm1 = rotate(system.discs[c.disc[1]].offset, angle_pred[c.body[1]]) +
                               point_from0 - c.branch;
        c.arm_n[0] = cross(arm0, c.normal);
        c.arm_t[0] = cross(arm0, t);
        c.arm_n[1] = cross(arm1, c.normal);
        c.arm_t[1] = cross(arm1, t);
        }
        c.W        = state.delassus_block(c);
        if (c.W(0, 0) <= 0)
          continue; // both bodies have imposed velocities: nothing to solve
        const auto terms   = contact_law.terms(c.gap, h, th);
        c.cohesion_impulse = terms.cohesion_impulse;
        c.shift            = terms.shift;
        c.compliance       = terms.compliance;
        c.u_free           = state.local_velocity(c);
        c.r                = previous_impulse.find(c.key());
        found[kept++]      = c;
      }
    found.resize(kept);
    current.swap(found);
    report.n_contacts = current.size();
    if (own_share)
      return; // the solver adds every process's warm start
    for (const Contact &c : current)
      if (c.r.x() != 0 || c.r.y() != 0)
        state.apply_impulse(c, c.r);

  }

  double MoreauJean::measure_gaps(double h, StepReport &report)
  {
    // Gap measures with the final velocities; the loaded contacts' impulses become the
    // next step's warm start.
    next_impulse.clear();
    double eps_sum = 0, min_gap_end = 0, min_gap_any = 0;
    for (const Contact &c : current)
      {
        if (c.r.x() == 0 && c.r.y() == 0)
          {
            min_gap_any = std::min(min_gap_any, c.gap + th * h * state.local_velocity(c).x());
            continue;
          }
        next_impulse.emplace_back(c.key(), c.r);
        ++report.n_active;
        const double un = state.local_velocity(c).x();
        eps_sum += th * h * (un - c.u_free.x());
        min_gap_end = std::min(min_gap_end, c.gap + th * h * un);
      }
    if (own_share)
      {
        double sums[3] = {double(report.n_active), eps_sum, double(current.size())};
        double least[2] = {min_gap_end, min_gap_any};
        split->sum(sums, 3);
        split->min(least, 2);
        report.n_active   = static_cast<decltype(report.n_active)>(sums[0]);
        eps_sum           = sums[1];
        report.n_contacts = static_cast<decltype(report.n_contacts)>(sums[2]);
        min_gap_end       = least[0];
        min_gap_any       = least[1];
      }
    report.epsilon     = report.n_active ? eps_sum / report.n_active : 0;
    report.max_overlap = std::max(0.0, -min_gap_end);
    const double deepest_overlap = std::max(report.max_overlap, -min_gap_any); // any contact

    return deepest_overlap;
  }

  void MoreauJean::sum_contact_forces(double h)
  {
    // Contact force on every body over the step.
    const std::size_t nb = state.velocity.size();
    body_force.assign(nb, Eigen::Vector3d::Zero());
    node_impulse.assign(n_nodes, Vec2::Zero());
    for (const Contact &c : current)
      {
        const Vec2 t(-c.normal.y(), c.normal.x());
        const Vec2 f = (c.r.x() * c.normal + c.r.y() * t) / h;
        if (c.on_boundary())
          for (int k = 0; k < 2; ++k)
            node_impulse[c.node[k]] -= h * (c.node_map[k].transpose() * f);
        for (int s = c.on_boundary() ? 1 : 0; s < 2; ++s)
          {
            const double sign = s == 0 ? -1.0 : 1.0;
            body_force[c.body[s]] +=
              sign * Eigen::Vector3d(f.x(), f.y(), (c.arm_n[s] * c.r.x() + c.arm_t[s] * c.r.y()) / h);
          }
      }

  }

  void MoreauJean::join_shares()
  {
    // Eigen's fixed vectors of 3 and 2 doubles lie side by side in a std::vector.
    if (split->held())
      split->sum_on_owners(body_force);
    else
      split->sum(body_force.front().data(), 3 * body_force.size());
    if (!node_impulse.empty())
      split->sum(node_impulse.front().data(), 2 * node_impulse.size());
  }

  void MoreauJean::sum_over_shares(std::vector<double> &values) const
  {
    if (own_share)
      split->sum(values.data(), values.size());
  }

  void MoreauJean::take_largest(double key, double *values, std::size_t n) const
  {
    if (!split_state())
      return;
    double least[1] = {-key};
    split->min(least, 1);
    std::vector<double> held(n, INFINITY);
    if (-key == least[0])
      std::copy(values, values + n, held.begin());
    split->min(held.data(), n);
    std::copy(held.begin(), held.end(), values);
  }

  void MoreauJean::gather_warm_start()
  {
    if (!own_share)
      return;
    std::vector<KeyedImpulse> mine;
    for (const auto &[key, r] : previous_impulse.sorted())
      mine.push_back({key, {r.x(), r.y()}});
    std::vector<WarmStart::Entry> every;
    for (const KeyedImpulse &k : split->all_gathered(mine))
      every.emplace_back(k.key, Eigen::Vector2d(k.r[0], k.r[1]));
    previous_impulse.assign(every);
  }

  double MoreauJean::update_bodies(ParticleSystem &system, double h, StepReport &report)
  {
    // End velocities and positions, external and contact powers.
    const std::size_t nb = system.bodies.size();
    body_power.assign(nb, 0.0);
    v_mid_of.resize(nb);
    double fastest = 0; // speed of the fastest body, m/s
    // The powers over the bodies this process counts: external, contacts, on the free bodies.
    double power[3] = {0, 0, 0};
    double diverged = INFINITY; // the least body with a non-finite velocity, with a split state
    // With a split state, the bodies held here (the others are not advanced here).
    const std::vector<unsigned int> *held = split_state() ? split->held() : nullptr;
    for (std::size_t i = 0, n = held ? held->size() : nb; i < n; ++i)
      {
        const std::size_t b = held ? (*held)[i] : i;
        if (!advances(b))
          continue;
        RigidBody &body = system.bodies[b];
        // v_end = v_free + M^-1 (total contact impulse), recomputed from the final
        // impulses rather than taken from the solver's running velocities (which
        // carry the round-off of every incremental update): the energy balance is
        // then exact to the last digits.
        Eigen::Vector3d v = v_free[b];
        for (int k = 0; k < 3; ++k)
          v[k] += h * state.inverse_mass[b][k] * body_force[b][k];
        if (!v.allFinite() && split_state())
          {
            diverged = std::min(diverged, double(b)); // every process stops below
            continue;
          }
        if (!v.allFinite())
          {
            std::ostringstream os;
            os << "body " << b << " has a non-finite velocity (" << v.transpose()
               << ") at position (" << body.position.transpose() << "): the solver diverged";
            throw RunError(os.str());
          }
        const Eigen::Vector3d v_mid = 0.5 * (v_begin[b] + v);
        v_mid_of[b]                 = v_mid;
        const bool counted          = counts(b);
        for (int k = 0; k < 3; ++k)
          {
            if (body.drive[k] == Drive::velocity)
              body_power[b] -= body_force[b][k] * v_mid[k];
            else if (body.drive[k] == Drive::force)
              body_power[b] += body.load[k] * v_mid[k];
            if (!counted)
              continue;
            power[1] += body_force[b][k] * v_mid[k];
            if (body.is_free())
              power[2] += (body_force[b][k] + (body.drive[k] == Drive::force ? body.load[k] : 0)) * v_mid[k];
          }
        if (counted)
          power[0] += body_power[b];
        fastest = std::max(fastest, v.head<2>().norm());
        if (own_share) // the solver left only this process's bodies current (measure_gaps)
          state.velocity[b] = v;
        body.velocity = v.head<2>();
        body.spin     = v.z();
        body.position = x_pred[b] + th * h * body.velocity;
        body.angle    = angle_pred[b] + th * h * body.spin;
        if (system.period > 0 && system.discs.size() > 0)
          {
            // Keep the body's reference point in [0, period); its discs follow.
            const double shift = system.period * std::floor(body.position.x() / system.period);
            body.position.x() -= shift;
          }
      }
    if (split_state())
      {
        split->min(&diverged, 1);
        if (std::isfinite(diverged))
          throw RunError("body " + std::to_string(long(diverged)) + " has a non-finite velocity: the solver diverged");
        split->sum(power, 3);
        double least[1] = {-fastest};
        split->min(least, 1);
        fastest = -least[0];
        // The ghosts' end states from their owners: their contacts' gaps, powers and checks.
        for (const unsigned int b : split->send_states(system))
          {
            const RigidBody      &body = system.bodies[b];
            const Eigen::Vector3d v(body.velocity.x(), body.velocity.y(), body.spin);
            state.velocity[b] = v;
            v_mid_of[b]       = 0.5 * (v_begin[b] + v);
          }
      }
    report.power_external += power[0];
    report.power_contacts += power[1];
    report.power_free += power[2];
    return fastest;
  }

  void MoreauJean::update_boundary_bodies(double h, StepReport &report)
  {
    // Each deformable body takes the contact impulses on its nodes; its end velocities
    // give the nodes' share of the contact power.
    if (!state.node_velocity.allFinite())
      throw RunError("a boundary body's nodes have non-finite velocities: the solver diverged");
    node_v_end.resize(n_nodes);
    for (const Attached &a : attached)
      {
        BoundaryBody      &body = *a.body;
        const unsigned int nn   = body.n_nodes();
        const auto         phase = std::chrono::steady_clock::now();
        body.finalize(std::vector<Vec2>(node_impulse.begin() + a.first_node, node_impulse.begin() + a.first_node + nn));
        report.time_boundary_body += seconds_since(phase);
        // With the body's own end velocities (not the solver's running copy, which
        // carries the round-off of many incremental updates), the balance is exact.
        for (unsigned int i = 0; i < nn; ++i)
          {
            const unsigned int node = a.first_node + i;
            node_v_end[node]        = body.node_velocity(i);
            report.power_contacts += node_impulse[node].dot(0.5 * (node_v_begin[node] + node_v_end[node])) / h;
          }
        report.power_contacts += body.impulse_extra_power();
        report.power_external += body.external_power();
        report.boundary_energy += body.energy();
        report.boundary_dissipation += body.internal_dissipation();
      }
  }

  void MoreauJean::compute_contact_powers(double h)
  {
    // Each contact's power at the mid-step velocities: r . (H_1^T v_1 - H_0^T v_0) / h,
    // side 0 of a half-disc contact moving as its material point J_A v_A + J_B v_B.
    power_of_contact.assign(current.size(), 0.0);
    for (std::size_t i = 0; i < current.size(); ++i)
      {
        const Contact  &c = current[i];
        const Vec2      t(-c.normal.y(), c.normal.x());
        Eigen::Vector2d u = Eigen::Vector2d::Zero();
        for (int side = 0; side < 2; ++side)
          {
            const double sign = side == 0 ? -1.0 : 1.0;
            if (side == 0 && c.on_boundary())
              {
                Vec2 v_point = Vec2::Zero();
                for (int k = 0; k < 2; ++k)
                  v_point += c.node_map[k] * (0.5 * (node_v_begin[c.node[k]] + node_v_end[c.node[k]]));
                u -= Eigen::Vector2d(c.normal.dot(v_point), t.dot(v_point));
                continue;
              }
            const Eigen::Vector3d &v = v_mid_of[c.body[side]];
            u += sign * Eigen::Vector2d(c.normal.dot(v.head<2>()) + c.arm_n[side] * v.z(),
                                        t.dot(v.head<2>()) + c.arm_t[side] * v.z());
          }
        power_of_contact[i] = c.r.dot(u) / h;
      }

  }

  MoreauJean::DeepestContact MoreauJean::deepest_contact(const ParticleSystem &system, double h) const
  {
    // A side's step velocity (vx, vy, spin), (1 - theta) v_begin + theta v_end; a half-disc
    // side moves as its material point, J_A v_A + J_B v_B (no spin).
    const auto side_velocity = [&](const Contact &c, int side) -> Eigen::Vector3d {
      if (side == 0 && c.on_boundary())
        {
          Vec2 v = Vec2::Zero();
          for (int k = 0; k < 2; ++k)
            v += c.node_map[k] * ((1 - th) * node_v_begin[c.node[k]] + th * node_v_end[c.node[k]]);
          return {v.x(), v.y(), 0};
        }
      const RigidBody &body = system.bodies[c.body[side]];
      return (1 - th) * v_begin[c.body[side]] + th * Eigen::Vector3d(body.velocity.x(), body.velocity.y(), body.spin);
    };
    DeepestContact deepest;
    double         least_gap = INFINITY;
    for (const Contact &c : current)
      if (const double end_gap = c.gap + th * h * state.local_velocity(c).x(); end_gap < least_gap)
        {
          // Each side moves h ((1 - theta) v_begin + theta v_end) in the step; along the normal
          // (side 1 relative to side 0, the arms turning the spins into the contact point's
          // motion) that is how far the step closed the contact.
          least_gap = end_gap;
          double rate = 0;
          deepest.moved = 0;
          for (int side = 0; side < 2; ++side)
            {
              const Eigen::Vector3d v = side_velocity(c, side);
              const bool            half_disc = side == 0 && c.on_boundary();
              rate += (side == 0 ? -1.0 : 1.0) * (c.normal.dot(v.head<2>()) + (half_disc ? 0.0 : c.arm_n[side] * v.z()));
              deepest.moved = std::max(deepest.moved, h * v.head<2>().norm());
            }
          deepest.overlap = -end_gap;
          deepest.closed  = std::max(0.0, -h * rate);
          deepest.bodies  = {{c.on_boundary() ? -1.0 : double(c.body[0]), double(c.body[1])}};
        }
    if (own_share)
      {
        // Another process may hold it: the values of the deepest over every process (each
        // contact is held once; a process whose deepest is shallower offers +inf).
        double least[1] = {least_gap};
        split->min(least, 1);
        double held[4] = {INFINITY, INFINITY, INFINITY, INFINITY};
        if (least_gap == least[0])
          held[0] = deepest.closed, held[1] = deepest.moved, held[2] = deepest.bodies[0], held[3] = deepest.bodies[1];
        split->min(held, 4);
        deepest = {-least[0], held[0], held[1], {{held[2], held[3]}}};
      }
    return deepest;
  }

  void MoreauJean::check_overlaps(const ParticleSystem &system, double h, const StepReport &report,
                                  double deepest_overlap) const
  {
    // Two discs overlapping by more than the smallest radius have passed through each
    // other: contacts were missed (something moved too far in one step for the detection
    // to see it coming), the solver left them unresolved, or an overlap grew over many steps.
    // Stop, naming the farthest mover when a body of the deepest contact moved more than a
    // quarter of the smallest radius in the step, else that contact's overlap at the start.
    const double r_min = system.discs.empty() ? 0 : system.min_radius();
    if (r_min > 0 && deepest_overlap > r_min)
      {
        const DeepestContact deepest = deepest_contact(system, h);
        // The farthest mover of the step: x_end - x_begin = h ((1 - theta) v_begin + theta v_end).
        double      farthest = 0, start_speed = 0, end_speed = 0;
        std::string mover;
        const auto  consider = [&](const Vec2 &v0, const Vec2 &v1, const std::string &name) {
          const double moved = h * ((1 - th) * v0 + th * v1).norm();
          if (moved > farthest)
            {
              farthest    = moved;
              start_speed = v0.norm();
              end_speed   = v1.norm();
              mover       = name;
            }
        };
        long farthest_body = -1;
        for (std::size_t b = 0; b < system.bodies.size(); ++b)
          if (advances(b))
            {
              const double before = farthest;
              consider(v_begin[b].head<2>(), system.bodies[b].velocity, "body " + std::to_string(b));
              if (farthest > before)
                farthest_body = long(b);
            }
        double mover_record[4] = {double(farthest_body), start_speed, end_speed, farthest};
        take_largest(farthest, mover_record, 4);
        if (split_state())
          {
            farthest_body = long(mover_record[0]);
            start_speed   = mover_record[1];
            end_speed     = mover_record[2];
            farthest      = mover_record[3];
            mover         = "body " + std::to_string(farthest_body);
          }
        for (std::size_t k = 0; k < node_v_end.size() && k < node_v_begin.size(); ++k)
          consider(node_v_begin[k], node_v_end[k], "a node of a deformable first body");
        const bool         by_nlgs = report.solver.solved_by_nlgs;
        std::ostringstream os;
        os << "an overlap of " << deepest_overlap << " m, more than the smallest disc radius ("
           << r_min << " m): contacts were missed or left unresolved ("
           << method_name(by_nlgs ? SolverParameters::Method::nlgs : solver->parameters().method) << " "
           << (report.solver.converged ? "converged" : "not converged") << "). ";
        if (deepest.moved > 0.25 * r_min)
          {
            const double fastest = std::max(start_speed, end_speed);
            os << "The farthest mover, " << mover << ", moved " << farthest << " m in the step (" << start_speed
               << " m/s at its start, " << end_speed << " at its end); a step of at most " << 0.25 * r_min / fastest
               << " s keeps it within a quarter of the smallest radius"
               << (substeps_entry.empty() || !attached.empty() ? ""
                   : most_substeps == 1 ? " (or set " + substeps_entry + " > 1 to take such steps in sub-steps)"
                                        : " (or raise " + substeps_entry + ")");
            std::ostringstream why;
            why << mover << " moved " << farthest / r_min << " r_min (" << fastest << " m/s) and left an overlap of "
                << deepest_overlap / r_min << " r_min";
            throw StepTooLong(os.str(), fastest, why.str());
          }
        else
          {
            const ParameterSection &solver_section = solver->parameters().section;
            os << "The deepest contact, between "
               << (deepest.bodies[0] < 0 ? std::string("a half-disc of a deformable first body")
                                         : "body " + std::to_string(long(deepest.bodies[0])))
               << " and body " << long(deepest.bodies[1]) << ", overlapped by "
               << deepest.overlap - deepest.closed << " m at the step's start and closed by " << deepest.closed
               << " m in the step: the overlap does not come from the step size. Either discs were placed "
                  "overlapping, or the law lets it grow: with IQS, overlaps kept step after step within the "
                  "solver's tolerance (high pressure: tighten "
               << (by_nlgs ? solver_section.entry("Tolerance") + " or " + solver_section.entry("Gap tolerance")
                   : solver->parameters().method == SolverParameters::Method::apgs
                     ? solver_section.entry("Residual target") + " or " + solver_section.entry("Gap tolerance")
                     : solver_section.entry("Residual target"))
               << ", or set " << contact_law.section.entry("Overlap recovery")
               << "); with ELAS, a stiffness too low for the load (docs/laws.md)";
          }
        for (const Attached &a : attached)
          if (const std::string hint = a.body->overlap_hint(h); !hint.empty())
            os << ". " << hint;
        throw RunError(os.str());
      }
  }

  void WarmStart::assign(const std::vector<Entry> &list)
  {
    std::size_t owners = 0;
    for (const auto &e : list)
      owners = std::max<std::size_t>(owners, static_cast<std::uint32_t>(e.first) + 1);
    start.assign(owners + 1, 0);
    for (const auto &e : list)
      ++start[static_cast<std::uint32_t>(e.first) + 1];
    for (std::size_t o = 0; o < owners; ++o)
      start[o + 1] += start[o];
    entries.resize(list.size());
    std::vector<unsigned int> fill(start.begin(), start.end() - 1);
    for (const auto &e : list)
      entries[fill[static_cast<std::uint32_t>(e.first)]++] = e;
  }

  std::vector<WarmStart::Entry> WarmStart::sorted() const
  {
    std::vector<Entry> out = entries;
    std::sort(out.begin(), out.end(), [](const Entry &a, const Entry &b) { return a.first < b.first; });
    return out;
  }

  void MoreauJean::save(CheckpointOut &ar) const
  {
    const std::vector<WarmStart::Entry> impulses = previous_impulse.sorted();
    std::size_t                         n        = impulses.size();
    ar << n;
    for (const auto &[key, r] : impulses)
      ar << key << r.x() << r.y();
    ar << solver->random_state();
  }

  void MoreauJean::load(CheckpointIn &ar)
  {
    std::size_t n;
    ar >> n;
    std::vector<WarmStart::Entry> impulses(n);
    for (auto &[key, r] : impulses)
      ar >> key >> r.x() >> r.y();
    previous_impulse.assign(impulses);
    std::string random;
    ar >> random;
    solver->set_random_state(random);
  }
} // namespace tribo::dem
