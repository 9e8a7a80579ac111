/// @file The MLP scene mlp_beams (Popov and Filippov 2006, section 5): two beams pressed
/// together and rubbed, the "liquid layer" at their contact (Fig. 6). A scene of the MLP
/// family (app/scenes/mlp_family.h), subsections "MLP" and "MLP beams".
/// 2D, per unit depth: masses kg/m, forces N/m, pressures Pa, energies J/m.

#include "app/scene_hooks.h"
#include "app/scenes/mlp_family.h"
#include "app/steady_state.h"
#include "mlp/analysis.h"
#include "mlp/particles.h"
#include "core/serialization.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace tribo::app
{
  using namespace mlp_scenes;

  namespace
  {
    /// mlp_beams: two lattice beams stacked along y in a box periodic along x (beams of
    /// infinite length) and y (a gap of 3 r0 across the y-period, beyond the interaction
    /// range, so that the beams touch only at their contact). The contact plane is
    /// horizontal, a row plane of the lattice (for the hexagonal lattice the close-packed
    /// plane, its easy slip plane); the paper's profile "along x, orthogonal to the
    /// contact" is our profile along y. The upper beam is shifted along x by `Interface
    /// offset` r0 from the natural stacking (a stacking fault at the contact). The outer
    /// row of each beam carries the pressing load +-P r0 along y (lower beam up, upper
    /// beam down); the transverse load, total +-tau L_x sin(2 pi f t) per beam along x
    /// (lower +, upper -), acts on every particle of the beam (+-tau r0 / ny: a body
    /// force, shear stress rising from 0 at the outer row to tau at the contact) or on
    /// the outer row (+-tau r0 per particle: uniform shear stress tau).
    /// Profile: mean |F_return| in layers along y (eq. 24, averaged over x and over time
    /// after Profile start).
    class BeamsScene : public MlpScene
    {
    public:
      BeamsScene(const ParameterFile &f, const CommonSettings &c) : s(c)
      {
        nx        = count(f, "MLP beams/Columns", 4);
        ny        = count(f, "MLP beams/Rows per beam", 2);
        pressure  = f.get_checked("MLP beams/Pressure", is_non_negative, "a pressure >= 0 in Pa");
        tau       = f.get_checked("MLP beams/Transverse traction", is_non_negative, "a traction amplitude >= 0 in Pa");
        freq      = f.get_checked("MLP beams/Frequency", is_positive, "a positive frequency in Hz");
        offset    = f.get_checked("MLP beams/Interface offset", [](double v) { return v >= 0 && v < 1; },
                            "a fraction of r0 in [0, 1)");
        start     = f.get_checked("MLP beams/Profile start", is_non_negative, "a time >= 0 in s");
        layer     = f.get_checked("MLP beams/Layer thickness", is_positive,
                            "a positive thickness in row spacings, e.g. 1"); // times h_row in build()
        body_load = f.get("MLP beams/Transverse load on") == "body";
      }

      void build(Particles &p, mlp::Box &box) override
      {
        const double c  = s.interaction.r0;
        const bool   hx = s.lattice == mlp::LatticeType::hexagonal;
        h_row           = hx ? 0.5 * std::sqrt(3.0) * c : c;
        layer *= h_row;
        box.periodic_x = box.periodic_y = true;
        box.lx         = nx * c;
        box.ly         = (2 * ny - 1) * h_row + 3 * c;
        const Vec2 lower(0.25 * c, 1.5 * c);
        mlp::add_lattice_patch(p, s.lattice, lower, nx, ny, c, s.mass, 0);
        // Natural stacking: row ny of one lattice is shifted by c/2 if ny is odd (hexagonal).
        const double natural = (hx && ny % 2 == 1) ? 0.5 * c : 0.0;
        mlp::add_lattice_patch(p, s.lattice, lower + Vec2(natural + offset * c, ny * h_row), nx, ny, c,
                               s.mass, 1);
        for (auto &x : p.position)
          x = box.wrap(x);
        contact_y = lower.y() + (ny - 0.5) * h_row;
        bins      = static_cast<unsigned int>(std::ceil(box.ly / layer));
        sum_net.assign(bins, 0.0);
        sum_bond.assign(bins, 0.0);
        samples.assign(bins, 0.0);
        for (unsigned int b = 0; b < 2; ++b)
          beam_y0[b] = mean_y(p, b);
      }

      /// Mean y of beam @p b (m); the beams do not cross the y-period.
      static double mean_y(const Particles &p, unsigned int b)
      {
        double       sum = 0;
        unsigned int n   = 0;
        for (unsigned int i = 0; i < p.size(); ++i)
          if (p.group[i] == b)
            {
              sum += p.position[i].y();
              ++n;
            }
        return sum / n;
      }

      void set_loads(Particles &p, double t) override
      {
        const double c = s.interaction.r0;
        forcing        = tau * std::sin(2 * M_PI * freq * t);
        const double fx = body_load ? forcing * c / ny : 0.0;
        for (unsigned int i = 0; i < p.size(); ++i)
          p.external_force[i] = Vec2(p.group[i] == 0 ? fx : -fx, 0);
        const double outer = body_load ? 0.0 : forcing * c;
        for (unsigned int i = 0; i < nx; ++i)
          {
            p.external_force[i] += Vec2(outer, pressure * c);                            // lower beam, row 0
            p.external_force[2 * nx * ny - nx + i] += Vec2(-outer, -pressure * c);       // upper beam, top row
          }
      }

      void after_step(MlpWorld &w) override
      {
        Particles   &p  = w.particles;
        const double dt = w.dt;
        // Mean x displacement of each beam, by integrating its mean velocity (the
        // positions wrap along x).
        double v[2] = {0, 0};
        for (unsigned int i = 0; i < p.size(); ++i)
          v[p.group[i]] += p.velocity[i].x();
        for (unsigned int b = 0; b < 2; ++b)
          displacement[b] += dt * v[b] / (nx * ny);
      }

      void measure(const MlpWorld &w, Row &row) override
      {
        const Particles       &p     = w.particles;
        const mlp::Box        &box   = w.box;
        const mlp::ForceField &field = *w.field;
        const double           t     = w.time;
        if (t >= start)
          sample_profile(p, box, field);
        row("transverse_traction", forcing)("slip", displacement[0] - displacement[1])
          ("beam_gap_change", (mean_y(p, 1) - mean_y(p, 0)) - (beam_y0[1] - beam_y0[0]))
          ("coordination", mean_coordination(field, p, box));
      }

      /// Adds the per-particle |F_return| (net and bond mean) to the layer of each particle,
      /// and this row's contact and bulk means (RowMeans) to the rows' series.
      void sample_profile(const Particles &p, const mlp::Box &box, const mlp::ForceField &field)
      {
        std::vector<double> net, bond;
        return_force_magnitudes(field, p, box, net, bond);
        std::vector<double> row_net(bins, 0.0), row_bond(bins, 0.0), row_n(bins, 0.0);
        for (unsigned int i = 0; i < p.size(); ++i)
          {
            const unsigned int b = std::min(bins - 1, static_cast<unsigned int>(p.position[i].y() / layer));
            row_net[b] += net[i];
            row_bond[b] += bond[i];
            row_n[b] += 1;
          }
        for (unsigned int b = 0; b < bins; ++b)
          {
            sum_net[b] += row_net[b];
            sum_bond[b] += row_bond[b];
            samples[b] += row_n[b];
          }
        const RowMeans m = contact_and_bulk(row_net, row_bond, row_n);
        for (unsigned int k = 0; k < 4; ++k)
          row_means[k].push_back(m[k]);
      }

      /// Mean of @p sum over the layers whose centre is within @p half of @p y0 (m), @p n
      /// the particle samples per layer.
      double window(const std::vector<double> &sum, const std::vector<double> &n, double y0, double half) const
      {
        double v = 0, count = 0;
        for (unsigned int b = 0; b < bins; ++b)
          if (std::abs((b + 0.5) * layer - y0) <= half)
            {
              v += sum[b];
              count += n[b];
            }
        return count > 0 ? v / count : 0.0;
      }

      /// Mean |F_return| (N/m) at the contact and in the bulk (the mean of the two beams'
      /// mid-planes), within 1.5 row spacings: {contact net, bulk net, contact bond, bulk bond}.
      using RowMeans = std::array<double, 4>;
      RowMeans contact_and_bulk(const std::vector<double> &net, const std::vector<double> &bond,
                                const std::vector<double> &n) const
      {
        const double half_beam = 0.5 * ny * h_row, w = 1.5 * h_row;
        const auto   bulk      = [&](const std::vector<double> &sum) {
          return 0.5 * (window(sum, n, contact_y - half_beam, w) + window(sum, n, contact_y + half_beam, w));
        };
        return {{window(net, n, contact_y, w), bulk(net), window(bond, n, contact_y, w), bulk(bond)}};
      }

      /// Batch-means standard error of the contact-over-bulk ratio of series @p c and @p b
      /// of row_means (the ratio formed per batch).
      double ratio_stderr(unsigned int c, unsigned int b) const
      {
        std::vector<double>       ratio = batch_means(row_means[c]);
        const std::vector<double> bulk  = batch_means(row_means[b]);
        for (std::size_t k = 0; k < ratio.size(); ++k)
          ratio[k] = bulk[k] > 0 ? ratio[k] / bulk[k] : 0.0;
        return batch_standard_error(ratio);
      }

      void summarize(const MlpWorld &, const TimeSeries &stats, JsonObject &results) override
      {
        auto &tables = made_tables;
        TimeSeries profile({"y", "y_from_contact", "f_return_net", "f_return_bond", "n_samples"});
        for (unsigned int b = 0; b < bins; ++b)
          profile.add_row({(b + 0.5) * layer, (b + 0.5) * layer - contact_y,
                           samples[b] ? sum_net[b] / samples[b] : 0.0,
                           samples[b] ? sum_bond[b] / samples[b] : 0.0, samples[b]});
        tables["profiles"] = profile;
        const auto [contact_net, bulk_net, contact_bond, bulk_bond] = contact_and_bulk(sum_net, sum_bond, samples);
        results.set("contact_y", contact_y);
        results.set("f_return_net_contact", contact_net);
        results.set("f_return_net_bulk", bulk_net);
        results.set("f_return_bond_contact", contact_bond);
        results.set("f_return_bond_bulk", bulk_bond);
        results.set("contact_over_bulk_bond", bulk_bond > 0 ? contact_bond / bulk_bond : 0.0);
        results.set("contact_over_bulk_net", bulk_net > 0 ? contact_net / bulk_net : 0.0);
        results.set("contact_over_bulk_bond_stderr", ratio_stderr(2, 3));
        results.set("contact_over_bulk_net_stderr", ratio_stderr(0, 1));
        const auto slip = stats.column("slip");
        double     amp  = 0;
        for (double v : slip)
          amp = std::max(amp, std::abs(v));
        results.set("slip_max", amp);
        results.set("slip_final", slip.back());
      }

      /// The transverse load, the beams' displacements and the profile sums.
      void save(CheckpointOut &ar) const override
      {
        ar << forcing << displacement << sum_net << sum_bond << samples << row_means;
      }
      void load(CheckpointIn &ar) override
      {
        ar >> forcing >> displacement >> sum_net >> sum_bond >> samples >> row_means;
      }

    private:
      CommonSettings s;
      unsigned int   nx = 0, ny = 0, bins = 0;
      bool           body_load = true;
      double pressure = 0, tau = 0, freq = 0, offset = 0, start = 0, layer = 0, h_row = 0;
      double contact_y = 0, forcing = 0, displacement[2] = {0, 0}, beam_y0[2] = {0, 0};
      std::vector<double> sum_net, sum_bond, samples;
      std::array<std::vector<double>, 4> row_means; ///< per profile row, RowMeans' four series
    };

    /// The scene, its subsection "MLP beams" read.
    std::unique_ptr<MlpScene> make_scene(const ParameterFile &f, const CommonSettings &s)
    {
      return std::make_unique<BeamsScene>(f, s);
    }
  } // namespace

  void declare_mlp_beams_parameters(dealii::ParameterHandler &prm)
  {
    using dealii::Patterns::Double;
    using dealii::Patterns::Integer;
    using dealii::Patterns::Selection;
    prm.enter_subsection("MLP beams");
    prm.declare_entry("Columns", "32", Integer(4), "Particles per row (along x, the periodic contact length), >= 4.");
    prm.declare_entry("Rows per beam", "12", Integer(2), "Rows of each beam (along y, across the contact), >= 2.");
    prm.declare_entry("Pressure", "5e7", Double(), "Pressing traction on the outer rows, Pa (>= 0).");
    prm.declare_entry("Transverse traction", "5e7", Double(), "Amplitude tau of the sinusoidal transverse traction, Pa (>= 0).");
    prm.declare_entry("Transverse load on", "body", Selection("body|outer row"),
                      "Where the transverse traction acts: 'body' (spread over every particle of a beam, "
                      "shear stress largest at the contact) or 'outer row' (uniform shear stress).");
    prm.declare_entry("Frequency", "1e7", Double(), "Frequency f of the transverse traction, Hz (> 0).");
    prm.declare_entry("Interface offset", "0.5", Double(), "x-shift of the upper beam from the natural stacking, fraction of r0 in [0, 1).");
    prm.declare_entry("Profile start", "2e-7", Double(), "Time from which the |F_return| profile is averaged, s (>= 0).");
    prm.declare_entry("Layer thickness", "1", Double(), "Thickness of the profile layers along y, in row spacings (> 0; 1: one row per layer).");
    prm.leave_subsection();
  }

  SceneHooks mlp_beams_hooks()
  {
    return mlp_scenes::hooks<make_scene>(declare_mlp_beams_parameters);
  }
} // namespace tribo::app
