#include "dem/boundary.h"

#include "core/errors.h"
#include "dem/contact.h"

#include <algorithm>
#include <cmath>

namespace tribo::dem
{
  HalfDiscs::HalfDiscs(const BoundaryBody &body, double diameter_, const Vec2 &outward_,
                       double period_)
    : diameter(diameter_)
    , outward(outward_.normalized())
    , period(period_)
  {
    if (!(diameter > 0) || !(period > 0) || body.n_nodes() < 2)
      throw RunError("half-disc elements need a positive diameter and period and at least two "
                     "boundary nodes");
    for (unsigned int i = 0; i < body.n_nodes(); ++i)
      node_abscissa.push_back(body.node_position(i).x());
    if (!std::is_sorted(node_abscissa.begin(), node_abscissa.end()) ||
        node_abscissa.front() < 0 || node_abscissa.back() >= period)
      throw RunError("boundary nodes must be ordered by x within [0, period)");
    const unsigned int n = std::max(1L, std::lround(period / diameter));
    for (unsigned int k = 0; k < n; ++k)
      centre_abscissa.push_back((k + 0.5) * period / n);
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

  Vec2 HalfDiscs::point_at(double s, const std::vector<Vec2> &nodes) const
  {
    const auto [e, xi] = locate(s);
    const unsigned int n = nodes.size();
    Vec2               b = nodes[(e + 1) % n];
    if (e + 1 == n)
      b.x() += period; // the wrapping edge ends at node 0's periodic image
    Vec2 a = nodes[e];
    // Keep the point near abscissa s (node positions are not wrapped).
    Vec2 p = (1 - xi) * a + xi * b;
    p.x() -= period * std::floor((p.x() - (s - 0.5 * period)) / period);
    return p;
  }

  std::vector<Vec2> HalfDiscs::centres(const std::vector<Vec2> &nodes) const
  {
    std::vector<Vec2> c;
    for (const double s : centre_abscissa)
      c.push_back(point_at(s, nodes));
    return c;
  }

  std::vector<Contact> HalfDiscs::detect(const ParticleSystem &system,
                                         const std::vector<Vec2> &disc_centres,
                                         const std::vector<double> &body_angles,
                                         const std::vector<Vec2> &nodes, double distance) const
  {
    std::vector<Contact> found;
    const std::vector<Vec2> c = centres(nodes);
    const unsigned int      nh = c.size();
    const double            spacing = period / nh, rho = radius();
    const double            reach = rho + system.max_radius() + distance;
    const int               span  = int(std::ceil(reach / spacing)) + 1;
    for (unsigned int d = 0; d < system.discs.size(); ++d)
      {
        const Vec2  &x = disc_centres[d];
        const double R = system.discs[d].radius;
        const int    k0 = int(std::floor(x.x() / spacing));
        const bool   all = 2 * span + 1 >= int(nh); // the window covers every half-disc
        for (int j = all ? 0 : -span; j <= (all ? int(nh) - 1 : span); ++j)
          {
            const unsigned int k = all ? j : ((k0 + j) % int(nh) + nh) % nh;
            Vec2 branch = x - c[k];
            branch.x() -= period * std::round(branch.x() / period);
            if (branch.dot(outward) <= 0)
              continue; // behind the flat side
            const double dist = branch.norm();
            const double gap  = dist - R - rho;
            if (gap > distance)
              continue;
            Contact ct;
            ct.disc[0] = d; // for the warm-start key only (with half_disc)
            ct.disc[1] = d;
            ct.half_disc = k;
            ct.body[0] = ct.body[1] = system.discs[d].body;
            ct.normal = branch / dist;
            ct.branch = branch;
            ct.gap    = gap;
            // Contact point and its projection on the chain.
            const Vec2   point_from_centre = (rho + 0.5 * gap) * ct.normal;
            const double s_p = centre_abscissa[k] + point_from_centre.x();
            const auto [e, xi] = locate(s_p);
            ct.node[0]        = e;
            ct.node[1]        = (e + 1) % nodes.size();
            ct.node_weight[0] = 1 - xi;
            ct.node_weight[1] = xi;
            const Vec2 t(-ct.normal.y(), ct.normal.x());
            const Vec2 arm1 = rotate(system.discs[d].offset, body_angles[ct.body[1]]) +
                              point_from_centre - branch;
            ct.arm_n[0] = ct.arm_t[0] = 0;
            ct.arm_n[1] = cross(arm1, ct.normal);
            ct.arm_t[1] = cross(arm1, t);
            found.push_back(ct);
          }
      }
    return found;
  }
} // namespace tribo::dem
