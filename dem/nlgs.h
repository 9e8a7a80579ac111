#pragma once
/// @file Nonlinear Gauss-Seidel on the Delassus operator, in the
/// "exchange local/global" form: body velocities are kept up to date and each
/// local solve reads its contact's velocity from them (no off-diagonal W stored).
///
/// Convergence is checked every `check_interval` sweeps with the norms of the
/// established NSCD code (LMGC90, see ../shared/notes/nscd-reference.md), in a check
/// pass that solves every contact's local problem against the current state and applies
/// nothing, over the N contacts with a non-zero mean impulse, with W the contact's own
/// 2x2 Delassus block, r its impulse and r_after the check's solution:
/// dV = W (r_after - r), the change of velocity the contact still wants (m/s),
/// r_bar = (r + r_after)/2, WR = W r (m/s), WRR = (W r.r before + after)/2.
/// (dV is neither the change of u since the previous sweep, blind to a closed IQS
/// contact whose impulse still moves, nor a sweep's own change, which carries what the
/// contacts before it in the sweep just did: docs/laws.md.)
/// - QuadWR = sqrt(sum (|WR_before|^2 + |WR_after|^2)/2 / N), MeanWRR = sum WRR / N;
/// - QuadDV = sqrt(sum |dV|^2 / N) / (QuadWR tol), MaxmDV with max |dV|^2;
/// - QuadDVR = sqrt(sum |dV|^2 |r_bar|^2 / N) / (MeanWRR tol), MaxmDVR with the max;
/// - MeanDVoR = sum r_bar.dV / (sum WRR tol).
/// "Quad" has converged when |MeanDVoR|, QuadDV and QuadDVR are all below 1,
/// "Maxm" when |MeanDVoR|, MaxmDV and MaxmDVR are.

#include "dem/contact.h"
#include "dem/contact_law.h"

#include <Eigen/Core>

#include <array>
#include <random>
#include <string>
#include <vector>

namespace tribo::dem
{
  /// Controls of the contact solve: the method, and the NLGS's own controls.
  struct SolverParameters
  {
    /// The method: nonlinear Gauss-Seidel (below); on the frictionless problem, the
    /// active-set (projected Newton) method with the sparse Delassus operator factorised
    /// by CHOLMOD (dem/active_set.h), the matrix-free MPRGP (dem/mprgp.h) and APGD
    /// (dem/apgd.h), APGS, Gauss-Seidel sweeps with momentum (dem/apgs.h), or the primal-dual interior-point method, also with CHOLMOD
    /// (dem/interior_point.h). With
    /// friction APGS solves the Coulomb law itself (solves_friction()); the other global
    /// methods hand the step to NLGS and say so.
    enum class Method
    {
      nlgs,
      active_set,
      mprgp,
      interior_point,
      apgd,
      apgs
    };
    Method method = Method::nlgs; ///< (a case file's default is apgs: dem/parameters.cc)
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
    /// (dem/frictionless_problem.h) is below this times the iterate's mean loaded impulse
    /// (the law residual, dem/law_residual.h; the active set and the interior-point method
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
    /// The case subsection these controls were read from: messages name entries through it.
    ParameterSection section;

    /// Declare the solver's entries in the current subsection of @p prm (the caller
    /// enters and leaves it).
    static void declare(dealii::ParameterHandler &prm);
    /// The controls of subsection @p section of @p file, checked; InputError names the
    /// file, the line and the entry.
    static SolverParameters parse(const ParameterFile &file, const std::string &section);
  };

  /// Whether @p method solves the law with Coulomb friction itself (NLGS and APGS); the
  /// other methods hand a frictional step to NLGS.
  inline bool solves_friction(SolverParameters::Method method)
  {
    return method == SolverParameters::Method::nlgs || method == SolverParameters::Method::apgs;
  }

  /// The name of @p method as the Method entry (SolverParameters::declare()) spells it.
  inline std::string method_name(SolverParameters::Method method)
  {
    switch (method)
      {
        case SolverParameters::Method::active_set:
          return "active-set";
        case SolverParameters::Method::mprgp:
          return "mprgp";
        case SolverParameters::Method::interior_point:
          return "interior-point";
        case SolverParameters::Method::apgd:
          return "apgd";
        case SolverParameters::Method::apgs:
          return "apgs";
        default:
          return "nlgs";
      }
  }

  /// What one solve achieved.
  struct SolveReport
  {
    unsigned int iterations   = 0; ///< NLGS sweeps done (check passes not included)
    /// Active set: sparse factorisations done (Newton iterations), and whether it fell
    /// back to NLGS (which then reports its sweeps in iterations).
    unsigned int factorizations = 0;
    bool         fell_back      = false;
    /// The law residual after the solve (dem/law_residual.h), max |phi| / mean loaded
    /// impulse: the same measure whatever the method.
    double law_residual = 0;
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
  };

  /// Velocities and inverse masses of the bodies as the solver sees them:
  /// (v_x, v_y, spin) and (1/m, 1/m, 1/I), with 0 for imposed-velocity dofs.
  struct BodyState
  {
    std::vector<Eigen::Vector3d>       velocity;
    std::vector<std::array<double, 3>> inverse_mass;
    /// Velocities of the boundary nodes of a BoundaryBody (2n: x, y per node), m/s,
    /// and its compliance (dem/boundary.h); empty / null without one.
    Eigen::VectorXd        node_velocity;
    const Eigen::MatrixXd *node_compliance = nullptr;

    /// The current velocities and inverse masses of @p system's bodies (no boundary body).
    static BodyState of(const ParticleSystem &system)
    {
      BodyState state;
      for (const auto &b : system.bodies)
        {
          state.velocity.push_back({b.velocity.x(), b.velocity.y(), b.spin});
          state.inverse_mass.push_back(b.inverse_mass());
        }
      return state;
    }

    /// Local velocity of contact @p c from the current body velocities.
    Eigen::Vector2d local_velocity(const Contact &c) const
    {
      if (c.on_boundary())
        return boundary_local_velocity(c);
      const Eigen::Vector3d &v0 = velocity[c.body[0]], &v1 = velocity[c.body[1]];
      const Vec2             t(-c.normal.y(), c.normal.x());
      return {c.normal.dot(v1.head<2>() - v0.head<2>()) + c.arm_n[1] * v1.z() - c.arm_n[0] * v0.z(),
              t.dot(v1.head<2>() - v0.head<2>()) + c.arm_t[1] * v1.z() - c.arm_t[0] * v0.z()};
    }

    /// Apply impulse @p dr of contact @p c: v_1 += M_1^-1 H_1 dr, v_0 -= M_0^-1 H_0 dr.
    void apply_impulse(const Contact &c, const Eigen::Vector2d &dr)
    {
      if (c.on_boundary())
        return apply_boundary_impulse(c, dr);
      const Vec2 t(-c.normal.y(), c.normal.x());
      const Vec2 f = dr.x() * c.normal + dr.y() * t;
      for (int s = 0; s < 2; ++s)
        {
          const double           sign = s == 0 ? -1.0 : 1.0;
          const auto            &im   = inverse_mass[c.body[s]];
          Eigen::Vector3d       &v    = velocity[c.body[s]];
          v.x() += sign * im[0] * f.x();
          v.y() += sign * im[1] * f.y();
          v.z() += sign * im[2] * (c.arm_n[s] * dr.x() + c.arm_t[s] * dr.y());
        }
    }

    /// The own Delassus block of @p c, sum over its two bodies of H^T M^-1 H (for a
    /// half-disc contact: the grain's part plus B^T G_AB B, with B the 4x2 map from
    /// (r_n, r_t) to the impulses -J_A^T f, -J_B^T f on its two nodes, dem/boundary.h).
    Eigen::Matrix2d delassus_block(const Contact &c) const;

    /// Side 0 of a half-disc contact: velocity of the half-disc's material point at the
    /// contact point, J_A v_A + J_B v_B (Contact::node_map), m/s.
    Vec2 half_disc_velocity(const Contact &c) const
    {
      return c.node_map[0] * node_velocity.segment<2>(2 * c.node[0]) +
             c.node_map[1] * node_velocity.segment<2>(2 * c.node[1]);
    }

  private:
    Eigen::Vector2d boundary_local_velocity(const Contact &c) const;
    void            apply_boundary_impulse(const Contact &c, const Eigen::Vector2d &dr);
  };

  /// The solver; it keeps its random generator across steps (reproducible from the seed).
  class NlgsSolver
  {
  public:
    explicit NlgsSolver(const SolverParameters &p = {});
    /// Solve for the impulses of @p contacts (warm-started from their r, whose
    /// effect must already be in @p state), updating @p state. @p theta_h = theta h
    /// turns velocity violations into gap violations for SolverParameters::gap_tolerance.
    SolveReport solve(std::vector<Contact> &contacts, BodyState &state, const ContactLaw &law,
                     double theta_h = 0);

    const SolverParameters &parameters() const { return prm; }
    /// The random generator's state as text (checkpoints), and its restoration.
    std::string random_state() const;
    void        set_random_state(const std::string &state);

  private:
    SolverParameters            prm;
    std::mt19937              rng;
    std::vector<unsigned int> order;
  };
} // namespace tribo::dem
