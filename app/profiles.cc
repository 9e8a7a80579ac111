#include "app/profiles.h"
#include "app/steady_state.h"

#include <boost/archive/binary_iarchive.hpp>
#include <boost/archive/binary_oarchive.hpp>
#include <boost/serialization/vector.hpp>

#include <algorithm>
#include <cmath>

namespace tribo::app
{
  namespace
  {
    enum Quantity
    {
      q_vx,
      q_solid_fraction,
      q_sxx,
      q_syy,
      q_sxy,
      q_syx,
      q_count,
      q_power,
      q_temperature,
      n_quantities
    };

    /// Area of the part of a disc (radius r, centre at 0) below the line y = s.
    double area_below(double s, double r)
    {
      if (s <= -r)
        return 0;
      if (s >= r)
        return M_PI * r * r;
      return r * r * std::acos(-s / r) + s * std::sqrt(r * r - s * s);
    }
  } // namespace

  double disc_area_between(double yc, double r, double a, double b)
  {
    return area_below(b - yc, r) - area_below(a - yc, r);
  }

  const std::vector<std::string> &LayerProfiles::quantity_names()
  {
    static const std::vector<std::string> names = {"vx", "solid_fraction", "sigma_xx", "sigma_yy",
                                                   "sigma_xy", "sigma_yx", "n_discs", "power_dissipated",
                                                   "granular_temperature"};
    return names;
  }

  std::vector<std::string> LayerProfiles::average_columns()
  {
    std::vector<std::string> c = {"layer", "y", "y_over_h"};
    for (const auto &n : quantity_names())
      c.push_back(n);
    c.push_back("n_samples");
    for (const auto &n : quantity_names())
      c.push_back(n + "_stderr");
    return c;
  }

  LayerProfiles::LayerProfiles(unsigned int lower, unsigned int upper, double wall_inset,
                               double layer_target)
    : lower(lower)
    , upper(upper)
    , inset(wall_inset)
    , target(layer_target)
  {}

  void LayerProfiles::accumulate(const dem::ParticleSystem &s, const dem::MoreauJean &mj, double upper_surface)
  {
    const double y_l = s.bodies[lower].position.y() + inset, y_u = upper_surface;
    const double H   = y_u - y_l;
    if (layers == 0)
      layers = std::max(1, int(std::lround(H / target)));
    const double thickness = H / layers;
    const double length    = s.period;
    const double area      = thickness * length;
    std::vector<double> row(layers * n_quantities, 0.0);
    auto layer_of = [&](double y) { return int(std::floor((y - y_l) / thickness)); };
    // Grains nestled between wall discs (centre beyond a wall surface) count in the
    // layer next to that wall.
    auto grain_layer = [&](double y) { return std::clamp(layer_of(y), 0, int(layers) - 1); };

    // Velocities and areas of the discs, summed over the MPI ranks when the state is split
    // over them (each counts the grains it owns and rank 0 the walls).
    for (std::size_t d = 0; d < s.discs.size(); ++d)
      {
        const auto  &disc = s.discs[d];
        if (!mj.counts(disc.body))
          continue;
        const auto  &body = s.bodies[disc.body];
        const double yc   = s.disc_centre(d).y();
        const int    k    = grain_layer(yc);
        const bool   free = disc.body != lower && disc.body != upper;
        if (free)
          {
            row[k * n_quantities + q_vx] += body.velocity.x();
            row[k * n_quantities + q_count] += 1;
          }
        const int k0 = std::max(0, layer_of(yc - disc.radius)), k1 = std::min(int(layers) - 1, layer_of(yc + disc.radius));
        for (int j = k0; j <= k1; ++j)
          row[j * n_quantities + q_solid_fraction] +=
            disc_area_between(yc, disc.radius, y_l + j * thickness, y_l + (j + 1) * thickness) / area;
      }
    // Mean velocity per layer, then the fluctuations about it.
    std::vector<double> vy_mean(layers, 0.0);
    for (std::size_t d = 0; d < s.discs.size(); ++d)
      if (s.discs[d].body != lower && s.discs[d].body != upper && mj.counts(s.discs[d].body))
        vy_mean[grain_layer(s.disc_centre(d).y())] += s.bodies[s.discs[d].body].velocity.y();
    {
      std::vector<double> sums = row;
      sums.insert(sums.end(), vy_mean.begin(), vy_mean.end());
      mj.sum_over_shares(sums);
      std::copy(sums.begin(), sums.begin() + row.size(), row.begin());
      std::copy(sums.begin() + row.size(), sums.end(), vy_mean.begin());
    }
    for (unsigned int k = 0; k < layers; ++k)
      if (row[k * n_quantities + q_count] > 0)
        {
          row[k * n_quantities + q_vx] /= row[k * n_quantities + q_count];
          vy_mean[k] /= row[k * n_quantities + q_count];
        }
    std::vector<double> temperature(layers, 0.0);
    for (std::size_t d = 0; d < s.discs.size(); ++d)
      if (s.discs[d].body != lower && s.discs[d].body != upper && mj.counts(s.discs[d].body))
        {
          const int        k = grain_layer(s.disc_centre(d).y());
          const dem::Vec2 &v = s.bodies[s.discs[d].body].velocity;
          const double     n = row[k * n_quantities + q_count];
          if (n > 1)
            temperature[k] +=
              0.5 * (std::pow(v.x() - row[k * n_quantities + q_vx], 2) + std::pow(v.y() - vy_mean[k], 2)) / n;
        }
    mj.sum_over_shares(temperature);
    for (unsigned int k = 0; k < layers; ++k)
      row[k * n_quantities + q_temperature] = temperature[k];

    // What the contacts add, summed over the MPI ranks when each holds its share of them.
    std::vector<double> from_contacts(row.size(), 0.0);
    // Love-Weber stresses, spread along the lever arms: each contact adds
    // -f (x) l / A for each free disc it touches (l from the disc centre to the
    // contact point), shared among the layers that l crosses in proportion to the
    // part of its height in each (all in the centre's layer for a horizontal l).
    // A static layer then carries exactly the force transmitted across its planes.
    const auto spread = [&](double y0, double y1, const dem::Vec2 &f, const dem::Vec2 &l) {
      const double c[4] = {-f.x() * l.x() / area, -f.y() * l.y() / area, -f.x() * l.y() / area,
                           -f.y() * l.x() / area};
      const double lo = std::min(y0, y1), hi = std::max(y0, y1);
      const int    k0 = grain_layer(lo), k1 = grain_layer(hi);
      for (int k = k0; k <= k1; ++k)
        {
          double w = 1;
          if (k1 > k0)
            {
              const double a = std::max(lo, k == 0 ? lo : y_l + k * thickness);
              const double b = std::min(hi, k == int(layers) - 1 ? hi : y_l + (k + 1) * thickness);
              w              = std::max(0.0, b - a) / (hi - lo);
            }
          from_contacts[k * n_quantities + q_sxx] += w * c[0];
          from_contacts[k * n_quantities + q_syy] += w * c[1];
          from_contacts[k * n_quantities + q_sxy] += w * c[2];
          from_contacts[k * n_quantities + q_syx] += w * c[3];
        }
    };
    const auto &contacts = mj.contacts();
    for (std::size_t i = 0; i < contacts.size(); ++i)
      {
        const dem::Contact &c = contacts[i];
        if (c.r.x() == 0 && c.r.y() == 0)
          continue;
        // What the contact dissipates, in the layer of its contact point (from disc 1,
        // which is a disc whatever side 0 is).
        from_contacts[grain_layer(s.disc_centre(c.disc[1]).y() - (s.discs[c.disc[1]].radius + 0.5 * c.gap) * c.normal.y()) *
              n_quantities +
            q_power] -= mj.contact_power()[i];
        const dem::Vec2 t(-c.normal.y(), c.normal.x());
        const dem::Vec2 f1 = (c.r.x() * c.normal + c.r.y() * t) / mj.step_length(); // on disc 1, over the last (sub-)step
        // Lever arms from each disc centre to the contact point (middle of the gap).
        const dem::Vec2 l0 = (s.discs[c.disc[0]].radius + 0.5 * c.gap) * c.normal;
        const dem::Vec2 l1 = -(s.discs[c.disc[1]].radius + 0.5 * c.gap) * c.normal;
        // Side 0 of a half-disc contact is the deformable first body, not a grain.
        for (int side = c.on_boundary() ? 1 : 0; side < 2; ++side)
          {
            const unsigned int b = c.body[side];
            if (b == lower || b == upper)
              continue;
            const dem::Vec2 f  = side == 0 ? dem::Vec2(-f1) : f1;
            const dem::Vec2 l  = side == 0 ? l0 : l1;
            const double    yc = s.disc_centre(c.disc[side]).y();
            spread(yc, yc + l.y(), f, l);
          }
      }
    mj.sum_over_shares(from_contacts);
    for (std::size_t j = 0; j < row.size(); ++j)
      row[j] += from_contacts[j];
    if (block_sum.empty())
      block_sum.assign(row.size(), 0.0);
    for (std::size_t j = 0; j < row.size(); ++j)
      block_sum[j] += row[j];
    block_gap += H;
    ++block_steps;
  }

  void LayerProfiles::end_block(double t_begin)
  {
    if (block_steps == 0)
      return;
    for (double &x : block_sum)
      x /= block_steps;
    times.push_back(t_begin);
    gap.push_back(block_gap / block_steps);
    data.push_back(std::move(block_sum));
    block_sum.clear();
    block_gap   = 0;
    block_steps = 0;
  }

  unsigned int LayerProfiles::n_samples_after(double t_start) const
  {
    return std::count_if(times.begin(), times.end(), [&](double t) { return t >= t_start; });
  }

  std::vector<std::vector<double>> LayerProfiles::average(double t_start) const
  {
    std::vector<std::vector<double>> out;
    const unsigned int               n = n_samples_after(t_start);
    if (n == 0 || layers == 0)
      return out;
    double mean_gap = 0;
    std::vector<double> sum(layers * n_quantities, 0.0);
    std::vector<std::vector<double>> series(layers * n_quantities); ///< per column, time order
    for (std::size_t i = 0; i < times.size(); ++i)
      if (times[i] >= t_start)
        {
          mean_gap += gap[i] / n;
          for (std::size_t j = 0; j < sum.size(); ++j)
            {
              sum[j] += data[i][j] / n;
              series[j].push_back(data[i][j]);
            }
        }
    for (unsigned int k = 0; k < layers; ++k)
      {
        const double        y = (k + 0.5) * mean_gap / layers;
        std::vector<double> r = {double(k), y, y / mean_gap};
        for (int q = 0; q < n_quantities; ++q)
          r.push_back(sum[k * n_quantities + q]);
        r.push_back(n);
        for (int q = 0; q < n_quantities; ++q)
          r.push_back(batch_standard_error(batch_means(series[k * n_quantities + q])));
        out.push_back(r);
      }
    return out;
  }

  std::pair<double, double> LayerProfiles::interior_mean(const std::string &quantity, double t_start) const
  {
    const auto names = quantity_names();
    const int  q     = std::find(names.begin(), names.end(), quantity) - names.begin();
    if (q == int(names.size()) || layers < 5 || n_samples_after(t_start) == 0)
      return {NAN, NAN};
    std::vector<double> series; // per sample: the mean over layers 2 .. n - 3
    for (std::size_t i = 0; i < times.size(); ++i)
      if (times[i] >= t_start)
        {
          double sum = 0;
          for (unsigned int k = 2; k + 2 < layers; ++k)
            sum += data[i][k * n_quantities + q];
          series.push_back(sum / (layers - 4));
        }
    double mean = 0;
    for (const double x : series)
      mean += x / series.size();
    return {mean, batch_standard_error(batch_means(series))};
  }
  void LayerProfiles::save(CheckpointOut &ar) const
  {
    ar << layers << times << gap << data << block_sum << block_gap << block_steps;
  }

  void LayerProfiles::load(CheckpointIn &ar)
  {
    ar >> layers >> times >> gap >> data >> block_sum >> block_gap >> block_steps;
  }
} // namespace tribo::app
