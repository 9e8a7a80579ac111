/// @file The MLP scene mlp_ordering (Popov and Filippov 2006, section 5): particles
/// ordering from random positions into a lattice (Fig. 2). A scene of the MLP family
/// (app/scenes/mlp_family.h), subsections "MLP" and "MLP ordering".
/// 2D, per unit depth: masses kg/m, forces N/m, pressures Pa, energies J/m.

#include "app/scene_hooks.h"
#include "app/scenes/mlp_family.h"
#include "mlp/analysis.h"
#include "mlp/particles.h"

#include <algorithm>
#include <cmath>
#include <complex>

namespace tribo::app
{
  using namespace mlp_scenes;

  namespace
  {
    /// mlp_ordering: N particles at random positions (no two closer than d_min) in a
    /// rectangle `Region enlargement` times the ideal packing area, open boundaries, a
    /// capped steepest descent removing the worst overlaps (x += min(|F|/k_c, 0.02 r0)
    /// F/|F| per iteration), then Langevin dynamics at low temperature. Result: the
    /// structure factor S(q) = |sum_k exp(-i q.x_k)|^2 / N (FT of the two-point density
    /// correlation, eqs. 19-21) on a grid, and its angular harmonics on the Bragg ring.
    class OrderingScene : public MlpScene
    {
    public:
      OrderingScene(const ParameterFile &f, const CommonSettings &c) : s(c)
      {
        n_particles   = count(f, "MLP ordering/Particles", 2);
        enlargement   = f.get_checked("MLP ordering/Region enlargement", [](double v) { return v >= 1 && v <= 4; },
                                "a factor in [1, 4], e.g. 1.2");
        aspect        = f.get_checked("MLP ordering/Aspect ratio", is_positive, "a positive width/height ratio");
        min_distance  = f.get_checked("MLP ordering/Minimum distance", [](double v) { return v > 0 && v < 1; },
                                "a fraction of r0 in (0, 1), e.g. 0.75") * s.interaction.r0;
        relaxation    = count(f, "MLP ordering/Relaxation iterations", 0);
        grid          = count(f, "MLP ordering/Structure factor points", 11) | 1u;
        q_range       = f.get_checked("MLP ordering/Structure factor range", [](double v) { return v > 1.2; },
                                "a multiple > 1.2 of the first Bragg wave number, e.g. 1.6");
      }

      void build(Particles &p, mlp::Box &box) override
      {
        box = mlp::Box();
        const Vec2 size = mlp::random_region_size(s.lattice, n_particles, s.interaction.r0, aspect, enlargement);
        mlp::add_random_particles(p, Vec2::Zero(), size, n_particles, min_distance, s.mass, s.langevin.seed);
      }

      void prepare(Particles &p, const mlp::Box &box, mlp::ForceField &field, Log &log) override
      {
        const double cap = 0.02 * s.interaction.r0;
        for (unsigned int k = 0; k < relaxation; ++k)
          {
            field.compute(p, box);
            for (unsigned int i = 0; i < p.size(); ++i)
              {
                const double f = p.force[i].norm();
                if (f > 0)
                  p.position[i] += std::min(f / s.interaction.stiffness, cap) / f * p.force[i];
              }
          }
        log("mlp_ordering: " + std::to_string(p.size()) + " random particles, " +
            std::to_string(relaxation) + " capped relaxation iterations");
      }

      void measure(const MlpWorld &w, Row &row) override
      {
        const Particles &p = w.particles;
        row("extent_x", mlp::extent(p, 0))("extent_y", mlp::extent(p, 1));
      }

      /// Bragg wave number of the first shell, 1/m: 4 pi/(sqrt(3) c) hexagonal, 2 pi/c square.
      double bragg() const
      {
        const double c = s.interaction.r0;
        return s.lattice == mlp::LatticeType::hexagonal ? 4 * M_PI / (std::sqrt(3.0) * c) : 2 * M_PI / c;
      }

      void summarize(const MlpWorld &w, const TimeSeries &, JsonObject &results) override
      {
        const Particles       &p      = w.particles;
        const mlp::Box        &box    = w.box;
        const mlp::ForceField &field  = *w.field;
        auto                  &tables = made_tables;
        const double q_b = bragg();
        const auto   S   = mlp::structure_factor(p, q_range * q_b, grid);
        TimeSeries   table({"qx", "qy", "S"});
        // Angular harmonics A_m = |sum S e^{i m theta}| / sum S over the ring
        // 0.85 q_B < |q| < 1.15 q_B: 1 for m-fold delta peaks, 0 for a uniform ring.
        std::complex<double> h4 = 0, h6 = 0;
        double               ring = 0;
        for (unsigned int b = 0; b < S.ny; ++b)
          for (unsigned int a = 0; a < S.nx; ++a)
            {
              const double qx = S.x0 + a * S.dx, qy = S.y0 + b * S.dy, v = S(a, b);
              table.add_row({qx, qy, v});
              const double q = std::hypot(qx, qy) / q_b;
              if (q > 0.85 && q < 1.15)
                {
                  const double th = std::atan2(qy, qx);
                  h4 += v * std::polar(1.0, 4 * th);
                  h6 += v * std::polar(1.0, 6 * th);
                  ring += v;
                }
            }
        tables["structure_factor"] = table;
        results.set("bragg_wave_number", q_b);
        results.set("harmonic_4", ring > 0 ? std::abs(h4) / ring : 0.0);
        results.set("harmonic_6", ring > 0 ? std::abs(h6) / ring : 0.0);
        results.set("mean_coordination", mean_coordination(field, p, box));
        results.set("n_particles", long(p.size()));
      }

    private:
      CommonSettings s;
      unsigned int   n_particles = 0, relaxation = 0, grid = 0;
      double         enlargement = 1, aspect = 1, min_distance = 0, q_range = 1.6;
    };

    /// The scene, its subsection "MLP ordering" read.
    std::unique_ptr<MlpScene> make_scene(const ParameterFile &f, const CommonSettings &s)
    {
      return std::make_unique<OrderingScene>(f, s);
    }
  } // namespace

  void declare_mlp_ordering_parameters(dealii::ParameterHandler &prm)
  {
    using dealii::Patterns::Double;
    using dealii::Patterns::Integer;
    prm.enter_subsection("MLP ordering");
    prm.declare_entry("Particles", "256", Integer(2), "Number of particles (paper: 256).");
    prm.declare_entry("Region enlargement", "1.2", Double(), "Area of the random region over the ideal packing area, in [1, 4].");
    prm.declare_entry("Aspect ratio", "1", Double(), "Width/height of the random region (> 0).");
    prm.declare_entry("Minimum distance", "0.75", Double(), "Smallest initial distance between particles, fraction of r0 in (0, 1).");
    prm.declare_entry("Relaxation iterations", "300", Integer(0),
                      "Capped steepest-descent iterations before the dynamics (step min(|F|/k_c, 0.02 r0)), >= 0.");
    prm.declare_entry("Structure factor points", "121", Integer(11), "Wave vectors per side of the S(q) grid (made odd), >= 11.");
    prm.declare_entry("Structure factor range", "1.6", Double(), "q_max of the grid over the first Bragg wave number (> 1.2).");
    prm.leave_subsection();
  }

  SceneHooks mlp_ordering_hooks()
  {
    return mlp_scenes::hooks<make_scene>(declare_mlp_ordering_parameters);
  }
} // namespace tribo::app
