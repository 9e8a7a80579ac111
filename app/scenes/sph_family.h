#pragma once
/// @file The SPH scene family (sph_slider, sph_plate): what its scenes share. Each scene
/// (app/scenes/sph_slider.cc, app/scenes/sph_plate.cc) is an Experiment<dim>, the one scene
/// interface on the solver, that make_simulation() runs as the driver's Simulation:
/// adaptive RK2 steps of the solver,
/// statistics rows and VTU snapshots on intervals of simulated time.
///
/// SI units. The vertical axis is the last one (y in 2D, z in 3D); in 2D (plane strain)
/// forces are per metre of depth (N/m) and masses kg/m.

#include "app/driver.h"
#include "app/scene_of.h"
#include "core/parameter_file.h"
#include "sph/eos.h"
#include "sph/solver.h"

#include <array>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace tribo::sph
{
  template <int dim>
  class Solver; // sph/solver.h
}

namespace tribo::app::sph_scenes
{
  /// Reads and checks entries through a ParameterFile.
  class EntryReader
  {
  public:
    explicit EntryReader(const ParameterFile &f) : file(f) {}
    /// The value of @p path as text.
    std::string text(const std::string &path) { return file.get(path); }
    /// A number satisfying @p ok, else InputError "FILE:LINE: entry ... expected @p expected".
    template <typename Check>
    double number(const std::string &path, Check ok, const std::string &expected)
    {
      return file.get_checked(path, ok, expected);
    }
    /// An integer >= @p lowest, else InputError naming the entry.
    long integer(const std::string &path, long lowest, const std::string &expected);
    /// Three lengths "Lx, Ly, Lz" in m, each > 0.
    std::array<double, 3> lengths(const std::string &path);
    /// Throws InputError "FILE:LINE: entry 'path' = 'value': expected @p expected".
    [[noreturn]] void fail(const std::string &path, const std::string &expected) const;

  private:
    const ParameterFile &file;
  };


  /// Young's modulus E = 9 K G/(3 K + G) (Pa) and Poisson ratio
  /// nu = (3 K - 2 G)/(2 (3 K + G)) of a material's small-strain moduli (K = A for Tillotson).
  std::pair<double, double> young_and_poisson(const sph::Material &m);

  /// The material named granite or basalt (pattern-checked).
  sph::Material material_named(const std::string &name);

  /// Declare, in the current subsection, the entries of the explicit integration that
  /// every SPH scene has: Artificial viscosity alpha and beta (Monaghan), CFL number C
  /// (dt = C h / (c (1 + 1.2 alpha) + beta max mu)), Step floor (s), Fixed step (s, 0:
  /// adaptive) and Interface viscosity (the viscosity across bodies).
  void declare_integration_entries(dealii::ParameterHandler &prm);

  /// Read those entries of subsection @p section ("SPH plate/") into a solver's
  /// parameters (the others at their defaults); InputError naming the entry.
  sph::SolverParameters read_integration(EntryReader &r, const std::string &section);

  /// What the SPH family's hooks see (app/scene_of.h): the solver, and after a step its
  /// length.
  template <int dim>
  struct SphWorld
  {
    sph::Solver<dim> &solver;
    double            dt = 0; ///< the last step's length, s
  };

  /// An SPH scene: the one scene interface on the SPH solver, plus its step limit and the
  /// sizes of its groups.
  template <int dim>
  class Experiment : public SceneOf<SphWorld<dim>>
  {
  public:
    /// Largest step allowed now (to land on an event time), s.
    virtual double step_limit(const sph::Solver<dim> &) const { return std::numeric_limits<double>::infinity(); }
    /// Integer entries of summary.json that come first (the sizes of the scene's groups).
    virtual std::vector<std::pair<std::string, long>> counts() const { return {}; }
  };

  /// Output settings of the explicit loop.
  struct LoopSettings
  {
    std::string scene;
    double      end_time = 0, statistics_interval = 0, field_interval = 0; ///< s
  };

  /// Builds the experiment of a scene on its solver.
  template <int dim>
  using ExperimentFactory = std::function<std::unique_ptr<Experiment<dim>>(sph::Solver<dim> &)>;

  /// An SPH scene as the driver runs it: RK2 steps of adaptive length until the end
  /// time, statistics rows every statistics interval of simulated time (the first at
  /// t = 0), VTU snapshots fields/particles_NNNNN.vtu indexed in fields/particles.pvd
  /// every field interval (0: the first and the last only). The experiment is built by
  /// @p make_experiment on @p solver. (dim = 2 or 3.)
  template <int dim>
  std::unique_ptr<Simulation> make_simulation(const LoopSettings &settings, std::unique_ptr<sph::Solver<dim>> solver,
                                              const ExperimentFactory<dim> &make_experiment);
} // namespace tribo::app::sph_scenes
