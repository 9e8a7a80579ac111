/// @file The fem and reduced models: the deal.II plane-strain body (fem/) behind the
/// coupling interface (coupling/elastic_boundary.h). Its entries and their check are built
/// whatever the build; the body only with TRIBO_WITH_FEM.

#include "coupling/models.h"

#include "core/errors.h"
#include "core/parameter_file.h"

#include <deal.II/base/parameter_handler.h>

#include <cmath>
#include <utility>

#ifdef TRIBO_WITH_FEM
#include "coupling/elastic_boundary.h"

#include <sstream>
#include <tuple>
#endif

namespace tribo::coupling
{
  void FemBodyParameters::declare(dealii::ParameterHandler &prm)
  {
    using dealii::Patterns::Double;
    using dealii::Patterns::Integer;
    prm.declare_entry("Upper body element degree", "1", Integer(1, 4),
                      "Degree p of the fem upper body's Q_p elements.");
    prm.declare_entry("Upper body modes", "20", Integer(0),
                      "Fixed-interface vibration modes kept by the reduced upper body (>= 0; 0: static "
                      "condensation plus the load mode only), docs/fem.md.");
    prm.declare_entry("Upper body mass damping", "0", Double(),
                      "Rayleigh coefficient a of C = a M + b K for the fem upper body, 1/s (>= 0).");
    prm.declare_entry("Upper body stiffness damping", "0", Double(),
                      "Rayleigh coefficient b of C = a M + b K for the fem upper body, s (>= 0).");
  }

  void FemBodyParameters::parse(const ParameterFile &f, FirstBodyParameters &p)
  {
    const auto entry = [&](const std::string &name) { return p.section.entry(name); };
    auto      &q     = p.fem;
    q.degree         = f.get_integer(entry("Upper body element degree"));
    q.modes          = f.get_integer(entry("Upper body modes"));
    q.rayleigh_mass  = f.get_checked(entry("Upper body mass damping"), is_non_negative, "a coefficient >= 0 in 1/s");
    q.rayleigh_stiffness =
      f.get_checked(entry("Upper body stiffness damping"), is_non_negative, "a coefficient >= 0 in s");
  }

  namespace
  {
    /// Cells of the body's mesh along x and y.
    std::pair<unsigned int, unsigned int> fem_cells(const FirstBodyParameters &p)
    {
      return {chain_nodes(p), static_cast<unsigned int>(std::max(1L, std::lround(p.thickness / p.resolution)))};
    }
  } // namespace

  void check_fem_body(const FirstBodyParameters &p)
  {
    const auto [nx, ny] = fem_cells(p);
    if (double(nx) * ny > 4e6)
      throw InputError("entry '" + p.section.entry("Upper body cell size") + "' = '" + to_text(p.resolution) +
                       "': expected a cell size giving at most 4e6 cells; it gives " + to_text(double(nx) * ny) +
                       " cells");
    if (p.model == "reduced")
      {
        // Interior unknowns with the bottom nodes and the top's x held: the mesh's
        // 2 (nx p)(ny p + 1) periodic unknowns less 2 nx and nx p.
        const long nxp = long(nx) * p.fem.degree, nyp = long(ny) * p.fem.degree;
        const long interior = 2 * nxp * (nyp + 1) - 2 * long(nx) - nxp;
        if (long(p.fem.modes) + 2 > interior)
          throw InputError("entry '" + p.section.entry("Upper body modes") + "' = '" + std::to_string(p.fem.modes) +
                           "': expected at most " + std::to_string(interior - 2) + ", the body's " +
                           std::to_string(interior) + " interior unknowns less 2");
      }
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

  std::unique_ptr<DeformableBody> make_fem_body(const FirstBodyParameters &p)
  {
    fem::ElasticBodyParameters e;
    e.length         = p.length;
    e.thickness      = p.thickness;
    e.bottom         = p.bottom;
    e.youngs_modulus = p.youngs_modulus;
    e.poisson_ratio  = p.poisson_ratio;
    e.density        = p.density;
    std::tie(e.cells_x, e.cells_y) = fem_cells(p);
    e.degree             = p.fem.degree;
    e.reduced            = p.model == "reduced";
    e.modes              = p.fem.modes;
    e.rayleigh_mass      = p.fem.rayleigh_mass;
    e.rayleigh_stiffness = p.fem.rayleigh_stiffness;
    e.theta              = p.theta;
    e.time_step          = p.time_step;
    e.top_pressure       = p.pressure;
    e.pressure_ramp_time = p.pressure_ramp_time;
    e.top_fixed_in_x     = true;
    // Until shearing starts: a + 2 zeta omega_1, omega_1 = pi c_p / (2 H): damping towards
    // rest, as for the particle bodies, which also caps the compaction stroke.
    if (p.compaction_damping > 0)
      e.rayleigh_mass += 2 * p.compaction_damping * M_PI * p_wave_speed(p) / (2 * e.thickness);
    return std::make_unique<ElasticBoundary>(std::make_unique<fem::ElasticBody>(e), p.fem.rayleigh_mass,
                                             p.fem.rayleigh_stiffness);
  }
#endif
} // namespace tribo::coupling
