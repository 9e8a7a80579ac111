#include "sph/lattice.h"

#include "core/errors.h"

#include <algorithm>
#include <cmath>
#include <random>

namespace tribo::sph
{
  template <int dim>
  std::vector<Tensor<1, dim>> lattice_points(LatticeType type, const Tensor<1, dim> &origin,
                                             const Tensor<1, dim> &size, double a)
  {
    if (!(a > 0))
      throw InputError("SPH lattice: spacing must be positive, got " + to_text(a));
    std::vector<Tensor<1, dim>> pts;
    const double                eps = 1e-9 * a;
    auto inside = [&](const Tensor<1, dim> &p) {
      for (unsigned int d = 0; d < dim; ++d)
        if (p[d] < -eps || p[d] >= size[d] - eps)
          return false;
      return true;
    };
    if (type == LatticeType::cubic)
      {
        unsigned int n[3] = {1, 1, 1};
        for (unsigned int d = 0; d < dim; ++d)
          n[d] = static_cast<unsigned int>(std::ceil(size[d] / a - 1e-9));
        for (unsigned int k = 0; k < n[2]; ++k)
          for (unsigned int j = 0; j < n[1]; ++j)
            for (unsigned int i = 0; i < n[0]; ++i)
              {
                Tensor<1, dim> p;
                p[0] = (i + 0.5) * a;
                p[1] = (j + 0.5) * a;
                if constexpr (dim == 3)
                  p[2] = (k + 0.5) * a;
                if (inside(p))
                  pts.push_back(origin + p);
              }
        return pts;
      }
    const double dy = a * std::sqrt(3.0) / 2;
    if constexpr (dim == 2)
      {
        const unsigned int rows = static_cast<unsigned int>(std::ceil(size[1] / dy - 1e-9));
        const unsigned int cols = static_cast<unsigned int>(std::ceil(size[0] / a - 1e-9));
        for (unsigned int j = 0; j < rows; ++j)
          for (unsigned int i = 0; i < cols; ++i)
            {
              Tensor<1, dim> p;
              p[0] = (i + 0.25 + 0.5 * (j % 2)) * a;
              p[1] = (j + 0.5) * dy;
              if (inside(p))
                pts.push_back(origin + p);
            }
      }
    else
      {
        const double       dz     = a * std::sqrt(2.0 / 3.0);
        const unsigned int layers = static_cast<unsigned int>(std::ceil(size[2] / dz - 1e-9));
        const unsigned int rows   = static_cast<unsigned int>(std::ceil(size[1] / dy - 1e-9)) + 1;
        const unsigned int cols   = static_cast<unsigned int>(std::ceil(size[0] / a - 1e-9)) + 1;
        for (unsigned int k = 0; k < layers; ++k)
          for (unsigned int j = 0; j < rows; ++j)
            for (unsigned int i = 0; i < cols; ++i)
              {
                Tensor<1, dim> p;
                p[0] = (i + 0.25 + 0.5 * (j % 2) + 0.5 * (k % 2)) * a;
                p[1] = (j + 0.25) * dy + (k % 2) * a / (2 * std::sqrt(3.0));
                p[2] = (k + 0.5) * dz;
                if (inside(p))
                  pts.push_back(origin + p);
              }
      }
    return pts;
  }

  template <int dim>
  double volume_per_particle(LatticeType type, double a)
  {
    if (type == LatticeType::cubic)
      return std::pow(a, dim);
    return dim == 2 ? std::sqrt(3.0) / 2 * a * a : a * a * a / std::sqrt(2.0);
  }

  template <int dim>
  double layer_spacing(LatticeType type, double a)
  {
    if (type == LatticeType::cubic)
      return a;
    return dim == 2 ? a * std::sqrt(3.0) / 2 : a * std::sqrt(2.0 / 3.0);
  }

  template <int dim>
  void tilt(std::vector<Tensor<1, dim>> &points, const Tensor<1, dim> &centre, double angle,
            unsigned int axis)
  {
    AssertIndexRange(axis, dim);
    Assert(axis > 0, ExcMessage("tilt: the rotation plane is x and a second axis"));
    const unsigned int v = axis;
    const double       c = std::cos(angle), s = std::sin(angle);
    for (auto &p : points)
      {
        const double dx = p[0] - centre[0], dz = p[v] - centre[v];
        p[0] = centre[0] + c * dx - s * dz;
        p[v] = centre[v] + s * dx + c * dz;
      }
  }

  template <int dim>
  std::vector<Tensor<1, dim>> rotated_lattice_points(LatticeType type, const Tensor<1, dim> &size, double a,
                                                     double angle, unsigned int axis)
  {
    const double       diag = size.norm();
    Tensor<1, dim>     big_origin, big = size;
    for (unsigned int d : {0U, axis})
      {
        big[d]        = size[d] + 2 * diag;
        big_origin[d] = -diag;
      }
    auto pts = lattice_points<dim>(type, big_origin, big, a);
    tilt(pts, size / 2, angle, axis);
    std::vector<Tensor<1, dim>> kept;
    for (const auto &x : pts)
      {
        bool in = true;
        for (unsigned int d = 0; d < dim; ++d)
          in = in && x[d] >= 0 && x[d] < size[d];
        if (in)
          kept.push_back(x);
      }
    return kept;
  }

  template <int dim>
  Tensor<1, dim> rest_shift(const std::vector<Tensor<1, dim>> &lower, const std::vector<Tensor<1, dim>> &upper,
                            const Tensor<1, dim> &centre, double a, double d, double period, bool highest)
  {
    double       lower_top = -1e300, upper_bottom = 1e300;
    for (const auto &x : lower)
      lower_top = std::max(lower_top, x[dim - 1]);
    for (const auto &x : upper)
      upper_bottom = std::min(upper_bottom, x[dim - 1]);
    std::vector<Tensor<1, dim>> near_lower, near_upper; // the layers that can touch
    for (const auto &x : lower)
      if (x[dim - 1] > lower_top - 2 * d)
        near_lower.push_back(x);
    for (const auto &x : upper)
      if (x[dim - 1] < upper_bottom + 2 * d)
        near_upper.push_back(x);
    const unsigned int n_grid = 8;
    Tensor<1, dim>     best;
    const double       sign = highest ? -1 : 1; // minimise sign z
    best[dim - 1] = sign * 1e300;
    for (unsigned int gx = 0; gx < n_grid; ++gx)
      for (unsigned int gy = 0; gy < (dim == 3 ? n_grid : 1U); ++gy)
        {
          Tensor<1, dim> shift = centre;
          shift[0] += gx * a / n_grid;
          if (dim == 3)
            shift[1] += gy * a / n_grid;
          // Lowest z such that the upper body's bottom is at z: max over the constraints.
          double z = lower_top + d - upper_bottom - 2 * d;
          for (const auto &xu : near_upper)
            for (const auto &xl : near_lower)
              {
                Tensor<1, dim> r = xu + shift - xl;
                if (period > 0)
                  r[0] -= period * std::nearbyint(r[0] / period);
                r[dim - 1] = 0;
                const double rho2 = r.norm_square();
                if (rho2 < d * d)
                  z = std::max(z, xl[dim - 1] + std::sqrt(d * d - rho2) - xu[dim - 1]);
              }
          if (sign * z < sign * best[dim - 1] - 1e-12 * a)
            {
              best          = shift;
              best[dim - 1] = z;
            }
        }
    return best;
  }

  template <int dim>
  std::vector<unsigned int> surface_layer(const std::vector<Tensor<1, dim>> &points, double tol,
                                          bool top)
  {
    std::vector<unsigned int> out;
    if (points.empty())
      return out;
    const unsigned int v   = dim - 1;
    double             ext = points[0][v];
    for (const auto &p : points)
      ext = top ? std::max(ext, p[v]) : std::min(ext, p[v]);
    for (unsigned int i = 0; i < points.size(); ++i)
      if (std::abs(points[i][v] - ext) <= tol)
        out.push_back(i);
    return out;
  }

  template <int dim>
  void add_step(std::vector<Tensor<1, dim>> &points, double x_step, double a, double tol)
  {
    for (unsigned int i : surface_layer(points, tol))
      if (points[i][0] > x_step)
        {
          Tensor<1, dim> p = points[i];
          p[dim - 1] += a;
          points.push_back(p);
        }
  }

  template <int dim>
  void random_holes(std::vector<Tensor<1, dim>> &points, double fraction, std::uint64_t seed,
                    double tol)
  {
    if (fraction < 0 || fraction > 1)
      throw InputError("SPH random holes: fraction must be in [0, 1], got " + to_text(fraction));
    auto               layer = surface_layer(points, tol);
    std::mt19937_64    rng(seed);
    std::shuffle(layer.begin(), layer.end(), rng);
    const unsigned int n_remove = static_cast<unsigned int>(std::lround(fraction * layer.size()));
    std::vector<bool>  remove(points.size(), false);
    for (unsigned int k = 0; k < n_remove; ++k)
      remove[layer[k]] = true;
    std::vector<Tensor<1, dim>> kept;
    for (unsigned int i = 0; i < points.size(); ++i)
      if (!remove[i])
        kept.push_back(points[i]);
    points.swap(kept);
  }

  template <int dim>
  void random_heights(std::vector<Tensor<1, dim>> &points, double dz, std::uint64_t seed,
                      double tol)
  {
    std::mt19937_64                        rng(seed);
    std::uniform_real_distribution<double> u(-0.5 * dz, 0.5 * dz);
    for (unsigned int i : surface_layer(points, tol))
      points[i][dim - 1] += u(rng);
  }

  template <int dim>
  void fractal_heights(std::vector<Tensor<1, dim>> &points, double D_f, double rms,
                       const Tensor<1, dim> &lengths, unsigned int n_modes, std::uint64_t seed,
                       double tol)
  {
    const double H = dim - D_f;
    if (!(H > 0 && H < 1))
      throw InputError("SPH fractal surface: D_f must lie in (" + std::to_string(dim - 1) + ", " +
                       std::to_string(dim) + "), got " + to_text(D_f));
    const double exponent = -(H + 0.5 * (dim - 1));
    struct Mode
    {
      double kx, ky, amp, phase;
    };
    std::vector<Mode>                      modes;
    std::mt19937_64                        rng(seed);
    std::normal_distribution<double>       gauss(0, 1);
    std::uniform_real_distribution<double> uphase(0, 2 * M_PI);
    const int                              nm = static_cast<int>(n_modes);
    for (int p = 0; p <= nm; ++p)
      for (int q = (dim == 3 ? -nm : 0); q <= (dim == 3 ? nm : 0); ++q)
        {
          if (p == 0 && q <= 0)
            continue; // half plane: each cosine once, no mean
          const double kx  = 2 * M_PI * p / lengths[0];
          const double ky  = dim == 3 ? 2 * M_PI * q / lengths[1] : 0.0;
          const double amp = gauss(rng) * std::pow(std::sqrt(kx * kx + ky * ky), exponent);
          modes.push_back({kx, ky, amp, uphase(rng)});
        }
    const auto          layer = surface_layer(points, tol);
    std::vector<double> z(layer.size(), 0);
    for (unsigned int k = 0; k < layer.size(); ++k)
      {
        const auto &pt = points[layer[k]];
        for (const auto &m : modes)
          z[k] += m.amp * std::cos(m.kx * pt[0] + (dim == 3 ? m.ky * pt[1] : 0.0) + m.phase);
      }
    double mean = 0, sq = 0;
    for (double zk : z)
      mean += zk;
    mean /= std::max<std::size_t>(1, z.size());
    for (double &zk : z)
      {
        zk -= mean;
        sq += zk * zk;
      }
    const double scale = sq > 0 ? rms / std::sqrt(sq / z.size()) : 0;
    for (unsigned int k = 0; k < layer.size(); ++k)
      points[layer[k]][dim - 1] += scale * z[k];
  }

  template <int dim>
  unsigned int add_particles(ParticleState<dim> &state, const std::vector<Tensor<1, dim>> &points,
                             double rho0, double volume, double h, unsigned int material,
                             unsigned int body)
  {
    const unsigned int first = state.size();
    for (const auto &p : points)
      state.add(p, Tensor<1, dim>(), rho0 * volume, rho0, h, material, body);
    return first;
  }

#define TRIBO_SPH_LATTICE(dim)                                                                    \
  template std::vector<Tensor<1, dim>> lattice_points<dim>(LatticeType, const Tensor<1, dim> &,   \
                                                           const Tensor<1, dim> &, double);       \
  template double volume_per_particle<dim>(LatticeType, double);                                  \
  template double layer_spacing<dim>(LatticeType, double);                                        \
  template std::vector<Tensor<1, dim>> rotated_lattice_points<dim>(LatticeType, const Tensor<1, dim> &, \
                                                                   double, double, unsigned int);   \
  template Tensor<1, dim> rest_shift<dim>(const std::vector<Tensor<1, dim>> &,                    \
                                          const std::vector<Tensor<1, dim>> &, const Tensor<1, dim> &, \
                                          double, double, double, bool);                          \
  template void   tilt<dim>(std::vector<Tensor<1, dim>> &, const Tensor<1, dim> &, double,        \
                            unsigned int);                                                        \
  template std::vector<unsigned int> surface_layer<dim>(const std::vector<Tensor<1, dim>> &,      \
                                                        double, bool);                            \
  template void add_step<dim>(std::vector<Tensor<1, dim>> &, double, double, double);             \
  template void random_holes<dim>(std::vector<Tensor<1, dim>> &, double, std::uint64_t, double);  \
  template void random_heights<dim>(std::vector<Tensor<1, dim>> &, double, std::uint64_t,         \
                                    double);                                                      \
  template void fractal_heights<dim>(std::vector<Tensor<1, dim>> &, double, double,               \
                                     const Tensor<1, dim> &, unsigned int, std::uint64_t,         \
                                     double);                                                     \
  template unsigned int add_particles<dim>(ParticleState<dim> &,                                  \
                                           const std::vector<Tensor<1, dim>> &, double, double,   \
                                           double, unsigned int, unsigned int);
  TRIBO_SPH_LATTICE(2)
  TRIBO_SPH_LATTICE(3)
#undef TRIBO_SPH_LATTICE
} // namespace tribo::sph
