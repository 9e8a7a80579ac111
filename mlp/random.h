#pragma once
/// @file Portable random numbers: the same seed gives the same sequence with any
/// standard library (std::normal_distribution is implementation-defined).

#include "core/checkpoint.h"

#include <cmath>
#include <cstdint>
#include <random>

namespace tribo::mlp
{
  /// Uniform and standard-normal variates drawn from std::mt19937_64.
  class RandomSource
  {
  public:
    /// Seeds the engine with @p seed.
    explicit RandomSource(std::uint64_t seed) : engine(seed) {}

    /// Uniform on [0, 1) with 53 random bits.
    double uniform() { return static_cast<double>(engine() >> 11) * 0x1.0p-53; }

    /// N(0, 1) by the Box-Muller transform (pairs are cached).
    double normal()
    {
      if (has_spare)
        {
          has_spare = false;
          return spare;
        }
      const double u1  = 1.0 - uniform(); // (0, 1]
      const double u2  = uniform();
      const double rad = std::sqrt(-2.0 * std::log(u1));
      const double ang = 2.0 * M_PI * u2;
      spare            = rad * std::sin(ang);
      has_spare        = true;
      return rad * std::cos(ang);
    }

    /// Checkpoint: the engine's state and the cached normal variate, so that the
    /// sequence goes on as if never interrupted (defined in mlp/langevin.cc).
    void save(CheckpointOut &ar) const;
    void load(CheckpointIn &ar);

  private:
    std::mt19937_64 engine;
    double          spare     = 0;
    bool            has_spare = false;
  };
} // namespace tribo::mlp
