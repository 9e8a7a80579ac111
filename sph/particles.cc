#include "sph/particles.h"

#include "core/errors.h"

#include <deal.II/base/parallel.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace tribo::sph
{
  template <int dim>
  unsigned int ParticleState<dim>::add(const Tensor<1, dim> &position,
                                       const Tensor<1, dim> &velocity, double m, double density,
                                       double smoothing_length, unsigned int material_id,
                                       unsigned int body_id, double energy)
  {
    x.push_back(position);
    v.push_back(velocity);
    mass.push_back(m);
    rho.push_back(density);
    e.push_back(energy);
    S.emplace_back();
    h.push_back(smoothing_length);
    material.push_back(material_id);
    body.push_back(body_id);
    return size() - 1;
  }

  template <typename T>
  static void compact(std::vector<T> &a, const std::vector<bool> &remove)
  {
    std::size_t k = 0;
    for (std::size_t i = 0; i < a.size(); ++i)
      if (!remove[i])
        a[k++] = a[i];
    a.resize(k);
  }

  template <int dim>
  void ParticleState<dim>::remove(const std::vector<bool> &flags)
  {
    compact(x, flags);
    compact(v, flags);
    compact(mass, flags);
    compact(rho, flags);
    compact(e, flags);
    compact(S, flags);
    compact(h, flags);
    compact(material, flags);
    compact(body, flags);
  }

  template <int dim>
  Tensor<1, dim> ParticleState<dim>::momentum() const
  {
    Tensor<1, dim> p;
    for (unsigned int i = 0; i < size(); ++i)
      p += mass[i] * v[i];
    return p;
  }

  template <int dim>
  double ParticleState<dim>::kinetic_energy() const
  {
    double k = 0;
    for (unsigned int i = 0; i < size(); ++i)
      k += 0.5 * mass[i] * v[i].norm_square();
    return k;
  }

  template <int dim>
  double ParticleState<dim>::internal_energy() const
  {
    double u = 0;
    for (unsigned int i = 0; i < size(); ++i)
      u += mass[i] * e[i];
    return u;
  }

  template <int dim>
  double deviator_norm_squared(const SymmetricTensor<2, dim> &S)
  {
    double s = S * S;
    if constexpr (dim == 2)
      {
        const double szz = -(S[0][0] + S[1][1]);
        s += szz * szz;
      }
    return s;
  }

  template <int dim>
  double ParticleState<dim>::j2(unsigned int i) const
  {
    return 0.5 * deviator_norm_squared(S[i]);
  }

  template <int dim>
  void NeighbourSearch<dim>::build(const std::vector<Tensor<1, dim>> &x, double cutoff)
  {
    const unsigned int n = static_cast<unsigned int>(x.size());
    start.assign(n + 1, 0);
    list.clear();
    if (n == 0)
      return;
    if (!(cutoff > 0))
      throw RunError("SPH neighbour search: cut-off must be positive, got " + to_text(cutoff));

    // Bounding box and bins.
    Tensor<1, dim> lo, hi;
    for (unsigned int d = 0; d < dim; ++d)
      {
        lo[d] = std::numeric_limits<double>::max();
        hi[d] = -std::numeric_limits<double>::max();
      }
    for (const auto &p : x)
      for (unsigned int d = 0; d < dim; ++d)
        {
          lo[d] = std::min(lo[d], p[d]);
          hi[d] = std::max(hi[d], p[d]);
        }
    std::array<long, 3> nb = {{1, 1, 1}};
    double               edge[3] = {cutoff, cutoff, cutoff};
    for (unsigned int d = 0; d < dim; ++d)
      nb[d] = std::max(1L, static_cast<long>((hi[d] - lo[d]) / cutoff) + 1);
    if (period > 0)
      {
        if (period < 3 * cutoff)
          throw RunError("SPH neighbour search: period " + to_text(period) +
                         " m is shorter than 3 cut-offs (" + to_text(3 * cutoff) + " m)");
        lo[0]   = 0;
        nb[0]   = static_cast<long>(period / cutoff);
        edge[0] = period / nb[0];
      }
    const long n_bins = nb[0] * nb[1] * nb[2];
    if (n_bins > 64L * n + 1024)
      throw RunError("SPH neighbour search: particles spread over " + std::to_string(n_bins) +
                     " bins for " + std::to_string(n) + " particles (a particle flew away?)");

    auto coord = [&](const Tensor<1, dim> &p, unsigned int d) {
      double xd = p[d] - lo[d];
      if (d == 0 && period > 0)
        xd -= period * std::floor(xd / period);
      return std::min(nb[d] - 1, std::max(0L, static_cast<long>(xd / edge[d])));
    };
    std::vector<long> bin_of(n);
    for (unsigned int i = 0; i < n; ++i)
      {
        long b = 0;
        for (int d = dim - 1; d >= 0; --d)
          b = b * nb[d] + coord(x[i], d);
        bin_of[i] = b;
      }
    // Counting sort of particles by bin.
    std::vector<unsigned int> bin_start(n_bins + 1, 0), sorted(n);
    for (unsigned int i = 0; i < n; ++i)
      ++bin_start[bin_of[i] + 1];
    for (long b = 0; b < n_bins; ++b)
      bin_start[b + 1] += bin_start[b];
    {
      std::vector<unsigned int> fill(bin_start.begin(), bin_start.end() - 1);
      for (unsigned int i = 0; i < n; ++i)
        sorted[fill[bin_of[i]]++] = i;
    }

    const double cut2 = cutoff * cutoff;
    // Visits the neighbours of i in a fixed order; f(j) per neighbour.
    auto visit = [&](unsigned int i, auto &&f) {
      std::array<long, 3> c = {{0, 0, 0}};
      for (unsigned int d = 0; d < dim; ++d)
        c[d] = coord(x[i], d);
      std::array<long, 3> lo_c = {{0, 0, 0}}, hi_c = {{0, 0, 0}};
      for (unsigned int d = 0; d < dim; ++d)
        {
          lo_c[d] = c[d] - 1;
          hi_c[d] = c[d] + 1;
          if (!(d == 0 && period > 0))
            {
              lo_c[d] = std::max(0L, lo_c[d]);
              hi_c[d] = std::min(nb[d] - 1, hi_c[d]);
            }
        }
      for (long cz = lo_c[2]; cz <= hi_c[2]; ++cz)
        for (long cy = lo_c[1]; cy <= hi_c[1]; ++cy)
          for (long cx = lo_c[0]; cx <= hi_c[0]; ++cx)
            {
              const long wx = (cx + nb[0]) % nb[0];
              const long b  = (cz * nb[1] + cy) * nb[0] + wx;
              for (unsigned int k = bin_start[b]; k < bin_start[b + 1]; ++k)
                {
                  const unsigned int j = sorted[k];
                  if (j != i && separation(x[i], x[j]).norm_square() < cut2)
                    f(j);
                }
            }
    };

    std::vector<unsigned int> count(n, 0);
    dealii::parallel::apply_to_subranges(
      0U, n,
      [&](unsigned int b, unsigned int e) {
        for (unsigned int i = b; i < e; ++i)
          visit(i, [&](unsigned int) { ++count[i]; });
      },
      256);
    for (unsigned int i = 0; i < n; ++i)
      start[i + 1] = start[i] + count[i];
    list.resize(start[n]);
    dealii::parallel::apply_to_subranges(
      0U, n,
      [&](unsigned int b, unsigned int e) {
        for (unsigned int i = b; i < e; ++i)
          {
            unsigned int k = start[i];
            visit(i, [&](unsigned int j) { list[k++] = j; });
          }
      },
      256);
  }

  template struct ParticleState<2>;
  template struct ParticleState<3>;
  template double deviator_norm_squared<2>(const SymmetricTensor<2, 2> &);
  template double deviator_norm_squared<3>(const SymmetricTensor<2, 3> &);
  template class NeighbourSearch<2>;
  template class NeighbourSearch<3>;
} // namespace tribo::sph
