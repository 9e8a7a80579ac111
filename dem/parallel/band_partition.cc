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
    std::sort(y.begin(), y.end());
    for (unsigned int k = 1; k < n; ++k)
      {
        const std::size_t i = y.size() * k / n; // the first height of band k
        if (y.empty())
          p.cut[k] = 0;
        else if (i == 0)
          p.cut[k] = y.front();
        else
          p.cut[k] = i < y.size() ? 0.5 * (y[i - 1] + y[i]) : y.back() + 1;
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
