#pragma once
/// @file Particle state (struct of arrays) and the cell-list neighbour search.
///
/// SI units: positions m, velocities m/s, masses kg (kg per metre of depth in 2D),
/// densities kg/m^3, specific internal energy J/kg, stress Pa.

#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/base/tensor.h>

#include <cmath>
#include <vector>

namespace tribo::sph
{
  using dealii::SymmetricTensor;
  using dealii::Tensor;

  /// The state of all particles, one array per field.
  ///
  /// The deviatoric stress S is stored as a symmetric dim x dim tensor. In 3D it
  /// is traceless. In 2D the model is plane strain: S holds the in-plane
  /// components (S_xx, S_yy, S_xy), which need not have zero trace, and the
  /// out-of-plane component is S_zz = -(S_xx + S_yy) (the full 3x3 deviator is
  /// traceless; eps_zz = 0 so S_zz enters neither the forces nor the energy rate,
  /// only invariants and the elastic energy).
  template <int dim>
  struct ParticleState
  {
    std::vector<Tensor<1, dim>>          x;    ///< position, m
    std::vector<Tensor<1, dim>>          v;    ///< velocity, m/s
    std::vector<double>                  mass; ///< kg (kg per m of depth in 2D)
    std::vector<double>                  rho;  ///< density, kg/m^3
    std::vector<double>                  e;    ///< specific internal energy, J/kg
    std::vector<SymmetricTensor<2, dim>> S;    ///< deviatoric stress, Pa
    std::vector<double>                  h;    ///< smoothing length, m
    std::vector<unsigned int>            material; ///< index into the material table
    std::vector<unsigned int>            body;     ///< body (and damping group) id

    /// Number of particles.
    unsigned int size() const { return static_cast<unsigned int>(x.size()); }
    /// Appends a particle with zero deviatoric stress and specific energy @p e (J/kg).
    unsigned int add(const Tensor<1, dim> &position, const Tensor<1, dim> &velocity,
                     double m, double density, double smoothing_length,
                     unsigned int material_id, unsigned int body_id, double e = 0);
    /// Remove the particles whose flag in @p remove is true (keeps the order).
    void remove(const std::vector<bool> &remove);

    /// sum m_i v_i, kg m/s.
    Tensor<1, dim> momentum() const;
    /// sum m_i |v_i|^2 / 2, J.
    double kinetic_energy() const;
    /// sum m_i e_i, J: includes the stored elastic (compression and shear) work.
    double internal_energy() const;
    /// Second invariant of the full (3x3 in 2D plane strain) deviator of particle
    /// @p i, J2 = S:S/2, Pa^2.
    double j2(unsigned int i) const;
  };

  /// The full 3x3 deviator's S:S for a stored S (adds S_zz^2 in 2D plane strain).
  template <int dim>
  double deviator_norm_squared(const SymmetricTensor<2, dim> &S);

  /// Cell-list neighbour search, linear in N: bins of edge >= the cut-off, each
  /// particle compares with the 3^dim surrounding bins. Optionally periodic along
  /// x with period L: separations use the minimum image
  /// dx <- dx - L round(dx/L) (requires L >= 3 * cut-off).
  ///
  /// The result is a full (both i->j and j->i) list in CSR form, in a
  /// deterministic order, so force loops can gather per particle without races.
  template <int dim>
  class NeighbourSearch
  {
  public:
    /// @p period > 0 makes x periodic with that period (m); 0 disables.
    explicit NeighbourSearch(double period = 0) : period(period) {}

    /// All pairs with |x_i - x_j| < @p cutoff (m), i != j.
    void build(const std::vector<Tensor<1, dim>> &x, double cutoff);

    /// Separation x_i - x_j, minimum image along x when periodic, m.
    Tensor<1, dim> separation(const Tensor<1, dim> &xi, const Tensor<1, dim> &xj) const
    {
      Tensor<1, dim> r = xi - xj;
      if (period > 0 && std::abs(r[0]) > 0.5 * period) // the division only across the period
        r[0] -= period * std::nearbyint(r[0] / period);
      return r;
    }

    /// Neighbours of particle i are list[start[i]] ... list[start[i+1]-1].
    std::vector<unsigned int> start, list;
    /// Number of unordered pairs (list.size()/2).
    std::size_t n_pairs() const { return list.size() / 2; }
    double      period;
  };
} // namespace tribo::sph
