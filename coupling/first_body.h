#pragma once
/// @file The shear cell's deformable upper first body, whatever its model, as one kind
/// of object: the solver's coupling interface (dem::BoundaryBody, ../shared/DESIGN.md
/// section 3) plus what the scene measures, writes and checkpoints.
///
/// Models (the Upper body model entry, FirstBodyParameters::declare()):
/// - fem: the deal.II plane-strain body (fem/), implicit Moreau-Jean, its bottom face
///   condensed onto its contact nodes (coupling/elastic_boundary.h);
/// - reduced: the same body, Craig-Bampton reduced to its contact nodes plus a few
///   vibration modes and a load mode (fem::ElasticBodyParameters::reduced);
/// - sph: a solid SPH block (sph/) on a square lattice, linear equation of state;
/// - mlp: a movable-lattice-particle block (mlp/) on a hexagonal lattice.
/// The particle models sub-cycle their explicit integrators inside a contact step; their
/// bottom row of particles is the contact chain, its compliance over the step measured
/// from the body's own dynamics (coupling/particle_first_body.h).
///
/// All share: period L along x, thickness H, bottom face (the chain) at y0, top face
/// held in x and loaded by the pressure P(t) = P min(1, t / ramp) (compressive), and a
/// compaction damping (towards rest, ratio zeta on the first thickness mode) until
/// start_shearing().
/// Units per unit depth: m, kg/m, N/m, J/m, W/m.

#include "core/checkpoint.h"
#include "core/output.h"
#include "core/parameter_section.h"
#include "dem/boundary.h"

#include <memory>
#include <string>

namespace tribo::coupling
{
  /// Geometry, material and loading of an upper first body (SI units). The body's own
  /// entries (model, material, resolution, damping, half-discs) are declared and read
  /// here (declare(), parse()); the scene gives the rest (period, thickness, density,
  /// load, time step).
  struct FirstBodyParameters
  {
    /// rigid | fem | reduced | sph | mlp. rigid is no FirstBody: the scene's rough wall of
    /// discs (the entry's default); the others are made by make_first_body().
    std::string  model = "rigid";
    double       length = 0;    ///< L: period along x, m (scene)
    double       thickness = 0; ///< H, m (scene)
    double       bottom = 0;    ///< y0 of the bottom face (the contact chain), m (scene)
    double       youngs_modulus = 0; ///< E, Pa
    double       poisson_ratio = 0;  ///< nu (plane strain)
    double       density = 0;        ///< rho, kg/m^3 (scene)
    /// Cell size (fem) or particle spacing (sph, mlp), m: the chain has
    /// chain_nodes() = max(minimum, round(L / resolution)) nodes. 0 from the case: the
    /// scene sets it.
    double       resolution = 0;
    unsigned int degree = 1;            ///< Q_p degree (fem, reduced)
    unsigned int modes = 20;            ///< fixed-interface modes kept (reduced)
    double       rayleigh_mass = 0;      ///< a of C = a M + b K while shearing, 1/s (fem)
    double       rayleigh_stiffness = 0; ///< b, s (fem)
    /// Diameter of the half-disc contact elements on the chain, m; 0: the chain's node
    /// spacing L / chain_nodes() (the scene attaches them).
    double       half_disc_diameter = 0;
    double       theta = 0.5;            ///< Moreau-Jean theta (fem; scene)
    double       time_step = 0;          ///< contact step h, s (scene)
    double       pressure = 0;           ///< P, Pa (> 0: compressive; scene)
    double       pressure_ramp_time = 0; ///< s; 0: a step at t = 0 (scene)
    /// Damping ratio zeta of the first thickness mode, omega_1 = pi c_p / (2 H), until
    /// start_shearing() (0: none), in every model as damping of the velocity towards rest
    /// at gamma = 2 zeta omega_1 (1/s; fem: mass-proportional Rayleigh a_c = gamma),
    /// which also caps the compaction stroke at the terminal speed P / (rho H gamma)
    /// (0.7 m/s for the paper's steel body at zeta = 1, as the rigid wall's Compaction
    /// speed limit does; a body that falls freely onto the layer hits it at tens of m/s,
    /// 47 m/s for the paper's sample, and drives grains through its surface).
    double       compaction_damping = 0;
    /// Smoothing length over spacing (sph).
    double       smoothing_ratio = 1.2;
    /// Velocity-Verlet step of the mlp body over its stability limit 2 / omega_max (the
    /// largest step that divides the contact step and is at most this fraction of it).
    double       verlet_fraction = 0.05;
    /// Depth of the strip of bottom rows on which a particle body's trial advances of a step
    /// (the free prediction, the compliance's columns) run, in wave reaches c_p h (sph, mlp);
    /// 0: the whole body (ParticleFirstBody::advance_strip()). The case entry's default is 3;
    /// this struct's is 0, so that a body built in code is the whole-body reference.
    double       prediction_depth = 0;
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

  /// Number of chain nodes the model places along L for @p p (fem: cells along x;
  /// sph: at least 8 columns, the kernel support must fit 3 times in the period;
  /// mlp: at least 4 columns). Throws InputError for an unknown model.
  unsigned int chain_nodes(const FirstBodyParameters &p);

  /// P-wave speed of the plane-strain material, sqrt(E (1 - nu) / ((1 + nu)(1 - 2 nu) rho)), m/s.
  double p_wave_speed(const FirstBodyParameters &p);

  /// An upper first body: the coupling interface plus the scene's measurements.
  class FirstBody : public dem::BoundaryBody
  {
  public:
    /// Mean y of the chain nodes at the start of the next step, m.
    virtual double mean_bottom_y() const = 0;
    /// Mean y-velocity of the chain nodes, m/s.
    virtual double mean_bottom_vy() const = 0;
    /// J/m.
    virtual double kinetic_energy() const = 0;
    /// Energy stored in the body, J/m: elastic (fem), internal (sph: elastic work plus
    /// the heat of its artificial viscosity), potential (mlp).
    virtual double stored_energy() const = 0;
    /// Kinetic plus stored energy, J/m.
    double energy() const final { return kinetic_energy() + stored_energy(); }
    /// Drop the compaction damping (the shearing phase starts).
    virtual void start_shearing() = 0;
    /// Write a VTU snapshot with index @p index into directory @p dir; returns its file
    /// name (upper_body_NNNNN.vtu).
    virtual std::string write_fields(const std::string &dir, unsigned int index) const = 0;
    /// One line for the log: model, resolution, counts.
    virtual std::string describe() const = 0;
    /// The coupling's own figures for summary.json (none by default).
    virtual void summarize(JsonObject &) const {}
    virtual void save(CheckpointOut &ar) const = 0;
    virtual void load(CheckpointIn &ar) = 0;
  };

  /// Throws InputError, naming the case entry and a value that would work, if @p p
  /// cannot run: for mlp a Poisson ratio above 1/4, for reduced more modes than the
  /// body has interior unknowns.
  void check_first_body(const FirstBodyParameters &p);

  /// The body of model p.model (check_first_body() first). Throws InputError for a model this build left out
  /// (naming the CMake option) or bad parameters.
  std::unique_ptr<FirstBody> make_first_body(const FirstBodyParameters &p);

  /// "upper_body_NNNNN.vtu" for snapshot @p index.
  std::string first_body_snapshot_name(unsigned int index);
} // namespace tribo::coupling
