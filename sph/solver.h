#pragma once
/// @file Solid SPH equations (Maveyraud et al. 1999; Benz and Asphaug 1995) and
/// their second-order Runge-Kutta integrator with adaptive step.
///
/// SI units throughout; 2D is plane strain with masses and forces per metre of
/// depth. Pressure positive in compression, sigma = -P I + S, tension positive.

#include "core/checkpoint.h"
#include "sph/boundary_force.h"
#include "sph/eos.h"
#include "sph/kernel.h"
#include "sph/particles.h"

#include <array>
#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace tribo::sph
{
  /// Time integrators of Solver::step().
  enum class Integrator
  {
    /// Midpoint Runge-Kutta: two evaluations of every rate per step.
    midpoint,
    /// Kick-drift-kick leapfrog: v_{n+1/2} = v_n + dt/2 a_n; rho, S and the stress power
    /// of e from the velocity gradient at the midpoint x_n + dt/2 v_{n+1/2} with velocity
    /// v_{n+1/2}; x_{n+1} = x_n + dt v_{n+1/2}; the forces a_{n+1} at the new state, the
    /// viscosity seeing v_{n+1/2} + dt/2 a_n; v_{n+1} = v_{n+1/2} + dt/2 a_{n+1}; the
    /// viscous heat as the mean of a_n's and a_{n+1}'s. One pass over the pairs for the
    /// forces and one for the velocity gradient per step, the forces reused by the next
    /// step within one advance_to(). Second order; for the elastic waves (v and S) it is
    /// the staggered leapfrog, neutral up to omega dt = 2, where the midpoint rule grows
    /// by (omega dt)^4 / 8 per step unless the viscosity damps it.
    leapfrog
  };

  /// Numerical parameters of the solver.
  struct SolverParameters
  {
    Integrator integrator = Integrator::midpoint;
    double alpha      = 1.0;  ///< Monaghan viscosity, linear term (paper: 1)
    double beta       = 0.1;  ///< Monaghan viscosity, quadratic term (paper: 0.1)
    double av_epsilon = 0.01; ///< eps in mu_ij = h v.r/(r^2 + eps h^2)
    double courant    = 0.3;  ///< C in dt = C h/(c + 1.2 alpha c + beta max mu_ij)
    double acceleration_factor = 0.25; ///< C_a in dt = C_a sqrt(h/|a|)
    double dt_max = std::numeric_limits<double>::infinity(); ///< largest step, s
    double dt_min = 1e-15; ///< step floor, s: a smaller step throws RunError
    double period = 0;     ///< period along x, m (0: not periodic); x wrapped into [0, period)
    BoundaryForce boundary; ///< force between particles of different bodies
    /// Corrected velocity gradient for the stress rate: L_i <- L_i M_i^-1 with
    /// M_i = sum_j (m_j/rho_j)(x_j - x_i) (x) grad_i W_ij (Bonet and Lok 1999),
    /// exact for linear velocity fields also near free surfaces; falls back to
    /// L_i where det M_i < 0.05^dim (M = I with a full
    /// kernel support, ~2^-dim I at a corner). false: the paper's eqs. (20), (24) as written.
    bool corrected_gradient = true;
    /// Verlet skin of the neighbour list, as a fraction of the cut-off c = max(2 h_max,
    /// boundary range): the list holds the pairs within c (1 + skin) and is rebuilt only
    /// when c + 2 max_i |x_i - x_i(at the build)| exceeds that. The rates do not depend on
    /// it (pairs beyond c are skipped); 0 rebuilds at every evaluation.
    double neighbour_skin = 0.1;
    /// Monaghan viscosity also between particles of different bodies (pairs within
    /// 2 h_ij, the same Pi_ij as within a body; its force counts in Rates::boundary_force
    /// and its heat in Rates::viscous_heating). false (default): only the boundary force
    /// acts across bodies. The paper's friction at gamma = 0 rises with alpha, which
    /// points to a viscosity across the interface.
    bool interface_viscosity = false;
    /// A fixed step, s (0: adaptive, dt = min(CFL, acceleration, dt_max)). A fixed step
    /// ignores the stability limits (the paper's typical 5e-8 s); the run stops with a
    /// RunError if it blows up.
    double fixed_step = 0;
  };

  /// Particles whose velocity is imposed (e.g. the top layers moved
  /// horizontally, the bottom layer fixed with velocity 0): v_i = velocity,
  /// dv_i/dt = 0, x_i moves with the imposed velocity. They are not damped.
  /// If @p field is set, the velocity is field(x_i, t) instead (e.g. a rigid
  /// rotation), re-evaluated at each Runge-Kutta stage. Only the components whose
  /// bit is set in @p components are imposed (bit c for component c; e.g. 1: x held,
  /// the others free); particles with some component free are damped.
  template <int dim>
  struct ImposedVelocity
  {
    std::vector<unsigned int> particles;
    Tensor<1, dim>            velocity; ///< m/s
    unsigned int              components = (1u << dim) - 1; ///< imposed components (bit mask)
    std::function<Tensor<1, dim>(const Tensor<1, dim> &x, double t)> field;
    /// false (default): imposed at every Runge-Kutta stage (dv/dt = 0 on the imposed
    /// components). true: imposed only after each step, a velocity reset, the particles
    /// integrated freely within it (an explicit code's reading of "moved with velocity v";
    /// the reset's impulse is the constraint's).
    bool between_steps = false;
    /// Impulse the constraint has supplied (N s; N s/m in 2D), summed over steps: dt times
    /// its force at the step's midpoint (Rates::imposed_force) plus the velocity reset
    /// sum m (v_imposed - v) at the end of each step (e.g. of the damping). The owner
    /// reads and clears it.
    Tensor<1, dim> impulse;
  };

  /// An external force on each listed particle, ramped in time:
  /// F_i(t) = force (1 - exp(-t/tau)) (tau = 0: no ramp). For a pressure P on a
  /// face of area A carried by n particles, force = -P A/n along the outward
  /// normal. Units N (N/m in 2D).
  template <int dim>
  struct ExternalForce
  {
    std::vector<unsigned int> particles;
    Tensor<1, dim>            force; ///< per particle, N
    double                    tau = 0; ///< ramp time, s
  };

  /// Damping of body @p body relative to its centre-of-mass velocity,
  /// f_i = -m_i gamma (v_i - v_cm) (paper's eq. 36), integrated exactly over a
  /// step: v_i <- v_cm + (v_i - v_cm) exp(-gamma dt), which keeps the body's
  /// momentum and sets no step limit. Its heat is not added to e (the paper's
  /// choice: radiated away).
  ///
  /// With @p relative_to_centre_of_mass = false the reference velocity is the
  /// fixed @p reference_velocity instead of v_cm (the paper's section 2.7 form
  /// -m gamma (v - V) with V the sliding velocity); then momentum is not kept.
  struct Damping
  {
    unsigned int          body;
    double                gamma; ///< 1/s
    bool                  relative_to_centre_of_mass = true;
    std::array<double, 3> reference_velocity = {{0, 0, 0}}; ///< m/s (first dim used)
  };

  /// Time derivatives of the state and by-products of one evaluation.
  template <int dim>
  struct Rates
  {
    std::vector<Tensor<1, dim>>          dx;   ///< m/s
    std::vector<Tensor<1, dim>>          dv;   ///< m/s^2
    std::vector<double>                  drho; ///< kg/m^3/s
    std::vector<double>                  de;   ///< J/kg/s
    std::vector<SymmetricTensor<2, dim>> dS;   ///< Pa/s
    std::vector<Tensor<1, dim>> boundary_force; ///< force on i from other bodies, N
    std::vector<double>         pressure;       ///< P_i, Pa
    std::vector<double>         signal;         ///< c_i + 1.2 alpha c_i + beta max_j mu_ij, m/s
    /// The artificial viscosity's share of de_i/dt, sum_j m_j Pi_ij/2 (v_i - v_j).grad_i W_ij, J/kg/s.
    std::vector<double>         viscous_heating;
    /// Leapfrog's velocity-gradient pass only: T_i = sum_j m_j (v_i - v_j) (x) grad_i W_ij
    /// (kg/(m^dim s)), the stress power being de_i/dt = -(sigma_i / rho_i^2) : T_i.
    std::vector<Tensor<2, dim>> velocity_moment;
    /// Per Solver::imposed entry, the force its constraint supplies, -sum_i m_i dv_i over
    /// the imposed components (before they are zeroed), N (N/m in 2D).
    std::vector<Tensor<1, dim>> imposed_force;
  };

  /// The solid SPH model and its integrator. Pairs of particles of the same body
  /// interact through the SPH equations (W the cubic spline with h_ij = (h_i+h_j)/2,
  /// grad_i W_ij its gradient with respect to x_i):
  ///
  /// - continuity: drho_i/dt = sum_j m_j (v_i - v_j).grad_i W_ij
  /// - momentum: dv_i/dt = sum_j m_j (sigma_i/rho_i^2 + sigma_j/rho_j^2 - Pi_ij I).grad_i W_ij
  ///   + (boundary + external forces)/m_i, sigma = -P I + S;
  /// - energy: de_i/dt = sum_j m_j [(v_j - v_i).(sigma_i/rho_i^2).grad_i W_ij
  ///   + Pi_ij/2 (v_i - v_j).grad_i W_ij]; this pairs exactly with the momentum
  ///   equation so that sum m (|v|^2/2 + e) is conserved (e holds the elastic work);
  /// - velocity gradient: L_i^{ab} = sum_j (m_j/rho_j)(v_j^a - v_i^a) grad_i^b W_ij
  ///   (times M_i^-1 if SolverParameters::corrected_gradient), strain rate eps_dot = (L + L^T)/2, spin Omega = (L - L^T)/2;
  /// - Hooke with Jaumann rate: dS/dt = 2G (eps_dot - tr(eps_dot)/3 I) + Omega S - S Omega
  ///   (= S Omega^T + Omega S, the paper's eq. 22). For a rigid rotation with
  ///   angular velocity w (Omega_yx = w), S(t) = Q(wt) S0 Q(wt)^T. In 2D
  ///   (plane strain) tr(eps_dot) is the in-plane trace, and S_zz = -(S_xx + S_yy);
  /// - Monaghan viscosity: for (v_i - v_j).(x_i - x_j) < 0,
  ///   mu_ij = h_ij (v_i - v_j).(x_i - x_j) / (|x_i - x_j|^2 + eps h_ij^2),
  ///   Pi_ij = (-alpha cbar_ij mu_ij + beta mu_ij^2) / rhobar_ij, else 0.
  ///
  /// The sound speed c_i used in the viscosity and the step is the longitudinal
  /// speed sqrt(c_EOS^2 + 4G/(3 rho_i)). Pairs of particles of different bodies
  /// interact only through SolverParameters::boundary.
  ///
  /// All loops gather per particle over a full neighbour list (TBB through
  /// deal.II), so results do not depend on the number of threads.
  template <int dim>
  class Solver
  {
  public:
    Solver(const std::vector<Material> &materials, const SolverParameters &parameters);

    ParticleState<dim>                state;
    double                            time = 0; ///< s
    std::vector<ImposedVelocity<dim>> imposed;
    std::vector<ExternalForce<dim>>   external;
    std::vector<Damping>              damping;

    /// One step of SolverParameters::integrator (midpoint: y* = y + dt/2 f(y, t),
    /// y' = y + dt f(y*, t + dt/2); leapfrog: Integrator::leapfrog), then exact damping
    /// over dt and imposed velocities. dt = min(dt_max, @p dt_limit, CFL, acceleration
    /// steps over all particles), evaluated with the rates at the step's start, or the
    /// fixed step (SolverParameters::fixed_step). Returns dt.
    /// Throws RunError if dt < dt_min (naming the limit and the particles) or if
    /// a rate or the new state holds NaN/Inf or a non-positive density.
    double step(double dt_limit = std::numeric_limits<double>::infinity());
    /// Steps until time reaches @p t_end (the last step is shortened). Returns the
    /// number of steps. The leapfrog reuses each step's end forces as the next one's start
    /// forces (step() evaluates them anew): external forces, imposed velocities and
    /// damping must not change within the call.
    unsigned int advance_to(double t_end);

    /// Evaluates all rates at state @p s and time @p t into @p k. With @p viscosity
    /// false the artificial viscosity is left out (Pi_ij = 0).
    void compute_rates(const ParticleState<dim> &s, double t, Rates<dim> &k, bool viscosity = true);

    /// The largest stable step for rates @p k at state @p s, s; @p limiter is set
    /// to "CFL" or "acceleration" and @p worst to the particles with the smallest
    /// steps (up to 5, smallest first).
    double stable_step(const ParticleState<dim> &s, const Rates<dim> &k, std::string &limiter,
                       std::vector<unsigned int> &worst) const;

    /// The rates of the last force evaluation (midpoint: the ones that advanced the
    /// state; leapfrog: at the step's end): boundary forces for friction
    /// measurements, pressures.
    const Rates<dim> &last_rates() const { return k2; }
    /// Name of the limit that set the last step ("CFL", "acceleration", "dt_max", "dt_limit", "fixed").
    const std::string &last_limiter() const { return limiter; }
    /// The neighbour search (as of the last evaluation): every pair within the cut-off,
    /// and some beyond it (SolverParameters::neighbour_skin).
    const NeighbourSearch<dim> &neighbours() const { return search; }
    /// Neighbour-list builds since construction (the skin saves the others).
    unsigned long n_neighbour_builds() const { return builds; }
    const std::vector<Material> &materials() const { return mats; }
    const SolverParameters &parameters() const { return prm; }

    /// Sum of m (|v|^2/2 + e), J: conserved without damping, boundary or external forces.
    double total_energy() const { return state.kinetic_energy() + state.internal_energy(); }
    /// Kinetic energy removed by the Damping terms since construction, J (>= 0).
    double damping_dissipation() const { return damped_energy; }
    /// Heat the artificial viscosity has put into e since construction, J (>= 0):
    /// sum over steps of dt sum_i m_i viscous_heating_i at the midpoint. It is part of
    /// state.internal_energy(); the rest of that is the elastic work.
    double viscous_heat() const { return heat; }

    /// Checkpoint: what a step carries to the next, bit for bit: the particle state, the
    /// time, the damping terms (a scene may switch them), the damped energy and viscous heat, the last step's
    /// limiter and the neighbour list with the positions it was built at (a list rebuilt at
    /// another time would sum the pairs in another order). The imposed velocities and
    /// external forces are the scene's, rebuilt with it; the step size is not carried (each
    /// step computes its own from the state).
    void save(CheckpointOut &ar) const;
    /// Restore what save() wrote; InputError if the checkpoint holds another number of
    /// particles than this solver (another case).
    void load(CheckpointIn &ar);

    /// "particle i (x = (..), v = (..), rho = ..)" for error messages.
    std::string describe_particle(const ParticleState<dim> &s, unsigned int i) const;

  private:
    /// What an evaluation computes: every rate; the velocity gradient's (drho, dS, dx,
    /// velocity_moment); the forces' (dv, boundary_force, signal, pressure,
    /// imposed_force, the viscous heating in de and viscous_heating).
    enum class Pass
    {
      all,
      kinematics,
      forces
    };
    template <Pass pass>
    void   evaluate(const ParticleState<dim> &s, double t, Rates<dim> &k, bool viscosity = true);
    /// The external forces (ramped by 1 - exp(-t / tau)) added to the accelerations k.dv at
    /// time @p t (s), then the imposed-velocity components' accelerations removed, their
    /// reactions -m dv (N) summed into k.imposed_force, one per ImposedVelocity entry.
    void   add_loads(const ParticleState<dim> &s, double t, Rates<dim> &k) const;
    double midpoint_step(double dt_limit);
    double leapfrog_step(double dt_limit);
    /// The step from rates @p k at the state's start (step()); RunError below dt_min.
    double step_size(const Rates<dim> &k, double dt_limit);
    /// RunError naming the particles whose rates in @p k are not finite.
    void check_rates(const Rates<dim> &k) const;
    /// Damping, time, imposed velocities (counted) and the finiteness check after a step.
    void finish_step(double dt);
    /// Sets the imposed velocity components; with @p count, adds the reset's impulse
    /// sum m (v_imposed - v) to each entry's ImposedVelocity::impulse. At a Runge-Kutta
    /// @p stage the entries imposed only between steps are left alone.
    void apply_imposed(ParticleState<dim> &s, double t, bool count = false, bool stage = false);
    void apply_damping(ParticleState<dim> &s, double dt);
    void check_finite(const ParticleState<dim> &s, const std::string &where) const;

    std::vector<Material> mats;
    SolverParameters      prm;
    NeighbourSearch<dim>  search;
    Rates<dim>            k1, k2;
    ParticleState<dim>    mid;
    std::string           limiter;
    double                damped_energy = 0; ///< J, see damping_dissipation()
    double                heat          = 0; ///< J, see viscous_heat()
    std::vector<Tensor<1, dim>> x_at_build;    ///< positions at the last list build, m
    double                      built_cutoff = 0; ///< the list's cut-off c (1 + skin), m
    unsigned long               builds = 0;
    bool forces_current = false; ///< leapfrog: k2 holds the forces at the current state
    /// Rebuild the neighbour list if a pair within @p cutoff may be missing from it.
    void update_neighbours(const ParticleState<dim> &s, double cutoff);
  };

  /// SPH interpolation at the particles, f~_i = sum_j (m_j/rho_j) f_j W_ij
  /// including j = i, over particles of the same body (neighbour list @p ns must
  /// be built with cut-off >= 2 max h).
  template <int dim>
  std::vector<double> interpolate(const ParticleState<dim> &s, const NeighbourSearch<dim> &ns,
                                   const std::vector<double> &f);
} // namespace tribo::sph
