#pragma once
/// @file A plane-strain linear-elastic first body discretised with deal.II
/// (Cao, Renouf, Dubois, Berthier 2011, eq. 6), advanced by the Moreau-Jean theta
/// scheme, with the condensed compliance of its bottom face for the NSCD solver.
///
/// Units (2D, per unit depth): lengths m, time s, masses kg/m, forces N/m,
/// impulses N s/m, energies J/m, powers W/m, stresses Pa. Stresses are positive
/// in tension (the top pressure P gives sigma_yy = -P). The body knows nothing
/// about contact: the solver sees it only through its bottom (contact) nodes.
///
/// This header does not include deal.II (pimpl): non-deal.II code can use it.
///
/// ## Discrete equations
/// Nodal displacement u (m) and velocity v (m/s) on a Q_p Lagrange mesh of
/// [0, L] x [y0, y0 + H], periodic in x; consistent mass M, stiffness K
/// (plane strain, lambda = E nu / ((1 + nu)(1 - 2 nu)), mu = E / (2 (1 + nu))),
/// Rayleigh damping C = a M + b K, external load f(t) (the traction (0, -P(t))
/// on the top face), nodal contact impulses R on the bottom nodes:
///
///     M (v_end - v) + h C v_theta + h K u_theta = h f(t + theta h) + R
///     v_theta = theta v_end + (1 - theta) v,   u_theta = u + theta h v_theta
///     u_end = u + h v_theta
///
/// i.e. with the iteration matrix Mt = M + theta h C + theta^2 h^2 K,
///
///     Mt v_free = (M - h (1 - theta) C - h^2 theta (1 - theta) K) v - h K u + h f
///     v_end     = v_free + Mt^-1 R
///     u_end     = u + h (theta v_end + (1 - theta) v).
///
/// All vectors satisfy the constraints (x-periodicity, and u_x = v_x = 0 on the top
/// face when `top_fixed_in_x`); the matrices are condensed on them (an impulse on a
/// constrained node is a load on its master dofs). Mt is factorised once per step size.
///
/// Energy: with theta = 1/2 the scheme conserves, to round-off,
///     E_kin + E_el + (damping dissipation) - (work of the load) - (work of the impulses),
/// with per-step works h f.vbar, h vbar.C v_theta and R.vbar, vbar = (v + v_end)/2.
/// theta > 1/2 adds numerical dissipation (not reported).

#include "core/checkpoint.h"

#include <Eigen/Core>

#include <memory>
#include <string>
#include <vector>

namespace tribo::fem
{
  /// Geometry, material, loading and time-integration parameters (SI units).
  struct ElasticBodyParameters
  {
    double length    = 1e-4;   ///< L (m): the period along x
    double thickness = 1.5e-4; ///< H (m)
    double bottom    = 0;      ///< y0 (m): the bottom face, which touches the grains

    double youngs_modulus = 100e9; ///< E (Pa)
    double poisson_ratio  = 0.33;  ///< nu, in (-1, 1/2)
    double density        = 7800;  ///< rho (kg/m^3)

    unsigned int cells_x = 104; ///< cells along x (= number of bottom contact nodes)
    unsigned int cells_y = 156; ///< cells along y
    unsigned int degree  = 1;   ///< p of the Q_p Lagrange element (2 components)

    double rayleigh_mass      = 0; ///< a (1/s) in C = a M + b K
    double rayleigh_stiffness = 0; ///< b (s) in C = a M + b K

    double theta     = 0.5;  ///< in [1/2, 1]
    double time_step = 1e-8; ///< h (s)

    /// P (Pa): traction (0, -P) on the top face, compressive for P > 0.
    double top_pressure = 0;
    /// P(t) = P min(1, t / ramp) if ramp > 0, else P for t >= 0 (a step), s.
    double pressure_ramp_time = 0;
    /// Dirichlet u_x = v_x = 0 on the top face: the body is held in x, as the rigid
    /// upper wall is. Otherwise only the x-periodicity constrains x.
    bool top_fixed_in_x = true;

    /// Direct solver for Mt: "cholmod" (SuiteSparse CHOLMOD, Cholesky, the faster one
    /// here, docs/fem.md) or "umfpack" (deal.II's SparseDirectUMFPACK, LU).
    std::string solver = "cholmod";

    /// Craig-Bampton reduction of the body onto its bottom contact nodes: u = T q with
    /// q = (u_b, eta, zeta) and T = [I 0 0; Psi Phi X]: the 2n constraint modes
    /// Psi = -K_ii^-1 K_ib (static shapes of unit boundary displacements), the @p modes
    /// lowest fixed-interface modes Phi (K_ii phi = omega^2 M_ii phi, boundary fixed,
    /// M-orthonormal, by ARPACK in shift-invert mode through deal.II) and one load mode
    /// X = K_ii^-1 f_i (the interior's static response to the top pressure with the
    /// boundary fixed, M-orthogonal to Phi). M, K and f become T^T M T, T^T K T, T^T f
    /// and the theta scheme runs on q (2n + modes + 1 unknowns): exact in the static
    /// limit (Guyan condensation plus the load mode), an approximation of the dynamics
    /// above the highest kept mode. Fields are rebuilt as T q for output.
    bool         reduced = false;
    unsigned int modes   = 20;
  };

  /// The deformable first body. Protocol of one step of size h:
  /// predict(); read boundary_free_velocity() and boundary_compliance(); solve the
  /// contacts; finalize(R). The state (u, v) is then the end of the step, time() has
  /// advanced by h, and the measurements describe that step.
  ///
  /// Contact nodes: the vertices of the bottom face y = y0, node i at reference
  /// x_i = i L / cells_x for i = 0 .. cells_x - 1 (the vertex at x = L is the periodic
  /// image of node 0); node i and node (i + 1) % n end bottom edge i. For degree > 1
  /// only the vertex nodes are contact nodes.
  class ElasticBody
  {
  public:
    /// Builds the mesh, assembles M, K, the unit load and Mt, factorises Mt.
    /// Initial state u = v = 0, t = 0. Throws tribo::InputError on bad parameters.
    explicit ElasticBody(const ElasticBodyParameters &parameters);
    ~ElasticBody();
    ElasticBody(ElasticBody &&) noexcept;
    ElasticBody &operator=(ElasticBody &&) noexcept;

    const ElasticBodyParameters &parameters() const;
    unsigned int n_dofs() const;   ///< number of dofs of the mesh, constrained ones included
    /// Unknowns of the time integration: n_dofs() for the full model, 2n + modes + 1
    /// for the reduced one.
    unsigned int n_model_dofs() const;
    /// Reduced model: the angular frequencies omega (rad/s) of the kept fixed-interface
    /// modes, increasing; empty for the full model.
    const std::vector<double> &mode_frequencies() const;
    double lame_lambda() const;    ///< lambda (Pa)
    double shear_modulus() const;  ///< mu (Pa)
    double time() const;           ///< t (s) at the start of the next step
    double time_step() const;      ///< h (s)
    /// Wall time of the constructor's assembly of M, K and the unit load (cells
    /// integrated concurrently through deal.II's WorkStream), s.
    double assembly_seconds() const;
    double pressure(double t) const; ///< P(t) (Pa), ramp included

    /// Change h (s); only if h changes: refactorises Mt, drops the cached compliance and
    /// the free velocity (call predict() again). Throws tribo::InputError for h <= 0.
    void set_time_step(double h);

    /// Change the Rayleigh coefficients a (1/s) and b (s) of C = a M + b K; only if they
    /// change: refactorises Mt and drops the cached compliance and free velocity.
    /// Throws tribo::InputError for negative values.
    void set_damping(double a, double b);

    /// Compute and keep the free velocity v_free of the step [t, t + h] (no impulse).
    void predict();
    /// Complete the step with nodal impulses (N s/m, on the body, one per bottom node,
    /// or an empty vector for none): v_end = v_free + Mt^-1 R (one solve),
    /// u_end = u + h (theta v_end + (1 - theta) v), t += h. Throws tribo::RunError if
    /// predict() was not called for this step or the size is wrong.
    void finalize(const std::vector<Eigen::Vector2d> &boundary_impulses);

    /// @name Bottom contact nodes
    /// @{
    unsigned int n_boundary_nodes() const; ///< n = cells_x
    /// Reference position (x_i, y0) of node i, m.
    Eigen::Vector2d boundary_position(unsigned int i) const;
    /// Displacement of node i at the start of the step (end of the last), m.
    Eigen::Vector2d boundary_displacement(unsigned int i) const;
    /// Free velocity of node i, m/s (valid after predict()).
    Eigen::Vector2d boundary_free_velocity(unsigned int i) const;
    /// Velocity of node i at the end of the last step (start of the next), m/s.
    Eigen::Vector2d boundary_velocity(unsigned int i) const;
    /// G = Z_b^T Mt^-1 Z_b (2n x 2n, m/s per N s/m, symmetric positive definite):
    /// bottom impulses R change the bottom velocities by G R, exactly as finalize()
    /// does. Index 2i is x and 2i + 1 is y of node i. Computed on first use after each
    /// factorisation (2n solves), then cached.
    const Eigen::MatrixXd &boundary_compliance() const;
    /// @}

    /// @name Energies and measurements (per unit depth)
    /// @{
    double kinetic_energy() const; ///< 1/2 v.M v at the current state, J/m
    double elastic_energy() const; ///< 1/2 u.K u at the current state, J/m
    /// Power of the top load over the last step, f(t + theta h).vbar, W/m
    /// (> 0 when the load does work on the body).
    double load_power() const;
    /// Power of the contact impulses over the last step, sum_i R_i.vbar_i / h, W/m.
    double contact_power() const;
    /// Power dissipated by the Rayleigh damping over the last step, vbar.C v_theta, W/m.
    double damping_power() const;
    double load_work() const;           ///< sum over steps of h load_power(), J/m
    double contact_work() const;        ///< sum over steps of h contact_power(), J/m
    double damping_dissipation() const; ///< sum over steps of h damping_power(), J/m
    /// Mean of u_y over the bottom contact nodes at the current state, m.
    double mean_bottom_displacement_y() const;
    /// Displacement (m), velocity (m/s) and small strain at a point of the reference
    /// domain (a cell search: for tests and probes, not for inner loops).
    Eigen::Vector2d displacement_at(const Eigen::Vector2d &point) const;
    Eigen::Vector2d velocity_at(const Eigen::Vector2d &point) const;
    Eigen::Matrix2d strain_at(const Eigen::Vector2d &point) const;
    /// @}

    /// Static equilibrium K u = f for the full pressure P, with the step's
    /// constraints plus u_y = 0 on the bottom face (a roller, which removes the rigid
    /// y-translation) and, if the top is free in x, u_x = 0 at node 0. Sets u to it
    /// and v = 0 (time unchanged); the reduced model takes the M-orthogonal projection
    /// of the full solution onto T, which holds it exactly. For tests and initial states.
    void static_solve();

    /// Write displacement, velocity (point data) and per-cell averages of sigma_xx,
    /// sigma_yy, sigma_xy, sigma_zz = nu (sigma_xx + sigma_yy) and von Mises (Pa) on
    /// the reference mesh, atomically (a temporary file, then a rename).
    void write_vtu(const std::string &filename) const;

    /// Checkpoint: displacement, velocity, time, the Rayleigh coefficients in force and
    /// the accumulated works. load() refactorises if the coefficients differ from the
    /// constructed body's (e.g. compaction damping removed at Shear start).
    void save(CheckpointOut &ar) const;
    void load(CheckpointIn &ar);

  private:
    struct Impl;
    std::unique_ptr<Impl> impl;
  };
} // namespace tribo::fem
