#include "mlp/analysis.h"

#include "core/errors.h"
#include "mlp/interaction.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>

namespace tribo::mlp
{
  namespace
  {
    Grid2D make_grid(unsigned int nx, unsigned int ny, const Vec2 &lower, const Vec2 &upper)
    {
      if (nx < 2 || ny < 2)
        throw InputError("MLP analysis: a grid needs at least 2 x 2 nodes");
      Grid2D g;
      g.nx = nx;
      g.ny = ny;
      g.x0 = lower.x();
      g.y0 = lower.y();
      g.dx = (upper.x() - lower.x()) / (nx - 1);
      g.dy = (upper.y() - lower.y()) / (ny - 1);
      g.values.assign(static_cast<std::size_t>(nx) * ny, 0.0);
      return g;
    }
  } // namespace

  Grid2D structure_factor(const Particles &particles, double q_max, unsigned int n)
  {
    Grid2D             g  = make_grid(n, n, Vec2(-q_max, -q_max), Vec2(q_max, q_max));
    const unsigned int np = particles.size();
    if (np == 0)
      return g;
    // exp(-i q.x) = exp(-i qx x) exp(-i qy y): tabulate per particle and axis.
    std::vector<std::complex<double>> ex(static_cast<std::size_t>(np) * n), ey(ex.size());
    for (unsigned int k = 0; k < np; ++k)
      for (unsigned int a = 0; a < n; ++a)
        {
          const double q = -q_max + a * g.dx;
          ex[static_cast<std::size_t>(k) * n + a] =
            std::polar(1.0, -q * particles.position[k].x());
          ey[static_cast<std::size_t>(k) * n + a] =
            std::polar(1.0, -q * particles.position[k].y());
        }
    for (unsigned int b = 0; b < n; ++b)
      for (unsigned int a = 0; a < n; ++a)
        {
          std::complex<double> s = 0;
          for (unsigned int k = 0; k < np; ++k)
            s += ex[static_cast<std::size_t>(k) * n + a] * ey[static_cast<std::size_t>(k) * n + b];
          g.values[b * n + a] = std::norm(s) / np;
        }
    return g;
  }

  Grid2D pair_correlation(const Particles &particles, const Box &box, double half_width,
                          unsigned int n)
  {
    Grid2D g = make_grid(n, n, Vec2(-half_width, -half_width), Vec2(half_width, half_width));
    const unsigned int np = particles.size();
    if (np == 0)
      return g;
    const double bin = 2 * half_width / n; // n bins, node = bin centre
    g.x0 = g.y0 = -half_width + 0.5 * bin;
    g.dx = g.dy = bin;
    for (unsigned int i = 0; i < np; ++i)
      for (unsigned int j = 0; j < np; ++j)
        {
          if (i == j)
            continue;
          const Vec2 d = box.minimum_image(particles.position[j] - particles.position[i]);
          const int  a = static_cast<int>(std::floor((d.x() + half_width) / bin));
          const int  b = static_cast<int>(std::floor((d.y() + half_width) / bin));
          if (a >= 0 && b >= 0 && a < static_cast<int>(n) && b < static_cast<int>(n))
            g.values[static_cast<std::size_t>(b) * n + a] += 1;
        }
    for (double &v : g.values)
      v /= np * bin * bin;
    return g;
  }

  Grid2D gaussian_density(const Particles &particles, const Vec2 &lower, const Vec2 &upper,
                          unsigned int nx, unsigned int ny, double lambda)
  {
    if (!(lambda > 0))
      throw InputError("MLP analysis: Gaussian width lambda must be > 0 m^2, got " +
                       to_text(lambda));
    Grid2D       g   = make_grid(nx, ny, lower, upper);
    const double cut = 6 * std::sqrt(lambda);
    for (const Vec2 &x : particles.position)
      {
        const int a0 = std::max(0, static_cast<int>(std::ceil((x.x() - cut - g.x0) / g.dx)));
        const int a1 = std::min(static_cast<int>(nx) - 1,
                                static_cast<int>(std::floor((x.x() + cut - g.x0) / g.dx)));
        const int b0 = std::max(0, static_cast<int>(std::ceil((x.y() - cut - g.y0) / g.dy)));
        const int b1 = std::min(static_cast<int>(ny) - 1,
                                static_cast<int>(std::floor((x.y() + cut - g.y0) / g.dy)));
        for (int b = b0; b <= b1; ++b)
          for (int a = a0; a <= a1; ++a)
            {
              const double rx = g.x0 + a * g.dx - x.x(), ry = g.y0 + b * g.dy - x.y();
              g.values[static_cast<std::size_t>(b) * nx + a] +=
                std::exp(-(rx * rx + ry * ry) / lambda);
            }
      }
    return g;
  }

  double extent(const Particles &particles, unsigned int axis)
  {
    if (particles.size() == 0)
      return 0;
    double lo = std::numeric_limits<double>::max(), hi = -lo;
    for (const Vec2 &x : particles.position)
      {
        lo = std::min(lo, x[axis]);
        hi = std::max(hi, x[axis]);
      }
    return hi - lo;
  }

  double normalised_width(const Particles &particles, double initial_extent)
  {
    return extent(particles, 1) / initial_extent;
  }

  void return_force_magnitudes(const ForceField &field, const Particles &p,
                               const Box &box, std::vector<double> &net,
                               std::vector<double> &bond)
  {
    const unsigned int n = p.size();
    std::vector<Vec2>  sum(n, Vec2::Zero());
    std::vector<unsigned int> bonds(n, 0);
    bond.assign(n, 0.0);
    const double rc = field.interaction().cutoff();
    for (const auto &[i, j] : field.neighbours().pairs())
      {
        const Vec2 d = box.minimum_image(p.position[j] - p.position[i]);
        if (d.norm() >= rc)
          continue;
        const Vec2   f = field.interaction().return_force(d);
        const double a = f.norm();
        sum[i] += f;
        sum[j] -= f;
        bond[i] += a;
        bond[j] += a;
        ++bonds[i];
        ++bonds[j];
      }
    net.resize(n);
    for (unsigned int i = 0; i < n; ++i)
      {
        net[i] = sum[i].norm();
        bond[i] = bonds[i] ? bond[i] / bonds[i] : 0.0;
      }
  }

  double mean_coordination(const ForceField &field, const Particles &p, const Box &box)
  {
    const double rc = field.interaction().cutoff();
    unsigned long bonds = 0;
    for (const auto &[i, j] : field.neighbours().pairs())
      if (box.minimum_image(p.position[j] - p.position[i]).norm() < rc)
        ++bonds;
    return p.size() ? 2.0 * bonds / p.size() : 0.0;
  }
} // namespace tribo::mlp
