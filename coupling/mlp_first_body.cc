// The MLP upper first body: a movable-lattice-particle block (mlp/) behind the coupling
// interface.
#include "coupling/models.h"
#include "coupling/particle_first_body.h"

#include "core/errors.h"
#include "core/output.h"
#include "core/point_cloud.h"
#include "mlp/interaction.h"
#include "mlp/langevin.h"
#include "mlp/linear_theory.h"

#include <boost/archive/binary_iarchive.hpp>
#include <boost/archive/binary_oarchive.hpp>

#include <cmath>
#include <sstream>

namespace tribo::coupling
{
  namespace
  {
    /// A hexagonal MLP block of nx x ny particles, spacing c = L / nx (mass
    /// rho (sqrt(3)/2) c^2), periodic in x, rows along x (the bottom row is the chain at
    /// y0). Model constants from the plane-strain target: the 2D moduli
    /// E' = E / (1 - nu^2), nu' = nu / (1 - nu) (mlp::hexagonal_model_for, pure-strain
    /// target, conservative return forces so that the energy is defined). nu' <= 1/3,
    /// i.e. nu <= 1/4, because return forces can only lower nu' below 1/3.
    /// Velocity Verlet (BAOAB at T = 0) with the largest step that divides h and is at
    /// most FirstBodyParameters::verlet_fraction of the stability limit 2 / omega_max of
    /// the stiffest bond. At the default, a twentieth, the resting column of
    /// tests/unit/test_particle_coupling.cc (c_p h / s = 4) loses 6e-4 of the contacts'
    /// dissipation in its sub-cycles (1.35e-2 at a fifth) and the 120-disc shear cell's
    /// books close to 0.03 % (0.17 % at a fifth, 3.5 times faster; docs/first_bodies.md).
    /// Before the implicit chain, its fall-and-catch in each step lost 1 % on the shear
    /// cell at a twentieth, 40 % at a half. Compaction damping: the Langevin friction
    /// eta = m gamma, gamma = 2 zeta omega_1.
    class MlpFirstBody : public ParticleFirstBody
    {
    public:
      explicit MlpFirstBody(const FirstBodyParameters &p)
        : ParticleFirstBody(p), forces(interaction(p))
      {
        const unsigned int nx = chain_nodes(p);
        spacing               = p.length / nx;
        const double dy       = 0.5 * std::sqrt(3.0) * spacing;
        ny                    = std::max(2L, std::lround(p.thickness / dy));
        const double m        = p.density * mlp::area_per_particle(mlp::LatticeType::hexagonal, spacing);
        mlp::add_lattice_patch(particles, mlp::LatticeType::hexagonal, {0.25 * spacing, p.bottom}, nx, ny, spacing, m);
        box.periodic_x = true;
        box.lx         = p.length;
        std::vector<unsigned int> bottom, top_row;
        for (unsigned int i = 0; i < nx; ++i)
          {
            bottom.push_back(i);
            top_row.push_back((ny - 1) * nx + i);
            particles.fixed[(ny - 1) * nx + i] = mlp::fix_x;
          }
        set_rows(bottom, top_row);
        const auto &ip = forces.interaction();
        omega_max = mlp::max_angular_frequency(mlp::LatticeType::hexagonal, ip.parameters().stiffness,
                                               ip.transverse_stiffness(), m);
        gamma     = 2 * p.compaction_damping * M_PI * p_wave_speed(p) / (2 * p.thickness);
        build_integrator(p.time_step);
      }

      std::string describe() const override
      {
        const auto &ip = forces.interaction().parameters();
        std::ostringstream os;
        os << "mlp upper body: " << particles.size() << " particles (" << n_nodes() << " x " << ny
           << " hexagonal, spacing " << spacing << " m), k_c = " << ip.stiffness << " Pa, f0 = " << ip.f0
           << " N/m, " << substeps_per_step << " Verlet steps of " << prm.time_step / substeps_per_step
           << " s per contact step";
        return os.str();
      }

      /// Potential energy above the unloaded lattice's, J/m (one pair pass, cached until
      /// the particles move).
      double stored_energy() const override
      {
        if (!potential_current)
          {
            potential         = forces.potential_energy(particles, box) - reference_energy;
            potential_current = true;
          }
        return potential;
      }
      std::string write_fields(const std::string &dir, unsigned int index) const override
      {
        const unsigned int                 n = particles.size();
        std::vector<std::array<double, 3>> points(n);
        PointField velocity{"velocity", 2, {}}, force{"force", 2, {}};
        for (unsigned int i = 0; i < n; ++i)
          {
            points[i] = {{particles.position[i].x(), particles.position[i].y(), 0}};
            velocity.values.insert(velocity.values.end(), {particles.velocity[i].x(), particles.velocity[i].y()});
            force.values.insert(force.values.end(), {particles.force[i].x(), particles.force[i].y()});
          }
        const std::string name = deformable_body_snapshot_name(index);
        atomic_write(dir + "/" + name, point_cloud_vtu(2, points, {velocity, force}));
        return name;
      }

    protected:
      unsigned int n_particles() const override { return particles.size(); }
      dem::Vec2    position(unsigned int p) const override { return particles.position[p]; }
      dem::Vec2    velocity(unsigned int p) const override { return particles.velocity[p]; }
      double       mass(unsigned int p) const override { return particles.mass[p]; }
      unsigned int advance(double h, double load, const std::vector<dem::Vec2> &chain_force) override
      {
        if (std::abs(h - step_built) > 1e-12 * step_built)
          build_integrator(h);
        for (unsigned int p : top)
          particles.external_force[p] = {0, load};
        for (std::size_t i = 0; i < chain_force.size(); ++i)
          particles.external_force[chain[i]] = chain_force[i];
        integrator->invalidate_forces();
        integrator->run(particles, box, substeps_per_step);
        potential_current = false;
        return substeps_per_step;
      }
      void save_engine(CheckpointOut &ar) const override
      {
        ar << total_dissipation() << gamma;
        particles.save(ar);
      }
      void load_engine(CheckpointIn &ar) override
      {
        double damped, saved_gamma;
        ar >> damped >> saved_gamma;
        particles.load(ar);
        potential_current = false;
        if (saved_gamma != gamma)
          {
            gamma = saved_gamma;
            build_integrator(step_built > 0 ? step_built : prm.time_step);
          }
        integrator->invalidate_forces();
        dissipation_offset = damped - integrator->bath_work();
      }
      bool stop_damping() override
      {
        if (gamma == 0)
          return false;
        gamma = 0;
        integrator->set_damping(0);
        return true;
      }
      double total_dissipation() const override { return dissipation_offset + integrator->bath_work(); }

      /// The strip: the particles of the bottom `rows` rows plus the row above them (indices
      /// [0, (rows + 1) nx), rows upwards), that row held (fix_xy: it keeps its start velocity
      /// and moves with it, no force). A disturbance from the held row reaches the chain
      /// after rows dy / c_p; rows = ceil(depth c_p h / dy) makes that depth contact steps.
      bool advance_strip(double h, const std::vector<dem::Vec2> &chain_force,
                         std::vector<dem::Vec2> &chain_position) override
      {
        const double dy   = 0.5 * std::sqrt(3.0) * spacing;
        const long   rows = prm.particle.prediction_depth > 0 ? std::lround(std::ceil(prm.particle.prediction_depth * p_wave_speed(prm) * h / dy)) : 0;
        if (rows == 0 || rows + 1 >= ny)
          return false;
        if (std::abs(h - step_built) > 1e-12 * step_built)
          build_integrator(h);
        const unsigned int nx = n_nodes(), n = (rows + 1) * nx;
        if (strip.size() != n || strip_gamma != gamma || strip_h != h)
          {
            strip = mlp::Particles{};
            for (unsigned int p = 0; p < n; ++p)
              strip.add(particles.position[p], particles.mass[p], particles.group[p]);
            for (unsigned int p = rows * nx; p < n; ++p)
              strip.fixed[p] = mlp::fix_xy;
            strip_integrator = std::make_unique<mlp::LangevinIntegrator>(strip_forces, strip, integrator_parameters(h));
            strip_gamma      = gamma;
            strip_h          = h;
          }
        for (unsigned int p = 0; p < n; ++p)
          {
            strip.position[p]       = particles.position[p];
            strip.velocity[p]       = particles.velocity[p];
            strip.external_force[p] = dem::Vec2::Zero();
          }
        for (std::size_t i = 0; i < chain_force.size(); ++i)
          strip.external_force[chain[i]] = chain_force[i];
        strip_integrator->invalidate_forces();
        strip_integrator->run(strip, box, substeps_per_step);
        chain_position.resize(chain.size());
        for (std::size_t i = 0; i < chain.size(); ++i)
          chain_position[i] = strip.position[chain[i]];
        return true;
      }

    private:
      static mlp::InteractionParameters interaction(const FirstBodyParameters &p)
      {
        const double nu2 = p.poisson_ratio / (1 - p.poisson_ratio); // <= 1/3: check_mlp_body()
        const double c = p.length / chain_nodes(p);
        const auto   m = mlp::hexagonal_model_for(p.youngs_modulus / (1 - p.poisson_ratio * p.poisson_ratio), nu2, c);
        mlp::InteractionParameters ip;
        ip.r0        = c;
        ip.stiffness = m.stiffness;
        ip.f0        = m.f0;
        ip.n         = 6;
        ip.form      = mlp::ReturnForceForm::potential;
        return ip;
      }

      /// The sub-steps of a contact step @p h (substeps_per_step of them), at T = 0 with the
      /// compaction damping gamma.
      mlp::LangevinParameters integrator_parameters(double h) const
      {
        mlp::LangevinParameters lp;
        lp.time_step = h / substeps_per_step;
        lp.damping   = gamma * particles.mass[0];
        return lp;
      }

      /// A Verlet step of at most prm.particle.verlet_fraction of the stability limit that divides @p h.
      void build_integrator(double h)
      {
        const double carried = integrator ? total_dissipation() : dissipation_offset;
        substeps_per_step     = std::max(1.0, std::ceil(h / (prm.particle.verlet_fraction * 2 / omega_max)));
        integrator            = std::make_unique<mlp::LangevinIntegrator>(forces, particles, integrator_parameters(h));
        dissipation_offset = carried;
        step_built         = h;
        if (std::isnan(reference_energy))
          reference_energy = forces.potential_energy(particles, box);
      }

      mutable mlp::ForceField                  forces;
      mlp::ForceField                          strip_forces{interaction(prm)}; ///< of the strip (advance_strip())
      mlp::Particles                           strip;
      std::unique_ptr<mlp::LangevinIntegrator> strip_integrator;
      double                                   strip_gamma = -1, strip_h = 0;
      mlp::Particles                           particles;
      mlp::Box                                 box;
      std::unique_ptr<mlp::LangevinIntegrator> integrator;
      double       spacing = 0, omega_max = 0, gamma = 0, step_built = 0;
      double       dissipation_offset = 0;
      double       reference_energy   = NAN; ///< U of the unloaded lattice (-D per bond), J/m
      long         ny                 = 0;
      mutable double potential         = 0;     ///< cache of stored_energy()
      mutable bool   potential_current = false;
      unsigned int substeps_per_step  = 1;
    };
  } // namespace

  std::unique_ptr<DeformableBody> make_mlp_body(const FirstBodyParameters &p)
  {
    return std::make_unique<MlpFirstBody>(p);
  }
} // namespace tribo::coupling
