#pragma once
/// @file The MLP pair interaction: a central two-point potential U(r) plus the
/// "return forces" that turn each bond towards the nearest lattice axis
/// (Popov and Filippov 2006, eqs. 12-18), and the force field that evaluates
/// them over a neighbour list.
///
/// Sign conventions. For a pair (i, j) the bond vector is d = x_j - x_i (nearest
/// periodic image), r = |d|, and phi = atan2(d_y, d_x) is the angle of the
/// neighbour j seen from i, counter-clockwise from +x. All pair functions return
/// the force ON i (N/m); the force on j is its exact negative (the pair
/// function is odd in d), so every pair adds zero to the total force. The
/// return forces are not central: pairs exert torques, and the total angular
/// momentum is not conserved (the lattice axes are fixed in the lab frame).

#include "mlp/neighbour_list.h"
#include "mlp/particles.h"

#include <cmath>
#include <Eigen/Core>

#include <vector>

namespace tribo::mlp
{
  /// Which return force is used.
  enum class ReturnForceForm
  {
    /// Paper eq. (18): F_i = f0 sin(n phi) (-sin phi, cos phi), magnitude
    /// independent of r. It derives from no potential (its curl in d-space is
    /// f0 sin(n phi)/r), so no energy is defined for it.
    paper,
    /// Conservative variant: V(r, phi) = (f0 r0 / n)(1 - cos(n phi)), giving
    /// F_i = (r0/r) f0 sin(n phi) (-sin phi, cos phi). Equal to the paper form at
    /// r = r0, hence the same linear theory.
    potential
  };

  /// Parameters of the MLP interaction (2D, per unit depth).
  struct InteractionParameters
  {
    double r0        = 1e-6; ///< equilibrium distance of U, = lattice spacing c, m
    double stiffness = 1e9;  ///< k_c = U''(r0), bond stiffness per unit depth, N/m^2 = Pa
    double width     = 7;    ///< Morse a r0 (dimensionless); larger = narrower well
    double switch_start = 1.2;  ///< r_s / r0: U and the return force are switched off
    double cutoff       = 1.35; ///< r_c / r0: proximity radius (< sqrt(3) for hexagonal,
                                ///< < sqrt(2) for square lattices: nearest neighbours only)
    unsigned int    n    = 6;   ///< lattice symmetry: 6 (hexagonal) or 4 (square)
    double          f0   = 0;   ///< return force amplitude, N/m
    ReturnForceForm form = ReturnForceForm::paper;

    /// Throws InputError naming the offending entry.
    void validate() const;
  };

  /// The central pair potential: a Morse potential switched off smoothly,
  ///   U(r) = D [(1 - exp(-a (r - r0)))^2 - 1] S(r),
  /// with a = width / r0, D = k_c / (2 a^2) (so that U''(r0) = k_c and U(r0) = -D),
  /// and the C1 switch S = 1 for r <= r_s, S = 1 - 3x^2 + 2x^3 with
  /// x = (r - r_s)/(r_c - r_s) for r_s < r < r_c, S = 0 beyond r_c.
  /// Units: r in m, U in J/m (per unit depth).
  class PairPotential
  {
  public:
    /// From the interaction parameters (validated).
    explicit PairPotential(const InteractionParameters &p);

    /// U(r), J/m.
    double energy(double r) const;
    /// dU/dr, N/m: positive when the pair attracts (r > r0 inside the well).
    double derivative(double r) const;
    /// Switch S(r) and its derivative dS/dr (1/m) in @p dsdr.
    double switch_value(double r, double &dsdr) const;
    /// The unswitched Morse well U_M(r) = D ((1 - e)^2 - 1), J/m, with
    /// e = exp(-a (r - r0)) in @p e.
    double morse_well(double r, double &e) const
    {
      e = std::exp(-a * (r - r0));
      return D * ((1 - e) * (1 - e) - 1);
    }
    /// Well depth D, J/m.
    double depth() const { return D; }
    /// Cutoff radius r_c, m.
    double cutoff() const { return r_c; }

  private:
    double r0, a, D, r_s, r_c;
  };

  /// The full pair interaction: central force from U plus the return force.
  class Interaction
  {
  public:
    /// Validates @p p (InputError on bad values).
    explicit Interaction(const InteractionParameters &p);

    /// Central force on i, N/m: F_i = U'(r) d / r (towards j when U' > 0).
    Vec2 central_force(const Vec2 &d) const;
    /// Return force on i, N/m (see ReturnForceForm), times the switch S(r):
    ///   F_i = g(r) f0 sin(n phi) (-sin phi, cos phi),  g = S (paper) or (r0/r) S
    /// (potential form, which adds the radial term (f0 r0/n)(1 - cos n phi) S'(r) d/r
    /// = -dV/dx_i from the switch, non-zero only for r_s < r < r_c). It vanishes on every axis phi = k pi/n and pushes i
    /// along +e_phi when sin(n phi) > 0, which decreases phi: it turns the bond
    /// back to the nearest axis phi = 2 k pi/n (stable); phi = (2k+1) pi/n are
    /// unstable equilibria (the sector boundaries of the paper's Fig. 1).
    Vec2 return_force(const Vec2 &d) const;
    /// central_force + return_force, N/m; zero for r >= r_c.
    Vec2 force(const Vec2 &d) const;
    /// U(r) plus, for the potential form, V(r, phi) S(r); J/m. The paper form of
    /// the return force has no energy.
    double energy(const Vec2 &d) const;

    /// Linearised transverse bond stiffness k_t = n f0 / r0, N/m^2.
    double transverse_stiffness() const { return prm.n * prm.f0 / prm.r0; }
    /// Paper eq. (2) constants of the linearised bond: k1 = k_t (full relative
    /// displacement), k2 = k_c - k_t (projection on the bond), N/m^2.
    double k1() const { return transverse_stiffness(); }
    /// See k1().
    double k2() const { return prm.stiffness - transverse_stiffness(); }
    /// The parameters.
    const InteractionParameters &parameters() const { return prm; }
    /// The central potential.
    const PairPotential &potential() const { return pot; }
    /// Cutoff radius r_c, m.
    double cutoff() const { return pot.cutoff(); }

  private:
    InteractionParameters prm;
    PairPotential         pot;
  };

  /// Evaluates the interaction forces of all particles over a Verlet list.
  ///
  /// Two passes, both deterministic and free of write races: (1) each pair
  /// force is computed once and stored in its own slot, (2) each particle sums
  /// the forces of its pairs in a fixed order (gather). Both passes run in
  /// parallel with deal.II's TBB wrappers when enabled; the result is
  /// bitwise identical for any number of threads.
  class ForceField
  {
  public:
    /// @p skin is the Verlet skin in m (default 0.3 r0 when negative).
    ForceField(const InteractionParameters &p, double skin = -1);

    /// particles.force = interaction forces + external_force, N/m. Updates the
    /// neighbour list first when needed.
    void compute(Particles &particles, const Box &box);
    /// Total potential energy sum_pairs energy(d), J/m (the paper form of the
    /// return force contributes nothing).
    double potential_energy(const Particles &particles, const Box &box);
    /// Virial stress of the pair forces, Pa:
    ///   sigma_ab = (1/A) sum_pairs F_a d_b,  F = force on i, d = x_j - x_i,
    /// tension positive; first index = force component, second = bond (normal)
    /// component, so the traction on a cut with normal n is sigma n. Not
    /// symmetric when f0 != 0. @p area is the area the particles fill, m^2.
    Eigen::Matrix2d virial_stress(const Particles &particles, const Box &box, double area);

    /// Use the TBB-parallel passes (default true).
    void set_parallel(bool on) { parallel = on; }
    /// The interaction.
    const Interaction &interaction() const { return model; }
    /// The neighbour list.
    const NeighbourList &neighbours() const { return list; }
    /// Number of pair force evaluations so far (pairs in the list per call).
    unsigned long long n_pair_evaluations() const { return pair_evaluations; }
    /// Checkpoint: the neighbour list and the evaluation count.
    void save(CheckpointOut &ar) const;
    void load(CheckpointIn &ar);

  private:
    Interaction        model;
    NeighbourList      list;
    std::vector<Vec2>  pair_force;
    bool               parallel          = true;
    unsigned long long pair_evaluations  = 0;
  };
} // namespace tribo::mlp
