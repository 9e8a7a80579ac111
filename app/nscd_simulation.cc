#include "app/nscd_simulation.h"

#include "app/sample_file.h"
#include "app/scene.h"
#include "core/errors.h"
#include "core/output.h"
#include "dem/parallel/band_split.h"
#include "dem/parallel/solve_across_ranks.h"
#include "dem/solvers/methods.h"

#include <deal.II/base/mpi.h>

#include <boost/archive/binary_iarchive.hpp>
#include <boost/archive/binary_oarchive.hpp>
#include <boost/serialization/vector.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include <sys/resource.h>

namespace tribo::app
{
  namespace
  {
    /// Peak resident memory of the process so far, MB (getrusage; Linux reports KiB).
    double peak_memory_mb()
    {
      rusage usage{};
      getrusage(RUSAGE_SELF, &usage);
      return usage.ru_maxrss / 1024.0;
    }

    /// What SolveReport::iterations counts for @p method, as it follows a number.
    /// Where the steps' wall time goes, over the steps of this process (since the start
    /// or the last resumption: not checkpointed), for summary.json "timing".
    struct StepTiming
    {
      unsigned long steps = 0, sweeps = 0, check_passes = 0;
      double        step = 0, detection = 0, boundary_body = 0, solver = 0, exchange = 0;
      /// Sum over steps of (sweeps + check passes) x contacts: a check pass solves every
      /// contact's law like a sweep.
      double contact_updates = 0;

      void add(const dem::StepReport &r)
      {
        ++steps;
        sweeps += r.solver.iterations;
        check_passes += r.solver.check_passes;
        step += r.time_step;
        detection += r.time_detection;
        boundary_body += r.time_boundary_body;
        solver += r.time_solver;
        exchange += r.solver.time_exchange;
        contact_updates += double(r.solver.iterations + r.solver.check_passes) * r.n_contacts;
      }

      /// Means per step, s, and the NLGS cost per contact update, ns.
      JsonObject to_json() const
      {
        JsonObject j;
        const double n = std::max(1ul, steps);
        j.set("steps", long(steps));
        j.set("step_mean_s", step / n);
        j.set("detection_mean_s", detection / n);
        j.set("boundary_body_mean_s", boundary_body / n);
        j.set("solver_mean_s", solver / n);
        j.set("exchange_mean_s", exchange / n); // part of solver_mean_s
        j.set("other_mean_s", (step - detection - boundary_body - solver) / n);
        j.set("solver_iterations_mean", double(sweeps) / n);
        j.set("solver_check_passes_mean", double(check_passes) / n);
        j.set("solver_ns_per_contact_update", contact_updates > 0 ? 1e9 * solver / contact_updates : 0.0);
        return j;
      }
    };

    /// What the solver did over the run's steps (checkpointed).
    struct SolverRecord
    {
      unsigned long total_iterations = 0, non_converged = 0, max_iterations = 0;
      double        worst_overlap = 0, max_residual = 0, max_speed = 0;
      /// The law residual (dem/laws/law_residual.h) over the steps, and the active set's work.
      double        max_law_residual = 0, sum_law_residual = 0, max_gap_violation = 0;
      unsigned long total_factorizations = 0, fallbacks = 0, gap_exceeded = 0;

      void add(const dem::StepReport &r)
      {
        total_iterations += r.solver.iterations;
        max_iterations    = std::max<unsigned long>(max_iterations, r.solver.iterations);
        max_residual      = std::max(max_residual, r.solver.residual);
        max_law_residual  = std::max(max_law_residual, r.solver.law_residual);
        sum_law_residual += r.solver.law_residual;
        max_gap_violation = std::max(max_gap_violation, r.solver.gap_violation);
        total_factorizations += r.solver.factorizations;
        fallbacks += r.solver.fell_back ? 1 : 0;
        gap_exceeded += r.solver.gap_exceeded ? 1 : 0;
        worst_overlap = std::max(worst_overlap, r.max_overlap);
        max_speed     = std::max(max_speed, r.max_speed);
      }
      void save(CheckpointOut &ar) const
      {
        ar << total_iterations << non_converged << max_iterations << worst_overlap << max_residual
           << max_law_residual << sum_law_residual << max_gap_violation << total_factorizations << fallbacks << gap_exceeded
           << max_speed;
      }
      void load(CheckpointIn &ar)
      {
        ar >> total_iterations >> non_converged >> max_iterations >> worst_overlap >> max_residual >>
          max_law_residual >> sum_law_residual >> max_gap_violation >> total_factorizations >> fallbacks >> gap_exceeded >>
          max_speed;
      }
    };

    /// Rigid discs stepped by Moreau-Jean: the scene builds them and measures its columns.
    class NscdSimulation : public Simulation
    {
    public:
      NscdSimulation(const CaseParameters &p, std::unique_ptr<Scene> built, Log &log)
        : prm(p), scene(std::move(built))
      {
        const auto wall_start = std::chrono::steady_clock::now();
        scene->build(system);
        h                     = scene->time_step(system);
        const double distance = p.law.detection_distance > 0 ? p.law.detection_distance : 0.1 * system.min_radius();
        dem::SolverParameters solver = p.solver;
        solver.gap_tolerance         = p.solver.relative_gap_tolerance * system.min_radius();
        solver.gap_target            = p.solver.relative_gap_target * system.min_radius();
        mj = std::make_unique<dem::MoreauJean>(p.theta, p.law, solver, distance);
        scene->attach(*mj);
        mj->allow_substeps(p.most_substeps, "Simulation/Most substeps");
        mj->allow_retakes(p.most_retake_substeps, "Simulation/Most substeps on retake");
        if (p.most_substeps > 1 && mj->n_boundary_bodies() > 0)
          log("Simulation/Most substeps = " + std::to_string(p.most_substeps) +
              " has no effect on this case: its deformable first body's integrator keeps the step");
        if (const unsigned int ranks = rank_count(p.ranks); ranks > 1)
          {
            // A rank holds the grains within a pair's reach of its band (2 r_max and the
            // detection distance, with the motion estimates' widening) and a step's motion (r_max).
            split = std::make_shared<dem::parallel::BandSplit>(p.ranks, 3 * system.max_radius() + distance);
            mj->use_split(split);
            mj->use_solver(std::make_unique<dem::parallel::SolveAcrossRanks>(solver, system, split));
            log("the contacts of each step split over " + std::to_string(ranks) +
                " MPI ranks (horizontal bands of equal contact counts: each rank detects and solves its "
                "band's, a deformable first body's on the top band's rank, and advances the grains of its "
                "band, the walls and first bodies on every rank); rank 0 writes (docs/scaling.md)");
          }
        world.integrator = mj.get();
        n_steps = std::max(1L, std::lround(std::ceil(p.end_time / h - 1e-9)));
        // A run that goes on from an initial state starts at its step (a whole number of
        // steps, checked with the parameters).
        start = std::lround(scene->start_time() / h);
        step  = start;

        std::ostringstream os;
        os << "scene " << p.scene << ": " << system.bodies.size() << " bodies, " << system.discs.size()
           << " discs; h = " << h << " s, " << n_steps << " steps, detection distance "
           << mj->detection_distance() << " m";
        log(os.str());
        if (!scene->description().empty())
          log(scene->description());
        if (start > 0)
          {
            std::ostringstream state;
            state << "starting from " << scene->start_state() << " at t = " << start * h
                  << " s (step " << start << "; its sample_final.csv, without contact impulses)";
            log(state.str());
          }
        if (!p.solver.unused_nlgs_entries.empty() && (p.law.friction <= 0 || dem::solves_friction(p.solver.method)))
          {
            std::ostringstream unused;
            unused << "Solver/Method = " << dem::method_name(p.solver.method) << " stops at Solver/Residual target = "
                   << p.solver.residual_target << "; the NLGS entries " << p.solver.unused_nlgs_entries
                   << " have no effect on this case (they act with Method = nlgs)";
            log(unused.str());
          }
        if (!dem::solves_friction(p.solver.method) && p.law.friction > 0)
          log("Solver/Method = " + dem::method_name(p.solver.method) +
              " solves frictionless problems only: with Coulomb friction (mu = " +
              std::to_string(p.law.friction) + ") every step uses NLGS (Method = apgs solves friction itself)");
        // What building the case cost: the modules a case does not use are not built (a
        // wall of discs builds no deal.II, SPH or MLP object).
        setup_time   = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
        setup_memory = peak_memory_mb();
        std::ostringstream cost;
        cost << "set-up " << setup_time << " s, peak memory " << setup_memory << " MB";
        log(cost.str());
      }

      unsigned long first_step() const override { return start; }
      double        time() const override { return step * h; }
      double        end_time() const override { return n_steps * h; }
      bool          reached_end(unsigned long s) const override { return s >= n_steps; }
      bool          finished() const override { return scene->finished(); }

      void advance(unsigned long s, const std::function<void(const std::string &)> &warn) override
      {
        world.step = s;
        scene->before_step(world);
        const dem::StepReport r = mj->step(system, h);
        step                    = s + 1;
        world.report            = r;
        scene->after_step(world);
        record.add(r);
        timing.add(r);
        if (r.retaken)
          {
            if (++retaken <= 10)
              warn("note: step " + std::to_string(step) + " (t = " + to_text(time()) + " s) taken again in " +
                   std::to_string(r.substeps) + " sub-steps (Simulation/Most substeps on retake): " +
                   mj->retake_reason() + (retaken == 10 ? " (further ones only counted)" : ""));
          }
        else if (r.substeps > 1 && ++substepped <= 10)
          {
            std::ostringstream os;
            os << "note: step " << step << " (t = " << time() << " s) taken in " << r.substeps
               << " sub-steps (Simulation/Most substeps): a body's speed at its start would have carried it "
                  "more than a quarter of the smallest radius"
               << (substepped == 10 ? " (further ones only counted)" : "");
            warn(os.str());
          }
        if (!r.solver.converged && ++record.non_converged <= 10)
          {
            // Which solve stopped short: NLGS (the method, the frictional steps it is handed,
            // the active set's fallback) with its own norm, or a global method at its law
            // residual.
            const auto method  = prm.solver.method;
            const bool by_nlgs = r.solver.solved_by_nlgs;
            std::ostringstream os;
            os << "warning: step " << step << " (t = " << time() << " s): ";
            if (r.solver.gap_exceeded)
              os << "a gap violation of " << r.solver.gap_violation / system.min_radius()
                 << " of the smallest radius, above Solver/Gap target = " << prm.solver.relative_gap_target
                 << ", at law residual " << r.solver.law_residual
                 << ": a few large impulses (a body landing or stopped in one step) inflate the mean impulse "
                    "the law residual is relative to, and hide closing velocities that drive discs through "
                    "each other; tighten Solver/Residual target (or Solver/Tolerance with NLGS), use "
                    "Solver/Method = interior-point, or let the body settle (a later Shear cell/Shear start)";
            else if (by_nlgs)
              os << "NLGS did not converge in " << r.solver.iterations << " sweeps, residual " << r.solver.residual;
            else
              {
                os << "Solver/Method = " << dem::method_name(method) << " stopped at law residual "
                   << r.solver.law_residual << " (Solver/Residual target = " << prm.solver.residual_target
                   << ") after ";
                if (r.solver.factorizations > 0)
                  os << r.solver.factorizations << " factorisations"
                     << (r.solver.iterations > 0 ? " and " : "");
                if (r.solver.iterations > 0 || r.solver.factorizations == 0)
                  os << r.solver.iterations << " " << dem::solver_method(method).iterations;
                if (r.n_active == 0)
                  os << "; no contact loaded: the law residual is relative to the contacts' velocity scale";
                else if (10 * r.n_active < r.n_contacts)
                  os << "; only " << r.n_active << " of the " << r.n_contacts
                     << " contacts loaded: the law residual is relative to their mean impulse";
              }
            os << (record.non_converged == 10 ? " (further warnings only counted)" : "");
            warn(os.str());
          }
        last = Row();
        last("n_contacts", r.n_contacts)("n_active_contacts", r.n_active)
          ("solver_iterations", r.solver.iterations)("solver_residual", r.solver.residual)
          ("solver_converged", r.solver.converged ? 1.0 : 0.0)("law_residual", r.solver.law_residual)
          ("gap_violation", r.solver.gap_violation)("epsilon", r.epsilon)("max_overlap", r.max_overlap)
          ("kinetic_energy", r.kinetic_energy)("power_external", r.power_external)
          ("power_free", r.power_free)("power_contacts", r.power_contacts);
        scene->measure(world, last);
        measured = true;
        const auto &columns = last.columns();
        power_sums.resize(columns.size(), 0.0);
        for (std::size_t c = 0; c < columns.size(); ++c)
          if (is_power(columns[c].first))
            power_sums[c] += columns[c].second;
        ++power_steps;
      }

      /// The columns of the last step; the power_* columns as their means over the steps
      /// since the previous row, so that a row every N steps carries the work of all N
      /// (a power that alternates from step to step would alias otherwise).
      bool row(Row &row) override
      {
        const auto &columns = last.columns();
        for (std::size_t c = 0; c < columns.size(); ++c)
          row(columns[c].first, is_power(columns[c].first) && power_steps > 1 ? power_sums[c] / power_steps
                                                                              : columns[c].second);
        power_sums.assign(power_sums.size(), 0.0);
        power_steps = 0;
        return measured;
      }
      bool row_due(unsigned long s) override { return s % prm.statistics_interval == 0; }
      bool snapshot_due(unsigned long s) override
      {
        return prm.field_interval > 0 && s % prm.field_interval == 0;
      }

      /// On N ranks each rank writes the discs of one band of equal disc counts (by the height
      /// of their centres) and the loaded contacts whose midpoint lies in it, as its piece of
      /// the snapshot; the first rank then writes the .pvtu records, the .pvd indices, the
      /// sample and the scene's own fields.
      void write_snapshot(FieldWriter &writer) override
      {
        mj->make_whole(system);
        const auto        &s     = system;
        const unsigned int ranks = rank_count(prm.ranks), rank = rank_in(prm.ranks);
        std::vector<double> cuts; // the bands' upper edges but the last's, m
        if (ranks > 1)
          {
            std::vector<double> heights;
            for (std::size_t d = 0; d < s.discs.size(); ++d)
              heights.push_back(s.wrap(s.disc_centre(d)).y());
            std::sort(heights.begin(), heights.end());
            for (unsigned int k = 1; k < ranks; ++k)
              cuts.push_back(heights[k * heights.size() / ranks]);
          }
        const auto mine = [&](double y) {
          return ranks == 1 || std::upper_bound(cuts.begin(), cuts.end(), y) - cuts.begin() == long(rank);
        };
        DiscField discs;
        for (std::size_t d = 0; d < s.discs.size(); ++d)
          {
            const auto &b   = s.bodies[s.discs[d].body];
            const auto  x   = s.wrap(s.disc_centre(d));
            if (!mine(x.y()))
              continue;
            const auto  arm = dem::rotate(s.discs[d].offset, b.angle);
            discs.x.push_back(x.x());
            discs.y.push_back(x.y());
            discs.radius.push_back(s.discs[d].radius);
            discs.vx.push_back(b.velocity.x() - b.spin * arm.y());
            discs.vy.push_back(b.velocity.y() + b.spin * arm.x());
            discs.spin.push_back(b.spin);
            discs.body.push_back(s.discs[d].body);
          }
        // Each rank's own contacts when it holds its share of them; otherwise those of its
        // band of discs.
        ContactField contacts;
        for (const auto &c : mj->contacts())
          {
            if (c.r.x() == 0 && c.r.y() == 0)
              continue;
            const auto x0 = s.wrap(s.disc_centre(c.disc[0]));
            if (mj->holds_every_contact() && !mine(x0.y() + 0.5 * c.branch.y()))
              continue;
            contacts.x0.push_back(x0.x());
            contacts.y0.push_back(x0.y());
            contacts.x1.push_back(x0.x() + c.branch.x());
            contacts.y1.push_back(x0.y() + c.branch.y());
            contacts.normal_force.push_back(c.r.x() / mj->step_length()); // over the last (sub-)step
            contacts.tangential_force.push_back(c.r.y() / mj->step_length());
            contacts.gap.push_back(c.gap);
          }
        writer.write(time(), discs, contacts, {rank, ranks});
        if (ranks > 1)
          {
            MPI_Barrier(prm.ranks); // every piece on disk before the records name it
            if (rank > 0)
              return;
            writer.write_piece_records(ranks);
          }
        // The discs as a sample file next to the snapshot (`tribo sample DIR --time T`),
        // exact where the VTU's Float32 is not.
        if (const std::string sample = scene->sample(s); !sample.empty())
          atomic_write(sample_snapshot_path(writer.directory(), writer.n_snapshots() - 1), sample);
        // The scene's own fields, SERIES_NNNNN.vtu, indexed in SERIES.pvd.
        for (const std::string &file : scene->write_fields(writer.directory(), writer.n_snapshots() - 1))
          writer.index(file.substr(0, file.rfind('_')), time(), file);
      }
      unsigned int n_snapshots(const FieldWriter &fields) const override { return fields.n_snapshots(); }
      bool         snapshot_on_every_rank() const override { return rank_count(prm.ranks) > 1; }

      std::string resumed_line(unsigned long s) const override
      {
        std::ostringstream os;
        os << "resumed at step " << s << " (t = " << time() << " s) of " << n_steps;
        return os.str();
      }

      void summarize(const RunEnd &end, JsonObject &summary, RunOutputs &out) override
      {
        const unsigned long steps_run = step - start;
        const auto          per_step  = [&](double total) { return steps_run ? total / steps_run : 0.0; };
        const auto          method    = prm.solver.method;
        summary.set("time_step", h);
        summary.set("steps_planned", long(n_steps - start));
        summary.set("start_time", start * h);
        summary.set("solver_iterations_total", long(record.total_iterations));
        summary.set("solver_iterations_mean", per_step(record.total_iterations));
        summary.set("solver_iterations_max", long(record.max_iterations));
        summary.set("solver_residual_max", record.max_residual);
        summary.set("solver_non_converged_steps", long(record.non_converged));
        summary.set("law_residual_max", record.max_law_residual);
        summary.set("law_residual_mean", per_step(record.sum_law_residual));
        summary.set("gap_violation_max", record.max_gap_violation);
        summary.set("solver_method", dem::method_name(method));
        summary.set("factorizations_mean", per_step(record.total_factorizations));
        summary.set("active_set_fallbacks", long(record.fallbacks));
        summary.set("gap_target_exceeded", long(record.gap_exceeded));
        summary.set("max_overlap", record.worst_overlap);
        summary.set("max_overlap_over_min_radius", record.worst_overlap / system.min_radius());
        summary.set("max_body_speed", record.max_speed);
        summary.set("n_bodies", long(system.bodies.size()));
        summary.set("n_discs", long(system.discs.size()));
        {
          JsonObject t = timing.to_json();
          if (split)
            t.set("band_cuts", long(split->cuts())); // since the start or the last resumption
          summary.set("timing", t);
        }
        summary.set("setup_time", setup_time);
        {
          // On N ranks, the largest rank's.
          const double here[2] = {setup_memory, peak_memory_mb()};
          double       largest[2] = {here[0], here[1]};
          if (split)
            dealii::Utilities::MPI::max(here, prm.ranks, largest);
          summary.set("setup_peak_memory", largest[0]);
          summary.set("peak_memory", largest[1]);
        }
        if (!end.statistics.rows().empty())
          {
            scene->summarize(world, end.statistics, out.results);
            if (const std::string note = scene->averaging_note(); !note.empty())
              end.log(note);
          }
        out.scalars["time_step"] = h;
        out.tables               = scene->tables();
        mj->make_whole(system);
        out.final_sample         = scene->sample(system);
        if (prm.plots)
          out.plot_script = scene->plot_script();

        std::ostringstream os;
        os << steps_run << " steps in " << end.wall_time << " s, " << per_step(record.total_iterations)
           << " " << dem::solver_method(method).iterations << " per step, " << record.non_converged << " steps not converged, law residual mean "
           << per_step(record.sum_law_residual) << " max " << record.max_law_residual << ", worst overlap "
           << record.worst_overlap << " m";
        if (record.total_factorizations > 0)
          os << ", " << per_step(record.total_factorizations) << " factorisations per step";
        if (record.fallbacks > 0)
          os << ", " << record.fallbacks << " NLGS fallbacks";
        if (record.gap_exceeded > 0)
          os << ", " << record.gap_exceeded << " steps above Solver/Gap target";
        if (substepped > 0)
          os << ", " << substepped << " steps in sub-steps since the run's start or resumption";
        if (retaken > 0)
          os << ", " << retaken << " steps taken again in sub-steps since the run's start or resumption";
        if (timing.steps > 0)
          {
            const double n = timing.steps;
            os << "; per step " << 1e3 * timing.step / n << " ms: solver " << 1e3 * timing.solver / n
               << " ms, detection " << 1e3 * timing.detection / n << " ms, upper body "
               << 1e3 * timing.boundary_body / n << " ms";
          }
        out.last_line = os.str();
      }

      // After the step number (the driver's): the solver's record, then every object's
      // state, in this order.
      void prepare_checkpoint() override
      {
        mj->make_whole(system);
        mj->gather_warm_start();
      }
      void save(CheckpointOut &ar) const override
      {
        record.save(ar);
        system.save(ar);
        mj->save(ar);
        scene->save(ar);
        ar << power_sums << power_steps;
      }
      void load(CheckpointIn &ar, unsigned long s) override
      {
        step = s;
        record.load(ar);
        system.load(ar);
        mj->load(ar);
        scene->load(ar);
        ar >> power_sums >> power_steps;
      }

    private:
      CaseParameters                   prm;
      std::unique_ptr<Scene>           scene;
      dem::ParticleSystem              system;
      NscdWorld                        world{system}; ///< what the scene's hooks see
      std::unique_ptr<dem::MoreauJean> mj;
      std::shared_ptr<dem::parallel::BandSplit> split; ///< on N > 1 ranks
      double                           h = 0;
      unsigned long                    n_steps = 0, start = 0, step = 0;
      double                           setup_time = 0, setup_memory = 0;
      SolverRecord                     record;
      unsigned long                    substepped = 0; ///< steps taken in sub-steps since this process started
      unsigned long                    retaken = 0; ///< steps taken again in sub-steps since this process started
      StepTiming                       timing; ///< the steps since the start or the last resumption
      Row                              last;   ///< the columns measured after the last step
      bool                             measured = false;
      std::vector<double>              power_sums;      ///< per column of last, power_* only, W/m
      unsigned long                    power_steps = 0; ///< steps summed into power_sums

      static bool is_power(const std::string &column) { return column.rfind("power_", 0) == 0; }
    };
  } // namespace

  std::unique_ptr<Simulation> make_nscd_simulation(const CaseParameters &p, std::unique_ptr<Scene> scene, Log &log)
  {
    return std::make_unique<NscdSimulation>(p, std::move(scene), log);
  }
} // namespace tribo::app
