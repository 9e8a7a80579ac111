#include "coupling/first_body.h"
#include "coupling/first_body_models.h"

#include "core/errors.h"
#include "core/parameter_file.h"

#include <deal.II/base/parameter_handler.h>

#include <cmath>
#include <iterator>
#include <stdexcept>
#include <sstream>
#include <tuple>
#include <utility>

#ifdef TRIBO_WITH_FEM
#include "coupling/elastic_boundary.h"
#endif

namespace tribo::coupling
{
#ifdef TRIBO_WITH_SPH
  std::unique_ptr<FirstBody> make_sph_first_body(const FirstBodyParameters &p);
#endif
#ifdef TRIBO_WITH_MLP
  std::unique_ptr<FirstBody> make_mlp_first_body(const FirstBodyParameters &p);
#endif

  namespace
  {
#ifdef TRIBO_WITH_FEM
    std::unique_ptr<FirstBody> make_fem_first_body(const FirstBodyParameters &p);
#endif

    /// The upper first-body models (the Upper body model entry): name, least number of
    /// chain nodes, the build option of their module, their factory (null when the build
    /// left the module out, and for the wall of discs, which the scene builds), and whether
    /// the model is a wall of discs (is_wall_of_discs()).
    struct FirstBodyModel
    {
      const char *name;
      long        min_chain_nodes;
      const char *build_option;
      std::unique_ptr<FirstBody> (*make)(const FirstBodyParameters &);
      bool        wall_of_discs = false;
    };

    const FirstBodyModel models[] = {
      {"rigid", 0, "", nullptr, true},
#ifdef TRIBO_WITH_FEM
      {"fem", 1, "TRIBO_WITH_FEM", make_fem_first_body},
      {"reduced", 1, "TRIBO_WITH_FEM", make_fem_first_body},
#else
      {"fem", 1, "TRIBO_WITH_FEM", nullptr},
      {"reduced", 1, "TRIBO_WITH_FEM", nullptr},
#endif
#ifdef TRIBO_WITH_SPH
      {"sph", 8, "TRIBO_WITH_SPH", make_sph_first_body},
#else
      {"sph", 8, "TRIBO_WITH_SPH", nullptr},
#endif
#ifdef TRIBO_WITH_MLP
      {"mlp", 4, "TRIBO_WITH_MLP", make_mlp_first_body},
#else
      {"mlp", 4, "TRIBO_WITH_MLP", nullptr},
#endif
    };

    /// "rigid, fem, reduced, sph or mlp" (@p last_separator " or ") or
    /// "rigid|fem|reduced|sph|mlp" (separators "|").
    std::string model_names(const std::string &separator, const std::string &last_separator)
    {
      std::string names;
      const std::size_t n = std::size(models);
      for (std::size_t i = 0; i < n; ++i)
        names += (i == 0 ? "" : i + 1 == n ? last_separator : separator) + std::string(models[i].name);
      return names;
    }

    const FirstBodyModel &model_of(const std::string &model)
    {
      for (const FirstBodyModel &m : models)
        if (model == m.name)
          return m;
      throw InputError("unknown upper body model '" + model + "': expected " + model_names(", ", " or "));
    }
    const FirstBodyModel &model_of(const FirstBodyParameters &p) { return model_of(p.model); }
  } // namespace

  bool is_wall_of_discs(const std::string &model) { return model_of(model).wall_of_discs; }

  const std::vector<std::string> &entries_that_may_change_on_resume()
  {
    // The prediction depth says only how the contact solve's prediction of a particle body
    // is computed (its real advances are the same), as the Solver entries do.
    static const std::vector<std::string> entries = {"Upper body prediction depth"};
    return entries;
  }

  void FirstBodyParameters::declare(dealii::ParameterHandler &prm)
  {
    using dealii::Patterns::Double;
    using dealii::Patterns::Integer;
    using dealii::Patterns::Selection;
    prm.declare_entry("Upper body model", "rigid", Selection(model_names("|", "|")),
                      "rigid: a rough wall of discs with the mass of the first body (the paper's "
                      "classical model); fem: a plane-strain elastic body of that thickness "
                      "(deal.II), touched through half-disc elements (the paper's hybrid model); reduced: "
                      "that body condensed onto its contact nodes plus Upper body modes vibration modes "
                      "(Craig-Bampton), cheaper than fem, exact in the static limit; "
                      "sph, mlp: the same body as an SPH (square lattice) or movable-lattice-particle "
                      "(hexagonal lattice) block whose bottom row of particles carries the half-discs, "
                      "sub-cycled inside each contact step (docs/first_bodies.md).");
    prm.declare_entry("Upper body Young's modulus", "1e11", Double(),
                      "E of the deformable upper body, Pa (> 0; paper: 1e11 and 3e9).");
    prm.declare_entry("Upper body Poisson ratio", "0.33", Double(),
                      "nu of the deformable upper body, plane strain (in (-1, 0.5); paper: 0.33; "
                      "mlp: at most 0.25).");
    prm.declare_entry("Upper body cell size", "0", Double(),
                      "Cell size of the fem upper body's mesh, or particle spacing of the sph and mlp "
                      "bodies, m (>= 0); 0: the smallest grain diameter d(1-s), the paper's choice.");
    prm.declare_entry("Upper body smoothing length ratio", "1.2", Double(),
                      "Smoothing length over particle spacing of the sph upper body (in [1, 2]).");
    prm.declare_entry("Upper body Verlet fraction", "0.05", Double(),
                      "Velocity-Verlet step of the mlp upper body as a fraction of its stability limit "
                      "2 / omega_max of the stiffest bond (in (0, 0.5]): smaller is more accurate and "
                      "slower. On the 120-disc cell at the fem body's step the energy books close to "
                      "0.03 % at 0.05 and to 0.17 % at 0.2, which is 3.5 times faster (docs/first_bodies.md).");
    prm.declare_entry("Upper body prediction depth", "3", Double(),
                      "sph and mlp upper bodies: the trial advances of each contact step (the chain's free "
                      "motion the contact solve predicts, and the columns of its compliance) run on the "
                      "bottom rows within this many wave reaches c_p h of the chain, the rows above them "
                      "within the interaction's reach carried at their start velocities, instead of on the "
                      "whole body (>= 0; 0: the whole body, also used when the strip would reach the top). "
                      "The real advance with the solved impulses is always the whole body's, so the books "
                      "are unchanged; a strip too thin shows as a larger linearisation miss. At 3 the "
                      "prediction is the whole body's to 1e-5 (unit tests; 1e-12 at every trial of a "
                      "sheared default-case mlp run) and a paper-size step costs 0.53 (sph) to 0.65 (mlp) "
                      "times as much (docs/first_bodies.md, \"Trial advances on a strip\"). May change on --resume.");
    prm.declare_entry("Upper body element degree", "1", Integer(1, 4),
                      "Degree p of the fem upper body's Q_p elements.");
    prm.declare_entry("Upper body modes", "20", Integer(0),
                      "Fixed-interface vibration modes kept by the reduced upper body (>= 0; 0: static "
                      "condensation plus the load mode only), docs/fem.md.");
    prm.declare_entry("Upper body mass damping", "0", Double(),
                      "Rayleigh coefficient a of C = a M + b K for the fem upper body, 1/s (>= 0).");
    prm.declare_entry("Upper body stiffness damping", "0", Double(),
                      "Rayleigh coefficient b of C = a M + b K for the fem upper body, s (>= 0).");
    prm.declare_entry("Half-disc diameter", "0", Double(),
                      "Diameter of the half-disc contact elements on the fem upper body, m (>= 0); "
                      "0: the cell size (one per boundary edge, the paper's choice).");
    prm.declare_entry("Upper body compaction damping", "1", Double(),
                      "Damping ratio zeta (>= 0) of the deformable upper body's first thickness mode, "
                      "omega_1 = pi c_p / (2 H), added before Shear start as damping of the velocity "
                      "towards rest at gamma = 2 zeta omega_1 (fem: mass-proportional Rayleigh damping) "
                      "and removed when shearing starts: the body then lands on the layer at the "
                      "terminal speed P / (rho H gamma) (0.7 m/s for the paper's steel body) instead of "
                      "falling freely onto it, and does not ring (no numerical damping at theta = 0.5). "
                      "The rigid wall's Compaction speed limit plays this part. 0: off.");
  }

  FirstBodyParameters FirstBodyParameters::parse(const ParameterFile &f, const std::string &section)
  {
    FirstBodyParameters p;
    p.section        = {section};
    const auto entry = [&](const std::string &name) { return p.section.entry(name); };
    p.model          = f.get(entry("Upper body model"));
    p.smoothing_ratio = f.get_checked(entry("Upper body smoothing length ratio"),
                                      [](double v) { return v >= 1 && v <= 2; }, "a ratio in [1, 2]");
    p.verlet_fraction = f.get_checked(entry("Upper body Verlet fraction"), [](double v) { return v > 0 && v <= 0.5; },
                                      "a fraction of the stability limit in (0, 0.5]");
    p.prediction_depth = f.get_checked(entry("Upper body prediction depth"), is_non_negative,
                                       "a depth >= 0 in wave reaches c_p h");
    p.youngs_modulus = f.get_checked(entry("Upper body Young's modulus"), is_positive, "a positive modulus in Pa");
    p.poisson_ratio  = f.get_checked(entry("Upper body Poisson ratio"), [](double v) { return v > -1 && v < 0.5; },
                                     "a Poisson ratio in (-1, 0.5)");
    p.resolution     = f.get_checked(entry("Upper body cell size"), is_non_negative, "a size >= 0 in m");
    p.degree         = f.get_integer(entry("Upper body element degree"));
    p.modes          = f.get_integer(entry("Upper body modes"));
    p.rayleigh_mass  = f.get_checked(entry("Upper body mass damping"), is_non_negative, "a coefficient >= 0 in 1/s");
    p.rayleigh_stiffness =
      f.get_checked(entry("Upper body stiffness damping"), is_non_negative, "a coefficient >= 0 in s");
    p.half_disc_diameter = f.get_checked(entry("Half-disc diameter"), is_non_negative, "a diameter >= 0 in m");
    p.compaction_damping =
      f.get_checked(entry("Upper body compaction damping"), is_non_negative, "a damping ratio >= 0");
    return p;
  }

  unsigned int chain_nodes(const FirstBodyParameters &p)
  {
    return std::max(model_of(p).min_chain_nodes, std::lround(p.length / p.resolution));
  }

  double p_wave_speed(const FirstBodyParameters &p)
  {
    const double E = p.youngs_modulus, nu = p.poisson_ratio;
    return std::sqrt(E * (1 - nu) / ((1 + nu) * (1 - 2 * nu) * p.density));
  }

  namespace
  {
    /// Cells of the fem and reduced bodies' mesh along x and y.
    std::pair<unsigned int, unsigned int> fem_cells(const FirstBodyParameters &p)
    {
      return {chain_nodes(p), static_cast<unsigned int>(std::max(1L, std::lround(p.thickness / p.resolution)))};
    }
  } // namespace

  void check_first_body(const FirstBodyParameters &p)
  {
    if (p.model == "reduced")
      {
        // Interior unknowns with the bottom nodes and the top's x held: the mesh's
        // 2 (nx p)(ny p + 1) periodic unknowns less 2 nx and nx p.
        const auto [nx, ny] = fem_cells(p);
        const long nxp = long(nx) * p.degree, nyp = long(ny) * p.degree;
        const long interior = 2 * nxp * (nyp + 1) - 2 * long(nx) - nxp;
        if (long(p.modes) + 2 > interior)
          throw InputError("entry '" + p.section.entry("Upper body modes") + "' = '" + std::to_string(p.modes) +
                           "': expected at most " + std::to_string(interior - 2) + ", the body's " +
                           std::to_string(interior) + " interior unknowns less 2");
      }
    if (p.model == "mlp" && p.poisson_ratio > 0.25 + 1e-12)
      throw InputError("entry '" + p.section.entry("Upper body Poisson ratio") + "' = '" + to_text(p.poisson_ratio) +
                       "': an mlp upper body needs nu <= 0.25 (its plane-strain 2D ratio nu/(1 - nu) must "
                       "be <= 1/3: return forces can only lower it); use 0.25 or less, or Upper body "
                       "model = fem or sph");
  }

  std::string first_body_snapshot_name(unsigned int index)
  {
    return "upper_body_" + std::to_string(100000 + index).substr(1) + ".vtu";
  }

#ifdef TRIBO_WITH_FEM
  std::string ElasticBoundary::describe() const
  {
    const auto        &e = body.parameters();
    std::ostringstream os;
    os << (e.reduced ? "reduced" : "fem") << " upper body: " << e.cells_x << " x " << e.cells_y << " Q" << e.degree
       << " cells, " << body.n_dofs() << " dofs";
    if (e.reduced)
      os << " reduced to " << body.n_model_dofs() << " (" << 2 * body.n_boundary_nodes() << " boundary, "
         << e.modes << " modes up to " << (e.modes > 0 ? body.mode_frequencies().back() / (2 * M_PI) : 0.0)
         << " Hz, 1 load mode)";
    os << ", E = " << e.youngs_modulus << " Pa, nu = " << e.poisson_ratio;
    return os.str();
  }
#endif

  namespace
  {
#ifdef TRIBO_WITH_FEM
    std::unique_ptr<FirstBody> make_fem_first_body(const FirstBodyParameters &p)
    {
      fem::ElasticBodyParameters e;
      e.length         = p.length;
      e.thickness      = p.thickness;
      e.bottom         = p.bottom;
      e.youngs_modulus = p.youngs_modulus;
      e.poisson_ratio  = p.poisson_ratio;
      e.density        = p.density;
      std::tie(e.cells_x, e.cells_y) = fem_cells(p);
      if (double(e.cells_x) * e.cells_y > 4e6)
        throw InputError("entry '" + p.section.entry("Upper body cell size") + "' = '" + to_text(p.resolution) +
                         "': expected a cell size giving at most 4e6 cells; it gives " +
                         to_text(double(e.cells_x) * e.cells_y) + " cells");
      e.degree             = p.degree;
      e.reduced            = p.model == "reduced";
      e.modes              = p.modes;
      e.rayleigh_mass      = p.rayleigh_mass;
      e.rayleigh_stiffness = p.rayleigh_stiffness;
      e.theta              = p.theta;
      e.time_step          = p.time_step;
      e.top_pressure       = p.pressure;
      e.pressure_ramp_time = p.pressure_ramp_time;
      e.top_fixed_in_x     = true;
      // Until shearing starts: a + 2 zeta omega_1, omega_1 = pi c_p / (2 H): damping towards
      // rest, as for the particle bodies, which also caps the compaction stroke.
      if (p.compaction_damping > 0)
        e.rayleigh_mass += 2 * p.compaction_damping * M_PI * p_wave_speed(p) / (2 * e.thickness);
      return std::make_unique<ElasticBoundary>(std::make_unique<fem::ElasticBody>(e), p.rayleigh_mass,
                                               p.rayleigh_stiffness);
    }
#endif
  } // namespace

  std::unique_ptr<FirstBody> make_first_body(const FirstBodyParameters &p)
  {
    check_first_body(p);
    const FirstBodyModel &m = model_of(p);
    if (m.wall_of_discs)
      throw std::logic_error("make_first_body: the " + p.model + " model is a wall of discs, which the scene builds");
    if (!m.make)
      throw InputError(p.section.entry("Upper body model") + " = " + p.model + " needs a module this build left out (" +
                       m.build_option + "=OFF); rebuild with -D" + m.build_option + "=ON");
    return m.make(p);
  }
} // namespace tribo::coupling
