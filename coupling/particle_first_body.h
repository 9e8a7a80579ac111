#pragma once
/// @file An explicit particle body (SPH or MLP) behind the coupling interface.
///
/// Coupling scheme (../shared/DESIGN.md section 3: boundary particles as contact sites
/// with their lumped mass, sub-cycling of the explicit steps inside a contact step):
/// - the chain nodes are the bottom row of particles, ordered by reference x;
/// - predict(h) keeps the start positions, then advances the whole body over [t, t + h]
///   with its own explicit integrator (several sub-steps, the top load applied) and no
///   contact force: the end velocities of the chain particles are the free velocities;
/// - the compliance is the lumped mass, G = diag(1/m_i): within one contact step an
///   impulse moves only the particle it hits (the explicit body propagates it later);
/// - finalize(R) kicks the chain particles at the end of the step as the Moreau-Jean
///   scheme moves a node, v_i <- v_free,i + R_i / m_i and x_i <- x_i + theta h R_i / m_i
///   (for theta = 1/2 what a constant force R_i / h over the step does to a free
///   particle). Without the position term a chain that carries the pressure sinks into
///   the grains by a h^2 / 2 per step (a = P s / m: 1.5e-8 m per step for steel at
///   100 MPa, s = 2 um, h = 2 ns).
/// Energy: the kick does the work R_i . (v_free,i + v_i) / 2, which the solver books
/// with node_velocity() = v_free at the start of the NLGS and v_i after finalize();
/// the position term changes the stored energy (mlp: the potential; sph: the elastic
/// work of the stresses on the displacement, sph::Solver::displace()), reported as
/// impulse_extra_power() and booked with the contact power. An sph body whose density
/// did not see the position term thinned geometrically at theta h P / (rho s) while its
/// pressure stayed (0.50 m/s measured against 0.48 predicted on the unit test's column).
/// With the sub-cycle's own energy error (RK2, Verlet) the body's balance then closes. A chain particle held up by a contact oscillates
/// within a step (its neighbours accelerate it, the contact stops it): the contacts
/// dissipate about (P s h)^2 / (2 m) per chain particle and step, a coupling loss
/// that shrinks with h^2 / m (docs/first_bodies.md gives the measured figure).

#include "coupling/first_body.h"

#include <vector>

namespace tribo::coupling
{
  class ParticleFirstBody : public FirstBody
  {
  public:
    unsigned int n_nodes() const override { return chain.size(); }
    /// Position of chain particle i at the start of the step, unwrapped along x
    /// (within half a period of its reference abscissa), m.
    dem::Vec2 node_position(unsigned int i) const override { return start[i]; }
    /// Current velocity of chain particle i: v_free after predict(), the end velocity
    /// after finalize(), m/s.
    dem::Vec2 node_velocity(unsigned int i) const override { return velocity(chain[i]); }
    void      predict(double h) override;
    dem::Vec2 node_free_velocity(unsigned int i) const override { return free[i]; }
    /// diag(1/m_i) over the chain, m/s per N s/m.
    const Eigen::MatrixXd &compliance() const override { return G; }
    void   finalize(const std::vector<dem::Vec2> &impulses) override;
    /// Work of the top load over the last step / h, W/m.
    double external_power() const override { return step_h > 0 ? load_work / step_h : 0.0; }
    /// Energy removed by the compaction damping over the last step / h, W/m.
    double internal_dissipation() const override { return step_h > 0 ? dissipated / step_h : 0.0; }
    /// Stored-energy change of finalize()'s position term / h, W/m.
    double impulse_extra_power() const override { return step_h > 0 ? correction_work / step_h : 0.0; }
    double mean_bottom_y() const override;
    double mean_bottom_vy() const override;
    double kinetic_energy() const override;
    /// Sub-steps of the last predict().
    unsigned int last_substeps() const { return substeps; }
    /// For the overlap guard: the chain's c_p h / s at step @p h (s) and, above half the
    /// coupling limit, the step at half of it (particle_coupling_courant / 2).
    std::string overlap_hint(double h) const override;

  protected:
    /// Engine hooks. Particle index p, all particles of the engine.
    virtual unsigned int n_particles() const                          = 0;
    virtual dem::Vec2    position(unsigned int p) const               = 0; ///< m, wrapped
    virtual dem::Vec2    velocity(unsigned int p) const               = 0; ///< m/s
    virtual double       mass(unsigned int p) const                   = 0; ///< kg/m
    /// v_p += dv_q, x_p += dx_q (wrapped into the period) for each p = @p p[q]; the
    /// engine's state variables must follow the position change (sph: density, stress
    /// and internal energy; mlp: its forces are functions of the positions).
    virtual void kick(const std::vector<unsigned int> &p, const std::vector<dem::Vec2> &dv,
                      const std::vector<dem::Vec2> &dx) = 0;
    /// Set the force on each top particle to (0, @p load) N/m, advance the body by
    /// @p h (s) and return the number of sub-steps.
    virtual unsigned int advance(double h, double load) = 0;
    /// Energy removed by damping since the start, J/m.
    virtual double total_dissipation() const = 0;

    /// To be called by the engine's constructor once its particles exist: the chain
    /// (bottom row, any order) and the loaded top row.
    void set_rows(const std::vector<unsigned int> &bottom, const std::vector<unsigned int> &top_row);

    /// The checkpointed state of this class (time, chain start positions are rebuilt).
    void save_base(CheckpointOut &ar) const;
    void load_base(CheckpointIn &ar);

    FirstBodyParameters prm;
    double              time = 0; ///< s, start of the next step
    std::vector<unsigned int> chain, top; ///< particle indices
    explicit ParticleFirstBody(const FirstBodyParameters &p) : prm(p) {}

  private:
    dem::Vec2 unwrapped(unsigned int i) const; ///< chain particle i, near its reference x
    void      build_compliance(double h);

    std::vector<double>    reference_x;       ///< of the chain, increasing
    std::vector<dem::Vec2> start, free;       ///< chain start positions, free velocities
    std::vector<double>    top_start_y;       ///< top-row y at the start of the step
    Eigen::MatrixXd        G;
    double                 compliance_h = 0; ///< step G was built for, s
    double                 step_h = 0, load_work = 0, dissipated = 0, correction_work = 0;
    unsigned int           substeps = 0;
  };
} // namespace tribo::coupling
