/// @file The table of the upper first-body models (the Upper body model entry) and what
/// it serves: the entries every model reads, each model's check when the case is read,
/// the factories, the chain nodes.

#include "coupling/first_body.h"
#include "coupling/first_body_models.h"
#include "coupling/models.h"

#include "core/errors.h"
#include "core/parameter_file.h"

#include <deal.II/base/parameter_handler.h>

#include <cmath>
#include <iterator>
#include <stdexcept>

namespace tribo::coupling
{
  namespace
  {
    /// The upper first-body models (the Upper body model entry): name, least number of
    /// chain nodes, the build option of their module, how the scene's placement makes them,
    /// the deformable body (null for a wall of discs and when the build left the module
    /// out), the model's own check of the parameters (null: none), and whether the model is
    /// a wall of discs (is_wall_of_discs()).
    struct FirstBodyModel
    {
      const char *name;
      long        min_chain_nodes;
      const char *build_option;
      std::unique_ptr<FirstBody> (*place)(const FirstBodyParameters &, const FirstBodyPlacement &);
      std::unique_ptr<DeformableBody> (*make_deformable)(const FirstBodyParameters &);
      void (*check)(const FirstBodyParameters &);
      bool wall_of_discs = false;
    };

#ifdef TRIBO_WITH_FEM
    constexpr auto fem_body = make_fem_body;
#else
    constexpr std::unique_ptr<DeformableBody> (*fem_body)(const FirstBodyParameters &) = nullptr;
#endif
#ifdef TRIBO_WITH_SPH
    constexpr auto sph_body = make_sph_body;
#else
    constexpr std::unique_ptr<DeformableBody> (*sph_body)(const FirstBodyParameters &) = nullptr;
#endif
#ifdef TRIBO_WITH_MLP
    constexpr auto mlp_body = make_mlp_body;
#else
    constexpr std::unique_ptr<DeformableBody> (*mlp_body)(const FirstBodyParameters &) = nullptr;
#endif

    const FirstBodyModel models[] = {
      {"rigid", 0, "", place_rigid_wall, nullptr, nullptr, true},
      {"fem", 1, "TRIBO_WITH_FEM", place_on_half_discs, fem_body, check_fem_body},
      {"reduced", 1, "TRIBO_WITH_FEM", place_on_half_discs, fem_body, check_fem_body},
      {"sph", 8, "TRIBO_WITH_SPH", place_on_half_discs, sph_body, nullptr},
      {"mlp", 4, "TRIBO_WITH_MLP", place_on_half_discs, mlp_body, check_mlp_body},
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

    /// InputError, naming the entry and the CMake option, when the build left out the
    /// module of model @p m.
    void require_module(const FirstBodyModel &m, const FirstBodyParameters &p)
    {
      if (!m.wall_of_discs && !m.make_deformable)
        throw InputError(p.section.entry("Upper body model") + " = " + p.model + " needs a module this build left " +
                         "out (" + m.build_option + "=OFF); rebuild with -D" + m.build_option + "=ON");
    }
  } // namespace

  bool is_wall_of_discs(const std::string &model) { return model_of(model).wall_of_discs; }

  const std::vector<std::string> &entries_that_may_change_on_resume()
  {
    static const std::vector<std::string> entries = ParticleBodyParameters::entries_that_may_change_on_resume();
    return entries;
  }

  void FirstBodyParameters::declare(dealii::ParameterHandler &prm)
  {
    using dealii::Patterns::Double;
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
    prm.declare_entry("Upper body thickness", "1.5e-4", Double(),
                      "Thickness H of the upper first body, m (> 0; paper: 1.5e-4): the deformable "
                      "body's, or that of the first body the rigid wall stands for, whose mass is "
                      "density * H * L.");
    prm.declare_entry("Upper body Young's modulus", "1e11", Double(),
                      "E of the deformable upper body, Pa (> 0; paper: 1e11 and 3e9).");
    prm.declare_entry("Upper body Poisson ratio", "0.33", Double(),
                      "nu of the deformable upper body, plane strain (in (-1, 0.5); paper: 0.33; "
                      "mlp: at most 0.25).");
    prm.declare_entry("Upper body cell size", "0", Double(),
                      "Cell size of the fem upper body's mesh, or particle spacing of the sph and mlp "
                      "bodies, m (>= 0); 0: the smallest grain diameter d(1-s), the paper's choice.");
    prm.declare_entry("Half-disc diameter", "0", Double(),
                      "Diameter of the half-disc contact elements on the deformable upper body, m (>= 0); "
                      "0: the cell size (one per boundary edge, the paper's choice).");
    prm.declare_entry("Upper body compaction damping", "1", Double(),
                      "Damping ratio zeta (>= 0) of the deformable upper body's first thickness mode, "
                      "omega_1 = pi c_p / (2 H), added before Shear start as damping of the velocity "
                      "towards rest at gamma = 2 zeta omega_1 (fem: mass-proportional Rayleigh damping) "
                      "and removed when shearing starts: the body then lands on the layer at the "
                      "terminal speed P / (rho H gamma) (0.7 m/s for the paper's steel body) instead of "
                      "falling freely onto it, and does not ring (no numerical damping at theta = 0.5). "
                      "The rigid wall's Compaction speed limit plays this part. 0: off.");
    RigidWallParameters::declare(prm);
    FemBodyParameters::declare(prm);
    ParticleBodyParameters::declare(prm);
  }

  FirstBodyParameters FirstBodyParameters::parse(const ParameterFile &f, const std::string &section)
  {
    FirstBodyParameters p;
    p.section        = {section};
    const auto entry = [&](const std::string &name) { return p.section.entry(name); };
    p.model          = f.get(entry("Upper body model"));
    p.thickness = f.get_checked(entry("Upper body thickness"), is_positive, "a positive thickness in m");
    p.youngs_modulus = f.get_checked(entry("Upper body Young's modulus"), is_positive, "a positive modulus in Pa");
    p.poisson_ratio  = f.get_checked(entry("Upper body Poisson ratio"), [](double v) { return v > -1 && v < 0.5; },
                                     "a Poisson ratio in (-1, 0.5)");
    p.resolution     = f.get_checked(entry("Upper body cell size"), is_non_negative, "a size >= 0 in m");
    p.half_disc_diameter = f.get_checked(entry("Half-disc diameter"), is_non_negative, "a diameter >= 0 in m");
    p.compaction_damping =
      f.get_checked(entry("Upper body compaction damping"), is_non_negative, "a damping ratio >= 0");
    RigidWallParameters::parse(f, p);
    FemBodyParameters::parse(f, p);
    ParticleBodyParameters::parse(f, p);
    return p;
  }

  void check_first_body(const FirstBodyParameters &p)
  {
    const FirstBodyModel &m = model_of(p);
    require_module(m, p);
    if (m.check)
      m.check(p);
  }

  std::unique_ptr<FirstBody> make_first_body(const FirstBodyParameters &p, const FirstBodyPlacement &where)
  {
    return model_of(p).place(p, where);
  }

  std::unique_ptr<DeformableBody> make_deformable_body(const FirstBodyParameters &p)
  {
    const FirstBodyModel &m = model_of(p);
    if (m.wall_of_discs)
      throw std::logic_error("make_deformable_body: the " + p.model + " model is a wall of discs");
    require_module(m, p);
    return m.make_deformable(p);
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

  std::string deformable_body_snapshot_name(unsigned int index)
  {
    return "upper_body_" + std::to_string(100000 + index).substr(1) + ".vtu";
  }
} // namespace tribo::coupling
