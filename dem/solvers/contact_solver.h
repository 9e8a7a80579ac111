#pragma once
/// @file The one interface of the contact solvers: their controls (SolverParameters, the
/// case's Solver subsection), what a solve reports (SolveReport) and ContactSolver, which
/// MoreauJean holds. Each method is one file pair in dem/solvers/ and one row of the table
/// in dem/solvers/methods.cc (its name, whether it solves Coulomb friction, its own
/// entries, its constructor).

#include "core/parameter_section.h"
#include "dem/engine/body_state.h"
#include "dem/engine/contact.h"
#include "dem/laws/contact_law.h"

#include <memory>
#include <string>
#include <vector>

namespace dealii
{
  class ParameterHandler;
}

namespace tribo::dem
{
  /// Controls of the contact solve: the method, and the NLGS's own controls.
  struct SolverParameters
  {
    /// The method, one row each in the table of dem/solvers/methods.cc: nonlinear
    /// Gauss-Seidel (dem/solvers/nlgs.h); on the frictionless problem, the active-set
    /// (projected Newton) method with the sparse Delassus operator factorised by CHOLMOD
    /// (active_set.h), the matrix-free MPRGP (mprgp.h) and APGD (apgd.h), APGS, Gauss-Seidel
    /// sweeps with momentum (apgs.h), or the primal-dual interior-point method, also with
    /// CHOLMOD (interior_point.h). NLGS and APGS solve the Coulomb law themselves
    /// (solves_friction()); the other methods hand a frictional step to NLGS and say so.
    enum class Method
    {
      nlgs,
      active_set,
      mprgp,
      interior_point,
      apgd,
      apgs
    };
    Method method = Method::apgs; ///< the Method entry's default too
    /// NLGS's stopping entries (Tolerance, Norm, Check interval, Gap tolerance) a case file set although
    /// the method is another, with where they were set ("Solver/Tolerance (case.prm:24)"):
    /// they then act only on the steps NLGS solves (friction), and the run log says so.
    std::string unused_nlgs_entries;
    /// Active set: relative regularisation delta of the Newton matrix W_FF + delta
    /// diag(W_FF) (redundant, hyperstatic contacts make W_FF singular; it changes the step,
    /// not the solution).
    double regularization = 1e-8;
    /// Global methods: NLGS sweeps before their iterations (0: none).
    unsigned int predictor_sweeps = 10;
    /// Active set: factorisations per step before the step is solved by NLGS instead;
    /// interior point: iterations per step before it stops, not converged.
    unsigned int max_factorizations = 50;
    /// Global methods: the solve ends when the natural map max |min(x, w / W_nn)|
    /// (dem/solvers/frictionless_problem.h) is below this times the iterate's mean loaded impulse
    /// (the law residual, dem/laws/law_residual.h; the active set and the interior-point method
    /// also stop at their round-off floors). The default, 1e-3, is below the 1.2-1.5e-3
    /// NLGS leaves on average at Quad 1e-4 in steady shear: at 1.5e-3 MPRGP let an overlap
    /// grow past a radius on the 3800-grain benchmark (docs/performance.md).
    double residual_target = 1e-3;
    enum class Norm
    {
      quad,
      maxm
    };
    double       tolerance      = 1e-4;
    Norm         norm           = Norm::quad;
    double       relaxation     = 1.0; ///< omega: r <- omega r_law + (1 - omega) r_old
    unsigned int check_interval = 10;  ///< sweeps between convergence checks
    unsigned int max_iterations = 10000; ///< sweeps
    /// Order of the local solves in a sweep: the detection order (cells by rows, bottom to
    /// top), that order and its reverse in turn (a symmetric Gauss-Seidel: what the
    /// bottom wall imposes climbs the layer in one forward sweep, what the loaded top
    /// wall imposes comes down in one backward sweep), or shuffled every sweep.
    enum class Order
    {
      fixed,
      alternating,
      random
    };
    Order        order          = Order::fixed;
    unsigned int seed           = 1;
    /// The fixed order in windows of streams x stream_spacing consecutive contacts; each
    /// window is cut into this many streams, solved one contact from each stream in turn
    /// (within each band, see threads). Contacts stream_spacing apart in detection order
    /// lie cells apart and rarely share a body, so the processor overlaps their updates
    /// instead of waiting on each body's last write, while a window stays in cache
    /// (docs/performance.md: 1.5 times more updates per second than the detection order
    /// at 1k discs, for 3 % more sweeps). 1 (the default): the detection order itself.
    unsigned int streams = 1;
    /// Distance in the order between the contacts solved one after another, see streams.
    unsigned int stream_spacing = 64;
    /// Bands solved at once (1: the plain serial sweep). With T > 1 the contacts, in
    /// detection order (rows of cells, bottom to top), are cut into 2T bands of equal
    /// count; a sweep solves the even bands concurrently, then the odd ones. Bands of
    /// one phase share no body, so the sweep is the serial Gauss-Seidel sweep in the
    /// order 0, 2, ..., 1, 3, ...: the result depends on T, never on the scheduling. If
    /// a solve's bands do share a body (a thin packing), that solve runs the same
    /// order serially. Needs Order::fixed (other orders ignore it: one band). The
    /// contact detection of the Moreau-Jean step also searches in T threads (the same
    /// contacts in the same order whatever T).
    unsigned int threads = 1;
    /// Extra criterion (0: off): also require, for every IQS contact, the gap
    /// violation theta h max(0, -(u_n + shift)) to be at most this, m. The norms
    /// above measure how much a sweep changes the solution, not how far it is
    /// from the law: a slowly converging packing under high pressure passes them
    /// with normal velocities whose small errors freeze into overlaps step after
    /// step (docs/laws.md).
    double gap_tolerance = 0;
    /// Solver/Gap tolerance as the case gives it: a fraction of the smallest radius (the run
    /// sets gap_tolerance = this times the smallest radius once the discs are known).
    double relative_gap_tolerance = 0;
    /// Every method: the largest gap violation theta h max(0, -(u_n + shift)) over the IQS
    /// contacts a step may keep and still count as converged, m (0: off). The law residual is
    /// relative to the mean loaded impulse, which a few large impulses (a heavy body stopped
    /// in one step) inflate: a step can pass it with closing velocities that drive discs
    /// through each other. A step above gap_target is reported not converged
    /// (SolveReport::gap_exceeded), and the run's log names the cause.
    double gap_target = 0;
    /// Solver/Gap target as the case gives it, a fraction of the smallest radius (the run sets
    /// gap_target = this times the smallest radius).
    double relative_gap_target = 0.01;
    /// The largest gap violation at which APGS (serial or across ranks) stops, m (0: none):
    /// gap_tolerance, or when it is 0 the gap target, which a converged step must meet anyway.
    double apgs_gap_stop() const { return gap_tolerance > 0 ? gap_tolerance : gap_target; }
    /// The case subsection these controls were read from: messages name entries through it.
    ParameterSection section;

    /// Declare the solver's entries in the current subsection of @p prm (the caller
    /// enters and leaves it): the entries every method reads, then each method's own (its
    /// row's declare); dem/solvers/methods.cc.
    static void declare(dealii::ParameterHandler &prm);
    /// The controls of subsection @p section of @p file, checked, in the same order;
    /// InputError names the file, the line and the entry.
    static SolverParameters parse(const ParameterFile &file, const std::string &section);
  };

  /// What one solve achieved.
  struct SolveReport
  {
    /// The method's iterations, predictor sweeps included (check passes not included): NLGS
    /// sweeps, or what the method's row in dem/solvers/methods.cc names.
    unsigned int iterations   = 0;
    /// Active set: sparse factorisations done (Newton iterations), and whether it fell
    /// back to NLGS (which then reports its sweeps in iterations).
    unsigned int factorizations = 0;
    bool         fell_back      = false;
    /// Whether NLGS solved the step (the method is NLGS, or it handed a frictional step
    /// to NLGS, or the active set fell back): residual is then NLGS's criterion.
    bool solved_by_nlgs = false;
    /// The law residual after the solve (dem/laws/law_residual.h), max |phi| / mean loaded
    /// impulse: the same measure whatever the method.
    double law_residual = 0;
    /// Whether law_residual and gap_violation are already those of the answer returned,
    /// over every contact, so that MoreauJean does not compute them again: a solve across
    /// MPI ranks sums them over the ranks' shares (dem/parallel/solve_across_ranks.h).
    bool law_assessed = false;
    /// Convergence checks done: passes of local solves that apply nothing, one every
    /// `check_interval` sweeps (their cost is part of the solver's time).
    unsigned int check_passes = 0;
    /// With SolverParameters::threads > 1: whether the bands were solved concurrently
    /// (false: they shared a body and were solved serially, in the same order).
    bool concurrent = false;
    bool         converged  = true;
    /// Whether the step's gap violation passed SolverParameters::gap_target (the step is then
    /// not converged, whatever its law residual).
    bool gap_exceeded = false;
    /// The achieved criterion: max(|MeanDVoR|, QuadDV, QuadDVR) (or the Maxm
    /// ones) times tol, i.e. the relative quantity that is compared with tol.
    double residual = 0;
    /// Largest gap violation theta h max(0, -(u_n + shift)) over the IQS contacts at
    /// the last check, m (0 for ELAS, whose law has no hard constraint).
    double gap_violation = 0;
    /// Of the solve's wall time on several MPI ranks (dem/parallel/solve_across_ranks.h), s:
    /// dividing the step's problem between the ranks (bands, share, exchange pattern), the
    /// sweeps' exchanges and sums over the ranks (waits included) and the gather of the
    /// result. 0 on one rank.
    double time_exchange = 0;
  };


  /// A contact solver: it finds the impulses of one step's local problems.
  class ContactSolver
  {
  public:
    explicit ContactSolver(const SolverParameters &p) : prm(p) {}
    virtual ~ContactSolver() = default;
    /// Solve for the impulses of @p contacts (warm-started from their r, whose effect must
    /// already be in @p state) under @p law, updating them and @p state. @p theta_h = theta h
    /// turns velocity violations into gap violations (m). Without contacts: an empty report.
    virtual SolveReport solve(std::vector<Contact> &contacts, BodyState &state, const ContactLaw &law,
                              double theta_h = 0) = 0;
    const SolverParameters &parameters() const { return prm; }
    /// Whether the method solves the law with Coulomb friction itself (NLGS, APGS); the
    /// others hand a frictional step to NLGS (dem/solvers/global_solver.h).
    virtual bool solves_friction() const = 0;
    /// The state of the random contact order as text (checkpoints), and its restoration.
    virtual std::string random_state() const = 0;
    virtual void        set_random_state(const std::string &state) = 0;

  protected:
    SolverParameters prm;
  };

  // Defined with the table of methods (dem/solvers/methods.cc):
  /// The solver of @p prm.method, built from @p prm.
  std::unique_ptr<ContactSolver> make_contact_solver(const SolverParameters &prm);
  /// Whether @p method solves the law with Coulomb friction itself (NLGS and APGS); the
  /// other methods hand a frictional step to NLGS.
  bool solves_friction(SolverParameters::Method method);
  /// The name of @p method as the Method entry spells it ("interior-point").
  std::string method_name(SolverParameters::Method method);
} // namespace tribo::dem
