#include "dem/engine/boundary.h"

#include "core/errors.h"
#include "dem/engine/contact.h"

#include <algorithm>
#include <cmath>

namespace tribo::dem
{
  namespace
  {
    /// v rotated by +90 degrees, (-v_y, v_x).
    Vec2 perp(const Vec2 &v) { return {-v.y(), v.x()}; }
  } // namespace

  HalfDiscs::HalfDiscs(const BoundaryBody &body, double diameter_, const Vec2 &outward, double period_)
    : diameter(diameter_)
    , side(outward.y() >= 0 ? 1.0 : -1.0)
    , period(period_)
  {
    if (!(diameter > 0) || !(period > 0) || body.n_nodes() < 2)
      throw RunError("half-disc elements need a positive diameter and period and at least two "
                     "boundary nodes");
    if (!(std::abs(outward.y()) > 0.5 * outward.norm()))
      throw RunError("half-disc elements: the chain runs along x, so the round sides must face "
                     "+y or -y");
    for (unsigned int i = 0; i < body.n_nodes(); ++i)
      node_abscissa.push_back(body.node_position(i).x());
    if (!std::is_sorted(node_abscissa.begin(), node_abscissa.end()) ||
        node_abscissa.front() < 0 || node_abscissa.back() >= period)
      throw RunError("boundary nodes must be ordered by x within [0, period)");
    const unsigned int n = std::max(1L, std::lround(period / diameter));
    for (unsigned int k = 0; k < n; ++k)
      {
        centre_abscissa.push_back((k + 0.5) * period / n);
        const auto [e, xi] = locate(centre_abscissa.back());
        anchor_edge.push_back(e);
        anchor_xi.push_back(xi);
      }
  }

  std::pair<unsigned int, double> HalfDiscs::locate(double s) const
  {
    s -= period * std::floor(s / period);
    const unsigned int n = node_abscissa.size();
    // Edge i runs from node i to node i + 1; the last one wraps to node 0 + period.
    auto it = std::upper_bound(node_abscissa.begin(), node_abscissa.end(), s);
    unsigned int e;
    double       s_a;
    if (it == node_abscissa.begin())
      {
        e   = n - 1; // s before the first node: on the wrapping edge
        s_a = node_abscissa[n - 1] - period;
      }
    else
      {
        e   = (it - node_abscissa.begin()) - 1;
        s_a = node_abscissa[e];
      }
    const double s_b = e + 1 < n ? node_abscissa[e + 1] : node_abscissa[0] + period;
    return {e, std::clamp((s - s_a) / (s_b - s_a), 0.0, 1.0)};
  }

  HalfDiscs::Placement HalfDiscs::placement(unsigned int k, const std::vector<Vec2> &nodes) const
  {
    const unsigned int n = nodes.size(), e = anchor_edge[k];
    const double       xi = anchor_xi[k];
    const Vec2        &a  = nodes[e];
    Vec2               b  = nodes[(e + 1) % n];
    if (e + 1 == n)
      b.x() += period; // the wrapping edge ends at node 0's periodic image
    // Keep the centre near its reference abscissa (node positions are not wrapped).
    Vec2 c = (1 - xi) * a + xi * b;
    c.x() -= period * std::floor((c.x() - (centre_abscissa[k] - 0.5 * period)) / period);
    return {c, b - a};
  }

  std::vector<Vec2> HalfDiscs::centres(const std::vector<Vec2> &nodes) const
  {
    std::vector<Vec2> c;
    for (unsigned int k = 0; k < count(); ++k)
      c.push_back(placement(k, nodes).centre);
    return c;
  }

  std::vector<Contact> HalfDiscs::detect(const ParticleSystem &system,
                                         const std::vector<Vec2> &disc_centres,
                                         const std::vector<double> &body_angles,
                                         const std::vector<Vec2> &nodes, double distance,
                                         const std::vector<Vec2> &disc_motion,
                                         const std::vector<Vec2> &node_motion) const
  {
    std::vector<Contact> found;
    const unsigned int   nh  = count();
    const double         rho = radius();
    if ((!disc_motion.empty() && disc_motion.size() != system.discs.size()) ||
        (!node_motion.empty() && node_motion.size() != nodes.size()))
      throw RunError("half-disc detection: " + std::to_string(disc_motion.size()) + " disc motions for " +
                     std::to_string(system.discs.size()) + " discs and " + std::to_string(node_motion.size()) +
                     " node motions for " + std::to_string(nodes.size()) + " nodes");
    // The centres' motions (interpolated from the nodes' as the centres are) and the largest
    // relative motion of a disc and a half-disc, capped as ContactDetector::detect caps it.
    std::vector<Vec2> centre_motion(nh, Vec2::Zero());
    double            largest_disc = 0, largest_centre = 0;
    for (const Vec2 &m : disc_motion)
      largest_disc = std::max(largest_disc, m.norm());
    if (!node_motion.empty())
      for (unsigned int k = 0; k < nh; ++k)
        {
          const unsigned int e = anchor_edge[k];
          centre_motion[k] = (1 - anchor_xi[k]) * node_motion[e] + anchor_xi[k] * node_motion[(e + 1) % nodes.size()];
          largest_centre   = std::max(largest_centre, centre_motion[k].norm());
        }
    const double closing_reach =
      std::min(largest_disc + largest_centre, ContactDetector::max_motion_reach * system.max_radius());
    const double reach = rho + system.max_radius() + std::max({distance, closing_reach, 0.0});
    std::vector<Placement> at(nh);
    double                 ymin = INFINITY, ymax = -INFINITY;
    for (unsigned int k = 0; k < nh; ++k)
      {
        at[k] = placement(k, nodes);
        ymin  = std::min(ymin, at[k].centre.y());
        ymax  = std::max(ymax, at[k].centre.y());
      }

    // The displaced centres by bins along x (wrapped), each at least one reach wide:
    // a half-disc within reach of a grain is in the grain's bin or a neighbouring one.
    const unsigned int nbins = std::max(1L, std::min<long>(long(period / reach), nh));
    const double       width = period / nbins;
    const auto         bin_of = [&](double x) {
      x -= period * std::floor(x / period);
      return std::min<unsigned int>(nbins - 1, static_cast<unsigned int>(x / width));
    };
    std::vector<unsigned int> bin_start(nbins + 1, 0), items(nh);
    for (unsigned int k = 0; k < nh; ++k)
      ++bin_start[bin_of(at[k].centre.x()) + 1];
    for (unsigned int b = 0; b < nbins; ++b)
      bin_start[b + 1] += bin_start[b];
    {
      std::vector<unsigned int> fill(bin_start.begin(), bin_start.end() - 1);
      for (unsigned int k = 0; k < nh; ++k)
        items[fill[bin_of(at[k].centre.x())]++] = k;
    }

    for (unsigned int d = 0; d < system.discs.size(); ++d)
      {
        const Vec2  &x = disc_centres[d];
        const double R = system.discs[d].radius;
        if (x.y() < ymin - reach || x.y() > ymax + reach)
          continue;
        // The distinct bins b - 1, b, b + 1 (all of them when there are fewer than 3).
        const unsigned int b0 = bin_of(x.x());
        unsigned int       bins[3];
        unsigned int       n_bins = 0;
        for (int j = -1; j <= 1; ++j)
          {
            const unsigned int b = (b0 + nbins + j) % nbins;
            if (std::find(bins, bins + n_bins, b) == bins + n_bins)
              bins[n_bins++] = b;
          }
        for (unsigned int m = 0; m < n_bins; ++m)
          for (unsigned int i = bin_start[bins[m]]; i < bin_start[bins[m] + 1]; ++i)
            {
              const unsigned int k = items[i];
              const Placement   &p = at[k];
              Vec2               branch = x - p.centre;
              branch.x() -= period * std::round(branch.x() / period);
              const Vec2 e_perp = perp(p.edge);
              if (side * branch.dot(e_perp) <= 0)
                continue; // behind the flat side
              const double dist = branch.norm();
              const double gap  = dist - R - rho;
              if (gap > distance)
                {
                  const Vec2 relative =
                    (disc_motion.empty() ? Vec2(Vec2::Zero()) : disc_motion[d]) - centre_motion[k];
                  if (gap > -relative.dot(branch) / dist)
                    continue; // beyond the distance, and the motions do not close it
                }
              Contact ct;
              ct.disc[0]   = d; // for the warm-start key only (with half_disc)
              ct.disc[1]   = d;
              ct.half_disc = k;
              ct.body[0] = ct.body[1] = system.discs[d].body;
              ct.normal = branch / dist;
              ct.branch = branch;
              ct.gap    = gap;
              // The half-disc's material point at the contact point: the centre's
              // interpolation plus the edge's rotation (dem/engine/boundary.h).
              const Vec2            a  = (rho + 0.5 * gap) * ct.normal;
              const Eigen::Matrix2d turn = perp(a) * e_perp.transpose() / p.edge.squaredNorm();
              const double          xi = anchor_xi[k];
              ct.node[0]     = anchor_edge[k];
              ct.node[1]     = (anchor_edge[k] + 1) % nodes.size();
              ct.node_map[0] = (1 - xi) * Eigen::Matrix2d::Identity() - turn;
              ct.node_map[1] = xi * Eigen::Matrix2d::Identity() + turn;
              const Vec2 t(-ct.normal.y(), ct.normal.x());
              const Vec2 arm1 = rotate(system.discs[d].offset, body_angles[ct.body[1]]) + a - branch;
              ct.arm_n[0] = ct.arm_t[0] = 0;
              ct.arm_n[1] = cross(arm1, ct.normal);
              ct.arm_t[1] = cross(arm1, t);
              found.push_back(ct);
            }
      }
    return found;
  }
} // namespace tribo::dem
