#include "mlp/particles.h"

#include "core/errors.h"
#include "core/serialization.h"
#include "mlp/random.h"

#include <algorithm>
#include <string>

namespace tribo::mlp
{
  void Box::validate() const
  {
    if (periodic_x && !(lx > 0))
      throw InputError("MLP box: periodic along x needs a period lx > 0, got " + to_text(lx) +
                       " m");
    if (periodic_y && !periodic_x)
      throw InputError("MLP box: periodic along y needs periodic along x as well");
    if (periodic_y && !(ly > 0))
      throw InputError("MLP box: periodic along y needs a period ly > 0, got " + to_text(ly) +
                       " m");
    if (periodic_y && std::abs(tilt) > 0.5 * lx)
      throw InputError("MLP box: tilt " + to_text(tilt) + " m exceeds lx/2 = " +
                       to_text(0.5 * lx) + " m");
  }

  unsigned int Particles::add(const Vec2 &x, double m, unsigned int group_id)
  {
    if (!(m > 0))
      throw InputError("MLP particle mass must be > 0 kg/m, got " + to_text(m));
    position.push_back(x);
    velocity.push_back(Vec2::Zero());
    force.push_back(Vec2::Zero());
    external_force.push_back(Vec2::Zero());
    mass.push_back(m);
    group.push_back(group_id);
    fixed.push_back(fix_none);
    return size() - 1;
  }

  double Particles::kinetic_energy() const
  {
    double e = 0;
    for (unsigned int i = 0; i < size(); ++i)
      e += 0.5 * mass[i] * velocity[i].squaredNorm();
    return e;
  }

  Vec2 Particles::momentum() const
  {
    Vec2 p = Vec2::Zero();
    for (unsigned int i = 0; i < size(); ++i)
      p += mass[i] * velocity[i];
    return p;
  }

  unsigned int symmetry_order(LatticeType type)
  {
    return type == LatticeType::hexagonal ? 6 : 4;
  }

  std::vector<Vec2> lattice_directions(LatticeType type)
  {
    const unsigned int n = symmetry_order(type);
    std::vector<Vec2>  e(n);
    for (unsigned int a = 0; a < n; ++a)
      e[a] = Vec2(std::cos(2 * M_PI * a / n), std::sin(2 * M_PI * a / n));
    return e;
  }

  double area_per_particle(LatticeType type, double c)
  {
    return type == LatticeType::hexagonal ? 0.5 * std::sqrt(3.0) * c * c : c * c;
  }

  unsigned int add_lattice_patch(Particles &particles, LatticeType type, const Vec2 &origin,
                                 unsigned int nx, unsigned int ny, double c, double mass,
                                 unsigned int group_id)
  {
    if (!(c > 0))
      throw InputError("MLP lattice spacing must be > 0 m, got " + to_text(c));
    const unsigned int first = particles.size();
    const bool         hex   = type == LatticeType::hexagonal;
    const double       dy    = hex ? 0.5 * std::sqrt(3.0) * c : c;
    for (unsigned int j = 0; j < ny; ++j)
      for (unsigned int i = 0; i < nx; ++i)
        {
          const double shift = (hex && j % 2 == 1) ? 0.5 * c : 0.0;
          particles.add(origin + Vec2(i * c + shift, j * dy), mass, group_id);
        }
    return first;
  }

  Box periodic_box(LatticeType type, unsigned int nx, unsigned int ny, double c, bool periodic_y)
  {
    Box box;
    box.periodic_x = true;
    box.lx         = nx * c;
    if (periodic_y)
      {
        if (type == LatticeType::hexagonal && ny % 2 != 0)
          throw InputError("MLP periodic hexagonal patch needs an even number of rows, got " +
                           std::to_string(ny));
        box.periodic_y = true;
        box.ly = ny * (type == LatticeType::hexagonal ? 0.5 * std::sqrt(3.0) * c : c);
      }
    return box;
  }

  Vec2 random_region_size(LatticeType type, unsigned int n, double c, double aspect,
                          double enlargement)
  {
    const double area = enlargement * n * area_per_particle(type, c);
    const double h    = std::sqrt(area / aspect);
    return Vec2(aspect * h, h);
  }

  void add_random_particles(Particles &particles, const Vec2 &lower, const Vec2 &upper,
                            unsigned int n, double min_distance, double mass,
                            std::uint64_t seed, unsigned int group_id)
  {
    const Vec2 size = upper - lower;
    if (!(size.x() > 0 && size.y() > 0))
      throw InputError("MLP random region must have positive extent");
    // Bucket grid with cells of side min_distance: a new point is checked against
    // the 3x3 neighbouring buckets only.
    const double cell = std::max(min_distance, 1e-300);
    const int    nx   = std::max(1, static_cast<int>(size.x() / cell));
    const int    ny   = std::max(1, static_cast<int>(size.y() / cell));
    std::vector<std::vector<Vec2>> buckets(static_cast<std::size_t>(nx) * ny);
    RandomSource                   rng(seed);
    const std::uint64_t            max_attempts = 1000ull * n;
    std::uint64_t                  attempts     = 0;
    unsigned int                   placed       = 0;
    while (placed < n)
      {
        if (++attempts > max_attempts)
          throw InputError("MLP random particles: placed only " + std::to_string(placed) +
                           " of " + std::to_string(n) + " with minimum distance " +
                           to_text(min_distance) + " m; enlarge the region or lower the distance");
        const Vec2 x  = lower + Vec2(rng.uniform() * size.x(), rng.uniform() * size.y());
        const int  cx = std::min(nx - 1, static_cast<int>((x.x() - lower.x()) / cell));
        const int  cy = std::min(ny - 1, static_cast<int>((x.y() - lower.y()) / cell));
        bool       ok = true;
        for (int jy = std::max(0, cy - 1); ok && jy <= std::min(ny - 1, cy + 1); ++jy)
          for (int jx = std::max(0, cx - 1); ok && jx <= std::min(nx - 1, cx + 1); ++jx)
            for (const Vec2 &y : buckets[static_cast<std::size_t>(jy) * nx + jx])
              if ((x - y).squaredNorm() < min_distance * min_distance)
                {
                  ok = false;
                  break;
                }
        if (!ok)
          continue;
        buckets[static_cast<std::size_t>(cy) * nx + cx].push_back(x);
        particles.add(x, mass, group_id);
        ++placed;
      }
  }
  void Particles::save(CheckpointOut &ar) const
  {
    ar << position << velocity << force << external_force << mass << group << fixed;
  }

  void Particles::load(CheckpointIn &ar)
  {
    const unsigned int n = size();
    ar >> position >> velocity >> force >> external_force >> mass >> group >> fixed;
    if (size() != n || velocity.size() != n || fixed.size() != n)
      throw InputError("checkpoint: it holds " + std::to_string(size()) +
                       " MLP particles, this case builds " + std::to_string(n));
  }
} // namespace tribo::mlp
