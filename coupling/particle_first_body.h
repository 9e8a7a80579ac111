#pragma once
/// @file A particle body (SPH or MLP) behind the coupling interface, its contact chain
/// treated implicitly (docs/first_bodies.md, "Implicit chain").
///
/// The chain nodes are the bottom row of particles, ordered by reference x. The body's
/// own integrator is explicit and sub-cycles inside a contact step [t, t + h]; the
/// contact impulse R_i on chain particle i acts on it as the constant force R_i / h over
/// the whole step, so the NSCD solve must know how the chain responds to it:
/// - predict(h): keep the state S_0, advance the body over the step with the top load
///   and no contact force: chain displacements d_free;
/// - compliance: D = d(chain displacements)/d(impulses), the response of the sub-cycled
///   dynamics linearised about S_0, one column per chain particle and direction by finite
///   differences (advance from S_0 with the force eps e / h on that particle; eps = P s h,
///   the impulse a chain particle carries over a step under the load P). For a linear undamped body with
///   modes omega_k, D = sum_k phi_k phi_k^T (1 - cos omega_k h) / (omega_k^2 h): symmetric
///   and positive semi-definite whatever omega_k h, so the solver gets
///   G = sym(D) / (theta h) (-> diag(1 / m_i) when omega h -> 0, the lumped mass);
/// - the velocities the solver sees are those that move the nodes as the Moreau-Jean
///   scheme moves a node, x_1 = x_0 + h ((1 - theta) v_b + theta u): begin velocity
///   v_b = the chain's mean velocity over the last step, d_last / h, free velocity
///   u_free = (d_free / h - (1 - theta) v_b) / theta, so that u = u_free + G R gives the
///   linearised end positions d_free + D R exactly. Only displacements enter: the
///   particles' instantaneous velocities, which a step of several wave crossings samples
///   as noise, would reach the grains through u with the gain (1 - theta) / theta (one at
///   theta = 1/2) and heat the chain; d_free / h as v_b would put every predicted contact
///   as deep into overlap as the unsupported chain falls in half a step
///   (docs/first_bodies.md, "Kinematics");
/// - trial advances on a strip (FirstBodyParameters::prediction_depth > 0): the free
///   prediction and the compliance's columns advance only a copy of the bottom rows within
///   depth wave reaches c_p h of the chain (advance_strip()), the rows above them within
///   the interaction's reach held at their start velocities; nothing from those rows reaches
///   the chain within the step but the numerical precursor (at depth 3, 1e-13 mlp and 5e-7
///   sph of the free velocities), and the engine stays at S_0 (docs/first_bodies.md);
/// - finalize(R): restore S_0 and advance the real nonlinear body with the forces
///   R_i / h on the chain (kept as is when every R_i = 0). The chain's end velocities
///   reported are u = (d / h - (1 - theta) v_b) / theta with the real displacements d.
/// - secant update: after each step with contacts, sym(D) (= theta h G) moves towards the
///   step's secant, the real response d - d_free to the impulses R, by the
///   Powell-symmetric-Broyden correction, the smallest symmetric change with D R = d - d_free,
///       D += omega [(e R^T + R e^T) / (R.R) - (e.R) R R^T / (R.R)^2],  e = d - d_free - D R,
///   relaxed by omega = secant_relaxation, and clipped to its positive semi-definite part.
///   It follows the body's state and its nonlinear (sph: one-sided viscous) response along
///   the loaded directions without advancing the body: on the sph shear cell the miss falls
///   from 10 % with a rebuild every 100 steps to 4 % without rebuilds (docs/first_bodies.md).
///   If the running mean of the miss (relative to the contact response |D R|) passes
///   compliance_tolerance, the next step rebuilds D; a new step size and the end of the
///   compaction damping (start_shearing()) do too.
/// Energy: the force R_i / h does the work R_i . d_i / h on the body; the solver books
/// R_i . (v_b + u_i) / 2, which is the same at theta = 1/2; impulse_extra_power() carries
/// the difference otherwise. The body's books then close to its integrator's error.

#include "coupling/deformable_body.h"

#include <string>
#include <vector>

namespace tribo::coupling
{
  class ParticleFirstBody : public DeformableBody
  {
  public:
    /// Displacement of a free chain particle by the compliance probe of an unloaded body
    /// (P = 0), in spacings; a loaded body is probed with P s h.
    static constexpr double compliance_probe = 1e-5;
    /// Relaxation omega of the secant update of the compliance after every step with
    /// contacts (file comment): the update averages the secants of about 1 / omega steps.
    static constexpr double secant_relaxation = 0.25;
    /// Running mean of the miss of the linearised chain displacements, relative to the
    /// contact response max_i |(D R)_i|, over about miss_memory steps with contacts
    /// (an exponential mean, zero at a build), above which D is rebuilt. A build costs
    /// 2 n_nodes() advances; the sph body's response is not linear even for a small
    /// impulse (its artificial viscosity acts on approaching pairs only), so single
    /// steps miss by up to 20 % whatever the compliance (docs/first_bodies.md).
    static constexpr double        compliance_tolerance = 0.1;
    static constexpr unsigned long miss_memory          = 100;

    unsigned int n_nodes() const override { return chain.size(); }
    /// Position of chain particle i at the start of the step, unwrapped along x
    /// (within half a period of its reference abscissa), m.
    dem::Vec2 node_position(unsigned int i) const override { return start[i]; }
    /// Between predict() and finalize(): the chain particle's velocity at the start of the
    /// step, v_b; otherwise the end velocity u of the last step (file comment), m/s.
    dem::Vec2 node_velocity(unsigned int i) const override { return in_step ? begin_velocity[i] : end_velocity[i]; }
    void      predict(double h) override;
    dem::Vec2 node_free_velocity(unsigned int i) const override { return free[i]; }
    /// sym(D) / (theta h) over the chain, m/s per N s/m.
    const Eigen::MatrixXd &compliance() const override { return G; }
    void   finalize(const std::vector<dem::Vec2> &impulses) override;
    /// Work of the top load over the last step / h, W/m.
    double external_power() const override { return step_h > 0 ? load_work / step_h : 0.0; }
    /// Energy removed by damping over the last step / h, W/m.
    double internal_dissipation() const override { return step_h > 0 ? dissipated / step_h : 0.0; }
    /// Work of the contact forces beyond what the solver books, / h, W/m.
    double impulse_extra_power() const override { return step_h > 0 ? extra_work / step_h : 0.0; }
    double mean_bottom_y() const override;
    double mean_bottom_vy() const override;
    double kinetic_energy() const override;
    /// The body's state and the coupling's (compliance, step, last step's books).
    void save(CheckpointOut &ar) const final;
    void load(CheckpointIn &ar) final;
    /// Drops the compaction damping (the scene calls it at every shearing step); the
    /// compliance is rebuilt at the next step if there was damping to drop.
    void start_shearing() final;
    /// upper_body_steps, upper_body_compliance_builds, upper_body_linearisation_miss_max
    /// and _mean (linearisation_error() over the steps with contacts),
    /// upper_body_compliance_asymmetry (last build), upper_body_response_ratio (the real
    /// body's displacement under the impulses against the predicted one, in work).
    void summarize(JsonObject &j) const override;

    /// Sub-steps of the last real advance.
    unsigned int last_substeps() const { return substeps; }
    /// Compliance builds since construction (each costs 2 n_nodes() advances).
    unsigned long compliance_builds() const { return builds; }
    /// Miss of the last step's linearised chain displacements relative to the contact
    /// response (0 without contacts).
    double linearisation_error() const { return last_miss; }
    /// ||D - D^T|| / ||D|| of the last build (Frobenius norms).
    double compliance_asymmetry() const { return asymmetry; }

  protected:
    /// Engine hooks. Particle index p, all particles of the engine.
    virtual unsigned int n_particles() const                          = 0;
    virtual dem::Vec2    position(unsigned int p) const               = 0; ///< m, wrapped
    virtual dem::Vec2    velocity(unsigned int p) const               = 0; ///< m/s
    virtual double       mass(unsigned int p) const                   = 0; ///< kg/m
    /// Advance the body by @p h (s) with the force (0, @p load) N/m on each top particle
    /// and @p chain_force[i] (N/m) on chain particle i, both constant over the step;
    /// returns the number of sub-steps.
    virtual unsigned int advance(double h, double load, const std::vector<dem::Vec2> &chain_force) = 0;
    /// Energy removed by damping (and, sph, the artificial viscosity's heat) since the start, J/m.
    virtual double total_dissipation() const = 0;
    /// The engine's whole state (what a step carries to the next), for checkpoints and
    /// for the restarts from S_0 within a step.
    virtual void save_engine(CheckpointOut &ar) const = 0;
    virtual void load_engine(CheckpointIn &ar)        = 0;
    /// Drop the engine's compaction damping; false if it had none (left).
    virtual bool stop_damping() = 0;
    /// The trial advances of a step (the free prediction and the compliance's columns) on
    /// the body's bottom rows alone (FirstBodyParameters::prediction_depth): from the
    /// engine's current state, which it leaves unchanged, advance a copy of the rows within
    /// that depth, the row above them carried at its start velocity, by @p h with
    /// @p chain_force[i] (N/m) on chain particle i; @p chain_position[i] gets its end
    /// position (m, wrapped). False when the engine has no such strip (the depth is 0 or
    /// reaches the top): the whole body is advanced instead.
    virtual bool advance_strip(double /*h*/, const std::vector<dem::Vec2> & /*chain_force*/,
                               std::vector<dem::Vec2> & /*chain_position*/)
    {
      return false;
    }

    /// To be called by the engine's constructor once its particles exist: the chain
    /// (bottom row, any order) and the loaded top row.
    void set_rows(const std::vector<unsigned int> &bottom, const std::vector<unsigned int> &top_row);

    FirstBodyParameters prm;
    std::vector<unsigned int> chain, top; ///< particle indices
    explicit ParticleFirstBody(const FirstBodyParameters &p) : prm(p) {}

  private:
    /// Chain particle i at @p x (wrapped), unwrapped near its reference x.
    dem::Vec2 unwrapped(unsigned int i, dem::Vec2 x) const;
    dem::Vec2 unwrapped(unsigned int i) const { return unwrapped(i, position(chain[i])); }
    /// Chain displacements since the start of the step, flattened (2i: x, 2i + 1: y), m.
    Eigen::VectorXd chain_displacement() const;
    /// The chain displacements of a trial advance from S_0 by @p h with @p force on the
    /// chain: on the engine's strip (advance_strip(), the engine stays at S_0), else the
    /// whole body (restored to S_0 first if it has left it).
    Eigen::VectorXd trial_displacement(double h, double load, const std::vector<dem::Vec2> &force);
    /// Top load per top particle at mid-step, N/m (compressive: < 0).
    double top_load(double h) const;
    /// D by finite differences from the saved state; leaves the engine off S_0's step.
    void build_compliance(double h, double load);
    /// The positive semi-definite part of sym(@p D) (negative eigenvalues set to zero).
    static Eigen::MatrixXd positive_part(const Eigen::MatrixXd &D);
    std::string snapshot() const;
    void        restore(const std::string &state);

    double                 time = 0;           ///< s, start of the next step
    std::vector<double>    reference_x;        ///< of the chain, increasing
    std::vector<dem::Vec2> start, free;        ///< chain start positions, free velocities
    std::vector<dem::Vec2> begin_velocity, end_velocity; ///< v_b, u (file comment)
    std::vector<dem::Vec2> mean_velocity; ///< chain displacements of the last step / h, m/s
    std::vector<double>    top_start_y;        ///< top-row y at the start of the step, m
    Eigen::VectorXd        free_displacement;  ///< d_free, m
    Eigen::MatrixXd        G;
    std::string            start_state;        ///< S_0 (save_engine()), taken before the whole body first leaves it
    bool                   in_step = false;    ///< between predict() and finalize()
    bool                   engine_free = false; ///< the engine holds the free end state
    bool                   engine_at_start = false; ///< the engine holds S_0 (trials on its strip)
    std::vector<dem::Vec2> strip_chain;         ///< chain end positions of a strip trial, m
    bool                   stale = true;        ///< rebuild G at the next predict()
    double                 compliance_h = 0;    ///< step G was built for, s
    double                 step_h = 0, step_load = 0, load_work = 0, dissipated = 0, extra_work = 0;
    double                 dissipation_at_start = 0;
    double                 last_miss = 0, worst_miss = 0, miss_sum = 0, asymmetry = 0;
    double                 recent_miss = 0; ///< running mean of the miss (miss_memory)
    /// sum over steps of R . (d - d_free) and R . D R, J/m x h: their ratio says whether
    /// the real body yields more (> 1) or less than the compliance predicted.
    double                 real_response_work = 0, predicted_response_work = 0;
    unsigned long          builds = 0, steps = 0, steps_with_contacts = 0;
    unsigned int           substeps = 0;
  };
} // namespace tribo::coupling
