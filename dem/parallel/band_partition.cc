#include "dem/parallel/band_partition.h"

#include <algorithm>
#include <limits>

namespace tribo::dem::parallel
{
  unsigned int BandPartition::band_of(double y) const
  {
    // cut[0] = -inf <= y, so the first cut above y is at 1..n.
    return static_cast<unsigned int>(std::upper_bound(cut.begin() + 1, cut.end() - 1, y) - cut.begin()) - 1;
  }

  BandPartition BandPartition::balanced(std::vector<double> y, unsigned int n)
  {
    BandPartition p;
    const double  inf = std::numeric_limits<double>::infinity();
    p.cut.assign(n + 1, inf);
    p.cut[0] = -inf;
    // The sorted heights at the quantiles only: y[i] put in place by a selection of the part
    // above the last one placed (O(n_ranks size) instead of a sort each step).
    std::size_t placed = 0; // y[0, placed) hold the placed-th smallest heights, y[placed - 1] the largest of them
    for (unsigned int k = 1; k < n; ++k)
      {
        const std::size_t i = y.size() * k / n; // the first height of band k
        if (y.empty())
          p.cut[k] = 0;
        else if (i == 0)
          p.cut[k] = *std::min_element(y.begin(), y.end());
        else if (i >= y.size())
          p.cut[k] = *std::max_element(y.begin(), y.end()) + 1;
        else
          {
            if (i >= placed)
              {
                std::nth_element(y.begin() + placed, y.begin() + i, y.end());
                // The largest of y[placed, i), all at most y[i]; y[placed - 1] is at most them.
                if (i > placed)
                  std::iter_swap(std::max_element(y.begin() + placed, y.begin() + i), y.begin() + i - 1);
                placed = i + 1;
              }
            p.cut[k] = 0.5 * (y[i - 1] + y[i]);
          }
      }
    return p;
  }

  double BandPartition::imbalance(const std::vector<double> &y) const
  {
    if (y.empty())
      return 1;
    std::vector<std::size_t> count(n_bands(), 0);
    for (const double v : y)
      ++count[band_of(v)];
    return double(*std::max_element(count.begin(), count.end())) * n_bands() / double(y.size());
  }
} // namespace tribo::dem::parallel
