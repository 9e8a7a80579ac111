#pragma once
/// @file Horizontal bands of the x-periodic cell, one per MPI rank (dem/parallel/README.md).

#include <vector>

namespace tribo::dem::parallel
{
  /// Band k holds the heights y in [cut[k], cut[k + 1]), m, with cut[0] = -inf and
  /// cut[n] = +inf. Each band spans the full period, so that a periodic pair stays inside
  /// one rank and a band has at most two neighbours (the one below and the one above).
  struct BandPartition
  {
    std::vector<double> cut;

    unsigned int n_bands() const { return static_cast<unsigned int>(cut.size()) - 1; }
    /// The band that holds height @p y.
    unsigned int band_of(double y) const;
    /// @p n bands with as equal counts of the heights @p y (one per contact) as ties allow:
    /// the cuts lie halfway between consecutive sorted heights at the quantiles k/n.
    static BandPartition balanced(std::vector<double> y, unsigned int n);
    /// The largest band's count of @p y over the mean count (1: balanced; n: all in one band).
    double imbalance(const std::vector<double> &y) const;
  };
} // namespace tribo::dem::parallel
