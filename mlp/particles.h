#pragma once
/// @file Movable lattice particles (MLP): particle state, the periodic box and
/// the lattice builders.
///
/// Everything is 2D and per unit depth: positions in m, velocities in m/s,
/// masses in kg/m, forces in N/m, energies in J/m. Coordinates are (x, y); the
/// paper (Popov and Filippov 2006) calls the second coordinate z.

#include "core/checkpoint.h"

#include <Eigen/Core>

#include <cmath>
#include <cstdint>
#include <vector>

namespace tribo::mlp
{
  using Vec2 = Eigen::Vector2d;

  /// The simulation cell: open, periodic along x (period lx), or periodic along
  /// x and y. When periodic along y, the image across the y-boundary is shifted
  /// by @p tilt along x (a sheared cell with edge vectors (lx, 0) and (tilt, ly),
  /// used to impose simple shear on a periodic patch).
  struct Box
  {
    bool   periodic_x = false; ///< x-periodic with period lx
    double lx         = 0;     ///< m
    bool   periodic_y = false; ///< y-periodic with period ly (requires periodic_x)
    double ly         = 0;     ///< m
    double tilt       = 0;     ///< x-offset of the y-image, m; |tilt| <= lx/2

    /// The nearest periodic image of the separation @p d = x_j - x_i, m.
    Vec2 minimum_image(Vec2 d) const
    {
      if (periodic_y)
        {
          const double n = std::round(d.y() / ly);
          d.y() -= n * ly;
          d.x() -= n * tilt;
        }
      if (periodic_x)
        d.x() -= lx * std::round(d.x() / lx);
      return d;
    }

    /// @p x mapped into the primary cell (0 <= y < ly, 0 <= x - tilt y/ly < lx).
    Vec2 wrap(Vec2 x) const
    {
      if (periodic_y)
        {
          const double n = std::floor(x.y() / ly);
          x.y() -= n * ly;
          x.x() -= n * tilt;
        }
      if (periodic_x)
        {
          const double xs = periodic_y ? x.x() - tilt * x.y() / ly : x.x();
          x.x() -= lx * std::floor(xs / lx);
        }
      return x;
    }

    /// Throws InputError if a period is not positive or the tilt exceeds lx/2.
    void validate() const;
  };

  /// Which components of a particle are held (velocity prescribed, no force,
  /// no noise): bit 0 = x, bit 1 = y.
  enum Fix : unsigned char
  {
    fix_none = 0,
    fix_x    = 1,
    fix_y    = 2,
    fix_xy   = 3
  };

  /// The particles, one array per field (struct of arrays).
  struct Particles
  {
    std::vector<Vec2>          position;       ///< m
    std::vector<Vec2>          velocity;       ///< m/s
    std::vector<Vec2>          force;          ///< total force of the last evaluation, N/m
    std::vector<Vec2>          external_force; ///< applied load added to the force, N/m
    std::vector<double>        mass;           ///< kg/m
    std::vector<unsigned int>  group;          ///< user group id (body, boundary layer...)
    std::vector<unsigned char> fixed;          ///< Fix mask

    /// Number of particles.
    unsigned int size() const { return static_cast<unsigned int>(position.size()); }
    /// Append a particle at rest at @p x with mass @p m (kg/m); returns its index.
    unsigned int add(const Vec2 &x, double m, unsigned int group_id = 0);
    /// sum m |v|^2 / 2, J/m.
    double kinetic_energy() const;
    /// sum m v, kg/s.
    Vec2 momentum() const;
    /// Checkpoint: every array, bit for bit.
    void save(CheckpointOut &ar) const;
    /// Restore what save() wrote; InputError if it holds another number of particles.
    void load(CheckpointIn &ar);
  };

  /// The two lattices of the paper: six-fold (hexagonal, n = 6) and four-fold
  /// (square, n = 4).
  enum class LatticeType
  {
    hexagonal,
    square
  };

  /// Symmetry order n of a lattice: 6 or 4.
  unsigned int symmetry_order(LatticeType type);

  /// The unit lattice vectors e^alpha = (cos(2 pi alpha/n), sin(2 pi alpha/n)),
  /// alpha = 0..n-1 (paper, eq. 1 for n = 6).
  std::vector<Vec2> lattice_directions(LatticeType type);

  /// Area per particle of an ideal lattice of spacing @p c, m^2:
  /// (sqrt(3)/2) c^2 (hexagonal) or c^2 (square).
  double area_per_particle(LatticeType type, double c);

  /// Adds an @p nx x @p ny patch of lattice spacing @p c (m) with its first
  /// particle at @p origin. Hexagonal: rows along x, row spacing (sqrt(3)/2) c,
  /// odd rows shifted by c/2. Square: rows and columns c apart. Returns the index
  /// of the first particle added.
  unsigned int add_lattice_patch(Particles &particles, LatticeType type, const Vec2 &origin,
                                 unsigned int nx, unsigned int ny, double c, double mass,
                                 unsigned int group_id = 0);

  /// The box that makes an @p nx x @p ny patch (from add_lattice_patch at origin
  /// (c/4, c/4)) periodic: along x only, or along x and y. A hexagonal patch
  /// periodic along y needs an even @p ny (InputError otherwise).
  Box periodic_box(LatticeType type, unsigned int nx, unsigned int ny, double c,
                   bool periodic_y);

  /// Side lengths (m) of the rectangle of aspect ratio @p aspect (width/height)
  /// whose area is @p enlargement times the ideal packing area of @p n particles
  /// of spacing @p c: the region for the ordering scene (paper, section 5).
  Vec2 random_region_size(LatticeType type, unsigned int n, double c, double aspect,
                          double enlargement);

  /// Adds @p n particles at uniformly random positions in [lower, upper] with no
  /// two closer than @p min_distance (m), by rejection (std::mt19937_64 seeded
  /// with @p seed, so the same seed gives the same positions). Throws InputError
  /// if the region cannot hold them after 1000 n attempts.
  void add_random_particles(Particles &particles, const Vec2 &lower, const Vec2 &upper,
                            unsigned int n, double min_distance, double mass,
                            std::uint64_t seed, unsigned int group_id = 0);
} // namespace tribo::mlp
