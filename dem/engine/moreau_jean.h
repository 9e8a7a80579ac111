#pragma once
/// @file The Moreau-Jean theta scheme for rigid bodies with contact impulses
/// (Cao et al. 2011, eqs. 4-5; Jean 1999). Over a step [t_i, t_i + h]:
/// - free velocity: v_free = v_i + h M^-1 F_ext (constant imposed loads);
/// - detection at the predicted configuration q_pred = q_i + (1 - theta) h v_i;
/// - local problems u = W r + u_free with W = H^T M^-1 H, solved by the contact solver of
///   SolverParameters::method (dem/solvers/contact_solver.h);
/// - velocity v_{i+1} = v_free + M^-1 H r, position q_{i+1} = q_pred + theta h v_{i+1}.
/// Imposed-velocity dofs keep their velocity. Impulses are warm-started from
/// the previous step's contact between the same two discs.
/// MoreauJean::step() runs these as named phases, in this order: predict(), detect(),
/// set_up_local_problems(), the contact solve and assess_solve(), sum_contact_forces(),
/// update_bodies(), measure_gaps(), update_boundary_bodies() (with deformable bodies),
/// compute_contact_powers(), check_overlaps().

#include "dem/solvers/active_set.h"
#include "dem/solvers/apgd.h"
#include "dem/solvers/apgs.h"
#include "dem/engine/boundary.h"
#include "dem/engine/contact.h"
#include "dem/engine/contact_split.h"
#include "dem/laws/contact_law.h"
#include "dem/solvers/interior_point.h"
#include "dem/solvers/mprgp.h"
#include "dem/solvers/nlgs.h"
#include "dem/engine/particle_system.h"

#include <Eigen/Core>

#include <array>

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace tribo::dem
{
  /// Measurements of one step.
  struct StepReport
  {
    unsigned int n_contacts = 0; ///< detected pairs within the detection distance
    unsigned int n_active   = 0; ///< contacts with a non-zero impulse
    SolveReport   solver;
    /// Cao et al. eq. (13): mean over active contacts of g_c - g_p, the end-of-step
    /// gap with contact impulses minus the one without, theta h (u_n - u_free,n), m.
    double epsilon = 0;
    /// Largest overlap at the end of the step, max(0, -min g_end), m.
    double max_overlap = 0;
    /// Speed of the fastest body at the end of the step, |v| of its centre of mass, m/s.
    double max_speed = 0;
    double kinetic_energy = 0; ///< after the step, J/m
    /// Power of the drivers: reactions of imposed-velocity dofs (minus the contact
    /// force on them) and imposed loads, times the mean velocity over the step, W/m.
    double power_external = 0;
    /// Power of all forces (contact and imposed) on the free bodies, W/m (Cao eq. 10).
    double power_free = 0;
    /// Power of the contact forces on all bodies, W/m (<= 0: dissipation).
    double power_contacts = 0;
    /// With BoundaryBody's attached: their energy (kinetic + elastic) after the step, J/m, and
    /// the power dissipated inside them over the step, W/m, summed over the bodies. Then
    /// KE_{i+1} + E_{i+1} - KE_i - E_i = h (power_external + power_contacts - boundary_dissipation).
    double boundary_energy      = 0;
    double boundary_dissipation = 0;
    unsigned int n_boundary_contacts = 0; ///< contacts with half-disc elements, every body's
    /// The step was taken as this many equal sub-steps (MoreauJean::allow_substeps()): its
    /// counts and the solve's figures are the sums (iterations, factorisations, times) or the
    /// worst (residuals, overlaps, speeds) over them, its powers their means (so that h times
    /// a power is the step's energy), epsilon, contacts and the end state the last one's.
    unsigned int substeps = 1;
    /// The step was too long for its motion and was taken again from its start in substeps
    /// sub-steps (MoreauJean::allow_retakes()); its figures are the last attempt's, time_step
    /// includes the failed attempts' time.
    bool retaken = false;
    /// Wall time of the step and of its phases, s: detection (disc pairs and half-discs),
    /// the boundary bodies' own work (their free state in predict() and their update in
    /// finalize()), and the NLGS solve; the rest is setting up the local problems and
    /// the update of the discs.
    double time_step = 0, time_detection = 0, time_boundary_body = 0, time_solver = 0;
  };

  /// The previous step's contact impulses, for the warm start: (key, r) grouped by the
  /// key's low 32 bits (the larger disc of a disc pair, the grain of a half-disc
  /// contact), so a lookup scans the few contacts of one grain, stored side by side.
  /// Rebuilt each step by a counting sort, O(contacts + discs); a hash table did the
  /// same with one allocation per contact and a cache miss per lookup.
  class WarmStart
  {
  public:
    using Entry = std::pair<std::uint64_t, Eigen::Vector2d>;
    /// Replace the content by @p list (any order; keys distinct).
    void assign(const std::vector<Entry> &list);
    /// The impulse stored for @p key, zero if none.
    Eigen::Vector2d find(std::uint64_t key) const
    {
      const std::size_t owner = static_cast<std::uint32_t>(key);
      if (owner + 1 >= start.size())
        return Eigen::Vector2d::Zero();
      for (unsigned int i = start[owner]; i < start[owner + 1]; ++i)
        if (entries[i].first == key)
          return entries[i].second;
      return Eigen::Vector2d::Zero();
    }
    /// Every entry, sorted by key (checkpoints: independent of the storage).
    std::vector<Entry> sorted() const;

  private:
    std::vector<unsigned int> start; ///< entries of owner o: [start[o], start[o + 1])
    std::vector<Entry>        entries;
  };

  /// The integrator; it owns the contacts of the current step.
  class MoreauJean
  {
  public:
    /// The scheme with @p theta, @p law and the contact solver of @p solver
    /// (make_contact_solver()).
    MoreauJean(double theta, const ContactLaw &law, const SolverParameters &solver,
               double detection_distance);

    /// Couple @p body (not owned; it must outlive this) to the discs through half-disc
    /// elements of diameter @p half_disc_diameter (m) facing @p outward, periodic with
    /// the system's period (dem/engine/boundary.h). Its loads, energy and power join the step's.
    /// Any number of bodies may be attached (an upper and a lower first body): the engine
    /// sees each through this one interface, numbers their nodes and half-discs one body
    /// after another in the order of attachment (a resumed run attaches them in the same
    /// order), and their compliances form the blocks of BodyState::node_blocks.
    void attach(BoundaryBody &body, double half_disc_diameter, const Vec2 &outward, double period);
    /// Solve the steps' contacts with @p other instead of the solver built from the
    /// SolverParameters (a case on several MPI ranks: dem/parallel/solve_across_ranks.h).
    void use_solver(std::unique_ptr<ContactSolver> other) { solver = std::move(other); }
    /// Divide the steps' contacts with the other processes of @p among (a case on several
    /// MPI ranks: dem/parallel/band_split.h), each step as among->divide() decides. On a step
    /// held in shares, this process detects, solves and measures only its own contacts:
    /// - the solver gets them with the state's free velocities, without their warm-start
    ///   impulses (it adds every process's: dem/parallel/solve_across_ranks.h);
    /// - the state is split (dem/engine/contact_split.h): this process advances the grains it
    ///   owns and the replicated walls, from the contact forces summed on their owners
    ///   (ContactSplit::sum_on_owners; the boundary bodies' node impulses summed over every
    ///   process, which all advance them), sends their states to the processes that hold
    ///   them as ghosts, and its copies of the other grains are stale until make_whole();
    /// - the StepReport's counts, epsilon, worst overlaps, powers, kinetic energy and fastest
    ///   speed are over every process's contacts and bodies, and so are the decisions to take
    ///   a step again;
    /// - contacts() and contact_power() are this process's share (holds_every_contact()).
    void use_split(std::shared_ptr<ContactSplit> among) { split = std::move(among); }
    /// Whether this process counts @p body in a sum over the processes (every body, unless
    /// the state is split: then the grains it owns, and the walls on one process).
    bool counts(unsigned int body) const { return !split_state() || split->counts(body); }
    /// Collective on a split: every body's current state in @p system on every process (for
    /// the outputs and checkpoints; a split state stays split). Nothing without a split.
    void make_whole(ParticleSystem &system) const
    {
      if (split)
        split->make_whole(system);
    }
    /// False when the last step's contacts() are this process's share only.
    bool holds_every_contact() const { return !own_share; }
    /// Collective on a split: @p values summed over the processes when the last step was
    /// held in shares (a sum over contacts()); unchanged otherwise.
    void sum_over_shares(std::vector<double> &values) const;
    /// Collective on a split: every process's warm-start impulses on every process (before a
    /// checkpoint, which the first process writes alone).
    void gather_warm_start();
    /// The attached bodies, in the order of attachment.
    unsigned int n_boundary_bodies() const { return attached.size(); }

    /// Advance @p system (and the attached boundary bodies) by one step @p h (s), in
    /// sub-steps where allow_substeps() lets it.
    StepReport step(ParticleSystem &system, double h);
    /// Take a step as k equal sub-steps, k <= @p most, when its fastest body would move
    /// farther than a quarter of the smallest radius at its speed at the step's start:
    /// k = ceil(h |v|_max / (r_min / 4)). The explicit half step (1 - theta) h v moves a body
    /// before the solve can stop it, and a grain the solve launched would otherwise be carried
    /// into its neighbours (the overlap stop's farthest mover). 1 (the default): never.
    /// Not with attached boundary bodies, whose own integrators keep their step. @p entry:
    /// the case's entry that sets @p most, which the overlap stop names as a remedy ("": none).
    void allow_substeps(unsigned int most, const std::string &entry = "")
    {
      most_substeps  = std::max(1U, most);
      substeps_entry = entry;
    }
    /// Take a step again from its start, as k equal sub-steps (k <= @p most), when it was too
    /// long for its motion: its motion carried a body into another past the smallest radius
    /// (check_overlaps()'s farthest-mover case), or a disc ended it farther than contact
    /// detection foresaw (check_foresight()). k = ceil(h v / (r_min / 4)) with v the larger of
    /// that body's speeds at the attempt's start and end, and at least twice the attempt's
    /// sub-steps; an attempt in k sub-steps that fails so too is followed by one in more, up
    /// to @p most. Only such steps pay: the bodies' positions, angles and velocities at the
    /// step's start are kept (a few doubles each), and the warm start is restored. 1: never
    /// (the run stops at an overlap, as without). Not with attached boundary bodies.
    /// @p entry: the case's entry that sets @p most, named by the stop.
    void allow_retakes(unsigned int most, const std::string &entry = "")
    {
      most_retake_substeps = std::max(1U, most);
      retake_entry         = entry;
    }
    /// Why the last retaken step was taken again (StepReport::retaken): its farthest mover,
    /// how far it moved and the overlap it left.
    const std::string &retake_reason() const { return last_retake_reason; }
    /// The length of the last step or, when it was taken in sub-steps, of its last sub-step
    /// (s): contacts() hold impulses over it, so a contact's force is r / step_length().
    double step_length() const { return last_step_length; }

    /// Contacts of the last step with their impulses (N s/m).
    const std::vector<Contact> &contacts() const { return current; }
    /// Contact force (Fx, Fy in N/m, torque in N) on each body over the last step.
    const std::vector<Eigen::Vector3d> &contact_force() const { return body_force; }
    /// External power on each body over the last step (drivers' reactions and
    /// imposed loads times the mean velocity), W/m; sums to StepReport::power_external.
    const std::vector<double> &external_power() const { return body_power; }
    /// Power of each contact's impulse on the bodies it touches over the last step, W/m:
    /// P_c = r_c . u_c,mid / h with u_c,mid the relative velocity at the contact (disc 1
    /// relative to disc 0 or the half-disc) at the mid-step velocities (v_begin + v_end)/2;
    /// in the order of contacts(). Their sum is StepReport::power_contacts (with a
    /// deformable body, less its impulse_extra_power()): -P_c is what contact c dissipates.
    const std::vector<double> &contact_power() const { return power_of_contact; }
    const ContactLaw &law() const { return contact_law; }
    double theta() const { return th; }
    double detection_distance() const { return distance; }
    /// Steps of motion at the start velocity over which a pair beyond the detection
    /// distance is still a contact when it closes (dem/engine/contact.h ContactDetector::detect):
    /// the discs move h v_end before the next detection, and the margin covers an end
    /// velocity up to twice the start one.
    static constexpr double lookahead = 2;

    /// Checkpoint: the impulses of the last step (the next step's warm start) and the
    /// solver's random state. The attached boundary bodies save their own states.
    void save(CheckpointOut &ar) const;
    void load(CheckpointIn &ar);

  private:
    /// One step of @p h without sub-steps: the phases below, in order.
    StepReport single_step(ParticleSystem &system, double h);
    /// The sub-steps of a step @p h (allow_substeps()).
    unsigned int substeps_needed(const ParticleSystem &system, double h) const;
    /// A step @p h as @p k equal single_step()s, their reports merged (StepReport::substeps).
    StepReport in_substeps(ParticleSystem &system, double h, unsigned int k);
    /// The law residual and gap violation of the solve that produced @p report (the residual
    /// too, unless NLGS solved the step; the solve's own when it reports them,
    /// SolveReport::law_assessed), and the step not converged above SolverParameters::gap_target
    /// or, solved by a global method, with a law residual above its residual target.
    void assess_solve(double h, SolveReport &report) const;

    // The phases of step(), in order (see the file comment).
    /// Free velocities v_free = v + h M^-1 F_ext and the predicted configuration
    /// x + (1 - theta) h v (x_pred, angle_pred), into state and the scratch below.
    /// With a split state only the bodies this process holds, unless @p every.
    void predict(const ParticleSystem &system, double h, bool every = false);
    /// Disc pairs, and the half-discs of the attached boundary bodies (after their own
    /// predictions), closer than the detection distance at the predicted configuration, into found.
    /// With a split state that must cut its bands again, the state is made whole first.
    void detect(ParticleSystem &system, double h, StepReport &report);
    /// The local problems of found into current: arms (rows of H), own Delassus blocks,
    /// law terms, free local velocities, warm-start impulses applied to state.
    void set_up_local_problems(const ParticleSystem &system, double h, StepReport &report);
    /// body_force (and node_impulse, every attached body's nodes) from the contacts' impulses.
    void sum_contact_forces(double h);
    /// On a step held in shares: body_force summed on the bodies' owners and node_impulse
    /// over the processes (update_bodies() then puts the held bodies' end velocities into
    /// state too).
    void join_shares();
    /// Whether the state is split over the processes (ContactSplit::held()).
    bool split_state() const { return split && split->held(); }
    /// Whether this process advances @p body (every body, unless the state is split).
    bool advances(unsigned int body) const { return !split_state() || split->advances(body); }
    /// With a split state: @p values (@p n doubles) of the process whose @p key is the largest,
    /// on every process (collective). Nothing otherwise.
    void take_largest(double key, double *values, std::size_t n) const;
    /// Each disc's centre at the predicted configuration (centres) and its motion estimate
    /// until the next detection (disc_motion).
    void place_discs(const ParticleSystem &system, double h, bool every = false);
    /// End velocities v_free + h M^-1 F_c, positions x_pred + theta h v, powers; returns the
    /// fastest body's speed (m/s). Throws RunError on a non-finite velocity.
    double update_bodies(ParticleSystem &system, double h, StepReport &report);
    /// epsilon, the worst overlap of the loaded contacts (report) and of any contact
    /// (returned, m); gathers the loaded contacts' impulses into next_impulse, which
    /// single_step() makes the next warm start once the step has passed check_overlaps().
    double measure_gaps(double h, StepReport &report);
    /// Each boundary body's update with its node impulses, and their powers and energies.
    void update_boundary_bodies(double h, StepReport &report);
    /// power_of_contact at the mid-step velocities.
    void compute_contact_powers(double h);
    /// The contact with the deepest end-of-step overlap (over every process on a step held
    /// in shares; collective there): its overlap (m), how far the step closed it, h times
    /// its normal closing velocity at (1 - theta) v_begin + theta v_end (m, >= 0), the
    /// farther move of its two sides in the step, h |(1 - theta) v_begin + theta v_end| (m),
    /// and its bodies (side 0 -1 for a half-disc), as doubles for the reduction.
    struct DeepestContact
    {
      double                overlap = 0, closed = 0, moved = 0;
      std::array<double, 2> bodies{{-1, -1}};
    };
    DeepestContact deepest_contact(const ParticleSystem &system, double h) const;
    /// RunError when an overlap exceeds the smallest radius, naming the likely cause. When a
    /// side of the deepest contact moved more than a quarter of the smallest radius in the
    /// step (the motion, not the contact's history, made the overlap, and the contact's
    /// linearised geometry may not hold): the body (or boundary node) that moved farthest,
    /// h |(1 - theta) v_begin + theta v_end|, and the step that keeps it within a quarter of
    /// the smallest radius. Otherwise the overlap was there at the step's start (placed, or
    /// grown over steps within the solver's tolerance): that contact's overlap then, what
    /// the step added, and the entries that limit its growth. The first case's error is one
    /// step() catches to take the step again in sub-steps (allow_retakes()).
    /// Collective on a step held in shares (every process throws the same message).
    void check_overlaps(const ParticleSystem &system, double h, const StepReport &report,
                        double deepest_overlap) const;
    /// While a step that may be taken again is under way (attempt_substeps > 0): a RunError
    /// that step() catches to take it again in more sub-steps, when a disc ended the step
    /// farther than r_min / 4 plus the detection distance from where its contact detection's
    /// motion estimate (disc_motion, any fraction of it) put it: a grain the solve launched may
    /// then have closed a pair that detection did not see. Collective with a split state (the
    /// worst disc over every process's).
    void check_foresight(const ParticleSystem &system, double h) const;

    double                   th;
    ContactLaw               contact_law;
    std::unique_ptr<ContactSolver> solver;
    std::shared_ptr<ContactSplit>  split;
    bool                           own_share = false; ///< this step's contacts are this process's share
    double                   distance;
    unsigned int             most_substeps    = 1;
    std::string              substeps_entry; ///< allow_substeps()'s entry
    unsigned int             most_retake_substeps = 64;
    std::string              retake_entry; ///< allow_retakes()'s entry
    std::string              last_retake_reason;
    /// The sub-steps of the attempt of a step that may be taken again; 0 otherwise.
    unsigned int             attempt_substeps = 0;
    /// The bodies' state at the start of a step that may be taken again (allow_retakes()).
    struct BodyAtStart
    {
      Vec2   position, velocity;
      double angle, spin;
    };
    std::vector<BodyAtStart> at_start;
    double                   last_step_length = 0;
    ContactDetector          detector;
    std::vector<Contact>     found;   ///< detect()'s pairs, kept between steps with their capacity
    std::vector<Contact>     current;
    WarmStart                previous_impulse;
    std::vector<WarmStart::Entry> next_impulse; ///< this step's, before it becomes the previous
    BodyState                state;
    std::vector<Eigen::Vector3d> body_force;
    std::vector<double>          body_power;
    std::vector<double>          power_of_contact;
    std::vector<Vec2>        centres;
    /// An attached first body, with where its nodes and half-discs begin in the numbering
    /// of all the attached bodies' (Contact::node, Contact::half_disc).
    struct Attached
    {
      BoundaryBody              *body;
      std::unique_ptr<HalfDiscs> half_discs;
      unsigned int               first_node, first_half_disc;
    };
    std::vector<Attached>       attached;
    unsigned int                n_nodes = 0;  ///< of all the attached bodies
    std::vector<Vec2>           node_impulse; ///< N s/m, per node of all the attached bodies
    // Scratch of one step, between its phases.
    std::vector<Eigen::Vector3d> v_begin, v_free, v_mid_of; ///< (vx, vy, spin) per body
    std::vector<Vec2>            x_pred;                    ///< predicted positions, m
    std::vector<Vec2>            disc_motion;               ///< lookahead h v per disc, m (detect())
    std::vector<double>          angle_pred;                ///< predicted angles, rad
    std::vector<Vec2>            node_v_begin;              ///< boundary nodes' velocities at the start
    std::vector<Vec2>            node_v_end;                ///< and at the end (the bodies' own)
  };
} // namespace tribo::dem
