#pragma once
/// @file The movable-lattice-particle scene family (Popov and Filippov 2006, section 5):
/// what mlp_ordering, mlp_compression and mlp_beams (app/scenes/mlp_*.cc) share. Each
/// scene is an MlpScene that make_simulation() runs as the driver's Simulation: Langevin
/// steps (mlp/langevin.h), statistics rows and VTU snapshots every so many steps, a guard
/// against a body flying apart. Their common settings are the subsection "MLP".
///
/// Units: 2D, per unit depth (masses kg/m, forces N/m, pressures and moduli Pa = N/m^2,
/// energies J/m). x is the axis of the loads (left-right), y the transverse axis.

#include "app/driver.h"
#include "app/scene_of.h"
#include "app/scene_hooks.h"
#include "core/parameter_file.h"
#include "mlp/interaction.h"
#include "mlp/langevin.h"
#include "mlp/particles.h"

#include <map>
#include <memory>
#include <string>
#include <utility>

namespace tribo::app
{
  /// Declare the subsection "MLP" that every MLP scene reads (in each MLP scene's hooks).
  void declare_mlp_parameters(dealii::ParameterHandler &prm);
} // namespace tribo::app

namespace tribo::app::mlp_scenes
{
  using mlp::Particles;
  using mlp::Vec2;

  /// Settings shared by all MLP scenes (subsection "MLP").
  struct CommonSettings
  {
    mlp::LatticeType           lattice = mlp::LatticeType::hexagonal;
    mlp::InteractionParameters interaction;
    mlp::LangevinParameters    langevin;
    double                     mass     = 0; ///< kg/m
    double                     end_time = 0; ///< s
    unsigned int               statistics_interval = 1, snapshot_interval = 0;
    bool                       plots  = true;
    bool                       mapped = false; ///< k_c and f0 from (E, nu)
  };

  /// A non-negative integer entry of at least @p min.
  unsigned int count(const ParameterFile &f, const std::string &path, long min);


  /// Reads subsection "MLP" (common to the scenes) and Simulation/End time. The (E, nu)
  /// mapping wins over Pair stiffness and Return force amplitude when Young's modulus > 0.
  CommonSettings read_common(const ParameterFile &f);

  /// Mass density of the ideal lattice, rho = m / area per particle, kg/m^3.
  double lattice_density(const CommonSettings &s);

  /// Linear theory of the configured lattice along x: 2D Young's modulus E (Pa, uniaxial
  /// stress with free lateral faces) and longitudinal speed c_L (m/s, plane wave).
  /// Hexagonal: mlp::hexagonal_elasticity with k1 = k_t, k2 = k_c - k_t (isotropic).
  /// Square along an axis: E = C11 - C12^2/C11 = k_c, c_L = sqrt(k_c/rho).
  std::pair<double, double> axial_theory(const CommonSettings &s);

  /// What the MLP family's hooks see (app/scene_of.h): the particles, the box, the force
  /// field and the time.
  struct MlpWorld
  {
    Particles             &particles;
    mlp::Box              &box;
    const mlp::ForceField *field = nullptr; ///< null until built
    /// s: the step's start in before_step(), its end in after_step(), the row's time in
    /// measure(), the end in summarize().
    double time = 0;
    double dt   = 0; ///< the step, s
  };

  /// An MLP scene: the one scene interface on the particles, plus building them, their
  /// preparation and the loads.
  class MlpScene : public SceneOf<MlpWorld>
  {
  public:
    /// Places the particles and sets the box.
    virtual void build(Particles &p, mlp::Box &box) = 0;
    /// Called once the force field exists, before the first step (e.g. relaxation).
    virtual void prepare(Particles &, const mlp::Box &, mlp::ForceField &, Log &) {}
    /// Sets the external forces for time @p t (s), before the step that ends at t.
    virtual void set_loads(Particles &, double /*t*/) {}
    std::map<std::string, TimeSeries> tables() const override { return made_tables; }

  protected:
    /// The tables summarize() made (CSV and results.h5 groups).
    std::map<std::string, TimeSeries> made_tables;
  };

  /// Reads a scene's own subsection and makes the scene.
  using SceneFactory = std::unique_ptr<MlpScene> (*)(const ParameterFile &, const CommonSettings &);

  /// Reads and checks the case's "MLP" entries, the scene's (through @p make_scene) and
  /// its time step against the stable limit of the built scene, without running it.
  void check_scene(const ParameterFile &file, SceneFactory make_scene);

  /// The scene of @p make_scene on the case @p file as the driver runs it: Langevin steps
  /// of MLP/Time step, a statistics row every Statistics interval steps (the first at
  /// t = 0), snapshots every Snapshot interval steps, and a guard against a body flying
  /// apart (what it built goes to @p log).
  std::unique_ptr<Simulation> make_simulation(const ParameterFile &file, Log &log, SceneFactory make_scene);

  /// The hooks of the scene table (app/scenes.h) for the MLP scene of @p make_scene whose
  /// own subsection @p declare declares: the "MLP" subsection and it, check_scene() and
  /// make_simulation().
  template <SceneFactory make_scene>
  SceneHooks hooks(void (*declare)(dealii::ParameterHandler &))
  {
    return {{declare_mlp_parameters, declare},
            [](const ParameterFile &file) { check_scene(file, make_scene); },
            [](const ParameterFile &file, const CaseParameters &, Log &log) {
              return make_simulation(file, log, make_scene);
            }};
  }
} // namespace tribo::app::mlp_scenes
