#pragma once
/// @file The shear cell's upper first body, whatever its model, as the scene sees it: one
/// interface (FirstBody) that the scene places, loads, measures, writes and checkpoints,
/// and one table of models behind the Upper body model entry (coupling/models.cc).
///
/// Models, each a row of the table and a file of coupling/:
/// - rigid (rigid_wall.cc): a rough wall of discs, a clump in the scene's particle system,
///   free in y under the load P L, with the mass of the first body it stands for;
/// - fem, reduced (fem_first_body.cc): the deal.II plane-strain body (fem/), implicit
///   Moreau-Jean, its bottom face condensed onto its contact nodes; reduced: Craig-Bampton
///   reduced to those nodes plus a few vibration modes and a load mode;
/// - sph, mlp (sph_first_body.cc, mlp_first_body.cc): a solid SPH block on a square
///   lattice, a movable-lattice-particle block on a hexagonal one, sub-cycled inside each
///   contact step (particle_first_body.h).
/// The deformable models are a DeformableBody (coupling/deformable_body.h) touched by the
/// grains through half-disc elements on their bottom face (half_disc_body.cc).
///
/// All share: period L along x, thickness H, density rho, top face held in x and loaded by
/// the pressure P(t) = P min(1, t / ramp) (compressive).
/// Units per unit depth: m, kg/m, N/m, J/m, W/m.

#include "core/checkpoint.h"
#include "core/output.h"
#include "core/parameter_section.h"

#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace dealii
{
  class ParameterHandler;
}

namespace tribo
{
  class ParameterFile;
}

namespace tribo::dem
{
  class MoreauJean;
  class ParticleSystem;
} // namespace tribo::dem

namespace tribo::coupling
{
  struct FirstBodyParameters;

  /// The rigid wall's own entry (coupling/rigid_wall.cc).
  struct RigidWallParameters
  {
    /// Cap on the wall's |v_y| before the shear starts, m/s (0: none).
    double compaction_speed_limit = 0;
    static void declare(dealii::ParameterHandler &prm);
    static void parse(const ParameterFile &file, FirstBodyParameters &p);
  };

  /// The deal.II bodies' own entries (fem, reduced; coupling/fem_first_body.cc).
  struct FemBodyParameters
  {
    unsigned int degree = 1;             ///< Q_p degree
    unsigned int modes = 20;             ///< fixed-interface modes kept (reduced)
    double       rayleigh_mass = 0;      ///< a of C = a M + b K while shearing, 1/s
    double       rayleigh_stiffness = 0; ///< b, s
    static void declare(dealii::ParameterHandler &prm);
    static void parse(const ParameterFile &file, FirstBodyParameters &p);
  };

  /// The particle bodies' own entries (sph, mlp; coupling/particle_first_body.cc).
  struct ParticleBodyParameters
  {
    /// Smoothing length over spacing (sph).
    double smoothing_ratio = 1.2;
    /// Velocity-Verlet step of the mlp body over its stability limit 2 / omega_max (the
    /// largest step that divides the contact step and is at most this fraction of it).
    double verlet_fraction = 0.05;
    /// Depth of the strip of bottom rows on which a particle body's trial advances of a step
    /// (the free prediction, the compliance's columns) run, in wave reaches c_p h;
    /// 0: the whole body (ParticleFirstBody::advance_strip()). The case entry's default is 3;
    /// this struct's is 0, so that a body built in code is the whole-body reference.
    double prediction_depth = 0;
    static void declare(dealii::ParameterHandler &prm);
    static void parse(const ParameterFile &file, FirstBodyParameters &p);
    /// Its entries a resumed run may change: they say only how the contact solve predicts
    /// the body, not how the body moves.
    static std::vector<std::string> entries_that_may_change_on_resume();
  };

  /// The upper first body's parameters (SI units). Its entries (the model, the body's
  /// thickness and material, each model's own part) are declared and read here
  /// (declare(), parse()); the scene gives the rest (period, density, load, time step).
  struct FirstBodyParameters
  {
    /// A row of the model table: rigid | fem | reduced | sph | mlp.
    std::string  model = "rigid";
    double       length = 0;    ///< L: period along x, m (scene)
    double       thickness = 0; ///< H, m: the rigid wall's mass is rho H L
    double       bottom = 0;    ///< y0 of a deformable body's bottom face (the contact chain), m (placement)
    double       youngs_modulus = 0; ///< E, Pa (deformable)
    double       poisson_ratio = 0;  ///< nu, plane strain (deformable)
    double       density = 0;        ///< rho, kg/m^3 (scene)
    /// Cell size (fem) or particle spacing (sph, mlp), m: the chain has
    /// chain_nodes() = max(minimum, round(L / resolution)) nodes. 0 from the case: the
    /// scene sets it.
    double       resolution = 0;
    /// Diameter of the half-disc contact elements on the chain, m; 0: the chain's node
    /// spacing L / chain_nodes().
    double       half_disc_diameter = 0;
    double       theta = 0.5;            ///< Moreau-Jean theta (fem; scene)
    double       time_step = 0;          ///< contact step h, s (scene)
    double       pressure = 0;           ///< P, Pa (> 0: compressive; scene)
    double       pressure_ramp_time = 0; ///< s; 0: a step at t = 0 (scene)
    /// Damping ratio zeta of a deformable body's first thickness mode, omega_1 = pi c_p /
    /// (2 H), until start_shearing() (0: none), in every deformable model as damping of the
    /// velocity towards rest at gamma = 2 zeta omega_1 (1/s; fem: mass-proportional
    /// Rayleigh a_c = gamma), which also caps the compaction stroke at the terminal speed
    /// P / (rho H gamma) (0.7 m/s for the paper's steel body at zeta = 1, as the rigid
    /// wall's compaction speed limit does; a body that falls freely onto the layer hits it
    /// at tens of m/s, 47 m/s for the paper's sample, and drives grains through its surface).
    double       compaction_damping = 0;
    RigidWallParameters    rigid;
    FemBodyParameters      fem;
    ParticleBodyParameters particle;
    /// The case subsection the body's entries were read from: messages name them
    /// through it.
    ParameterSection section;

    /// Declare the body's entries in the current subsection of @p prm (the caller enters
    /// and leaves it).
    static void declare(dealii::ParameterHandler &prm);
    /// The body's entries of subsection @p section of @p file, each checked on its own
    /// (InputError naming the file, the line and the entry); the scene's fields keep
    /// their defaults, and check_first_body() checks the whole once they are set.
    static FirstBodyParameters parse(const ParameterFile &file, const std::string &section);
  };

  /// Throws InputError, naming the case entry and a value that would work, if the model
  /// of @p p cannot run with it (its row's check: for mlp a Poisson ratio above 1/4, for
  /// reduced more modes than the body has interior unknowns, for fem and reduced a mesh of
  /// more than 4e6 cells), or if the build left its module out (naming the CMake option).
  void check_first_body(const FirstBodyParameters &p);

  /// What the statistics need from the upper first body after a step.
  struct FirstBodyState
  {
    double y, vy;          ///< wall centre line (rigid) or mean bottom face (deformable), m and m/s
    double surface;        ///< the surface the grains touch, m
    double power;          ///< power of its external load over the step, W/m
    double kinetic_energy; ///< J/m
    double stored_energy;  ///< J/m (0 for the rigid wall)
  };

  /// The upper first body as the scene sees it, whatever its model.
  class FirstBody
  {
  public:
    /// system_body() of a body that is not in the particle system.
    static constexpr unsigned int no_system_body = ~0u;

    virtual ~FirstBody() = default;
    /// Its body in the particle system (the rigid wall), no_system_body if none.
    virtual unsigned int system_body() const = 0;
    /// From its reference height (FirstBodyState::y) down to the surface the grains touch, m:
    /// the wall's mean disc radius, or the half-disc radius.
    virtual double y_to_surface() const = 0;
    /// Diameter of the half-disc elements on its face, m (0: none, the rigid wall).
    virtual double half_disc_diameter() const { return 0; }
    /// The time the pressure ramp counts from at run time @p t, s: a deformable body
    /// placed on a state takes its load from the state's time @p start on, on its own
    /// clock; the rigid wall of a state goes on with the state's ramp.
    virtual double load_time(double t, double start) const = 0;
    /// Couple it to the integrator (once, before the first step).
    virtual void attach(dem::MoreauJean &) {}
    /// Before a step: the load @p normal_force = P L times the ramp (N/m), @p sliding once
    /// the lower wall slides (the compaction's damping or speed cap ends).
    virtual void before_step(dem::ParticleSystem &s, double normal_force, bool sliding) = 0;
    /// Its state after a step; @p power the integrator's external power per body.
    virtual FirstBodyState state(const dem::ParticleSystem &s, const std::vector<double> &power) const = 0;
    /// Mean x-displacement of its contact face since the start, m, minimum image over the
    /// period (0 for the rigid wall, whose x is imposed). About tau H / G in steady shear.
    virtual double face_shift() const { return 0; }
    /// True when its kinetic and stored energy count in the energy balance (a deformable
    /// body; the rigid wall's vertical motion is the load's work, counted in its power).
    virtual bool in_energy_balance() const { return false; }
    /// Its own field snapshot @p index in @p dir; the file names written.
    virtual std::vector<std::string> write_fields(const std::string &, unsigned int) const { return {}; }
    /// A line for the log ("" for none).
    virtual std::string describe() const { return ""; }
    /// Its own figures for summary.json.
    virtual void summarize(JsonObject &) const {}
    virtual void save(CheckpointOut &) const {}
    virtual void load(CheckpointIn &) {}
  };

  /// Where the scene puts the upper first body.
  struct FirstBodyPlacement
  {
    dem::ParticleSystem &system;
    /// The surface the grains touch, m: a deformable body's half-discs' bottom.
    double surface;
    /// Adds the scene's rough wall of discs to @c system (a model that is a wall of
    /// discs calls it): the clump and its mean disc diameter, m.
    std::function<std::pair<unsigned int, double>()> add_wall;
  };

  /// The body of model p.model (check_first_body() passed), placed by @p where.
  std::unique_ptr<FirstBody> make_first_body(const FirstBodyParameters &p, const FirstBodyPlacement &where);
} // namespace tribo::coupling
