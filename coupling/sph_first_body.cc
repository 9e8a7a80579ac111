// The SPH upper first body: a solid SPH block (sph/) behind the coupling interface.
#include "coupling/models.h"
#include "coupling/particle_first_body.h"

#include "core/errors.h"
#include "core/output.h"
#include "core/point_cloud.h"
#include "sph/lattice.h"
#include "sph/solver.h"

#include <boost/archive/binary_iarchive.hpp>
#include <boost/archive/binary_oarchive.hpp>

#include <cmath>
#include <sstream>

namespace tribo::coupling
{
  namespace
  {
    using sph::Tensor;

    /// A plane-strain SPH block of nx x ny particles on a square lattice of spacing
    /// s = L / nx (mass rho s^2, smoothing length ratio x s), linear equation of
    /// state P = K (rho / rho0 - 1) with K = E / (3 (1 - 2 nu)), shear modulus
    /// G = E / (2 (1 + nu)), Monaghan viscosity (alpha 1, beta 0.1), periodic in x.
    /// The bottom row is the chain at y0; the top row carries the load and is held in x.
    /// Compaction damping: the SPH damping towards rest (not relative to the centre of
    /// mass), which also caps the body's landing speed on the layer.
    class SphFirstBody : public ParticleFirstBody
    {
    public:
      explicit SphFirstBody(const FirstBodyParameters &p)
        : ParticleFirstBody(p)
        , solver({sph::Material::linear(p.density, p.youngs_modulus / (3 * (1 - 2 * p.poisson_ratio)),
                                        p.youngs_modulus / (2 * (1 + p.poisson_ratio)))},
                 parameters(p))
      {
        const unsigned int nx = chain_nodes(p);
        spacing               = p.length / nx;
        ny                    = std::max(2L, std::lround(p.thickness / spacing));
        // Cell centres of [0, L) x [y0 - s/2, y0 + (ny - 1/2) s): rows at y0 + j s.
        const auto points = sph::lattice_points<2>(sph::LatticeType::cubic, Tensor<1, 2>({0, p.bottom - 0.5 * spacing}),
                                                   Tensor<1, 2>({p.length, ny * spacing}), spacing);
        sph::add_particles(solver.state, points, p.density, spacing * spacing, p.particle.smoothing_ratio * spacing, 0, 0);
        std::vector<unsigned int> bottom, top_row;
        for (unsigned int i = 0; i < solver.state.size(); ++i)
          {
            const double y = solver.state.x[i][1];
            if (y < p.bottom + 0.5 * spacing)
              bottom.push_back(i);
            if (y > p.bottom + (ny - 1.5) * spacing)
              top_row.push_back(i);
          }
        if (bottom.size() != nx || top_row.size() != nx)
          throw std::logic_error("SPH first body: lattice rows of " + std::to_string(bottom.size()) + " and " +
                                 std::to_string(top_row.size()) + " particles, expected " + std::to_string(nx));
        set_rows(bottom, top_row);
        row_of.resize(solver.state.size());
        for (unsigned int i = 0; i < solver.state.size(); ++i)
          row_of[i] = std::lround((solver.state.x[i][1] - p.bottom) / spacing);

        sph::ImposedVelocity<2> hold;
        hold.particles  = top_row;
        hold.components = 1; // x held, y free
        solver.imposed.push_back(hold);
        sph::ExternalForce<2> load;
        load.particles = top_row;
        solver.external.push_back(load);
        for (unsigned int p : chain) // the contact forces, external[1 + i] on chain particle i
          solver.external.push_back({{p}, {}, 0});
        if (p.compaction_damping > 0)
          {
            sph::Damping d{0, 2 * p.compaction_damping * M_PI * p_wave_speed(p) / (2 * p.thickness)};
            d.relative_to_centre_of_mass = false; // towards rest: also caps the landing speed
            solver.damping.push_back(d);
          }
      }

      std::string describe() const override
      {
        std::ostringstream os;
        os << "sph upper body: " << solver.state.size() << " particles (" << n_nodes() << " x " << ny
           << ", spacing " << spacing << " m, smoothing length " << prm.particle.smoothing_ratio << " x spacing), E = " << prm.youngs_modulus
           << " Pa, nu = " << prm.poisson_ratio << ", c_p = " << p_wave_speed(prm) << " m/s";
        return os.str();
      }

      /// The elastic energy: the internal energy sum m e less the artificial viscosity's
      /// heat, which is booked as dissipation inside the body (total_dissipation()), J/m.
      double stored_energy() const override { return solver.state.internal_energy() - solver.viscous_heat(); }

      std::string write_fields(const std::string &dir, unsigned int index) const override
      {
        const auto        &s = solver.state;
        const unsigned int n = s.size();
        std::vector<std::array<double, 3>> points(n);
        PointField velocity{"velocity", 2, {}}, sxx{"sigma_xx", 1, {}}, syy{"sigma_yy", 1, {}},
          sxy{"sigma_xy", 1, {}}, pressure{"pressure", 1, {}}, energy{"internal_energy", 1, {}};
        for (unsigned int i = 0; i < n; ++i)
          {
            points[i] = {{s.x[i][0], s.x[i][1], 0}};
            const double P = solver.materials()[0].evaluate(s.rho[i], s.e[i]).pressure;
            velocity.values.insert(velocity.values.end(), {s.v[i][0], s.v[i][1]});
            sxx.values.push_back(s.S[i][0][0] - P);
            syy.values.push_back(s.S[i][1][1] - P);
            sxy.values.push_back(s.S[i][0][1]);
            pressure.values.push_back(P);
            energy.values.push_back(s.e[i]);
          }
        const std::string name = deformable_body_snapshot_name(index);
        atomic_write(dir + "/" + name, point_cloud_vtu(2, points, {velocity, sxx, syy, sxy, pressure, energy}));
        return name;
      }

    protected:
      unsigned int n_particles() const override { return solver.state.size(); }
      dem::Vec2    position(unsigned int p) const override { return {solver.state.x[p][0], solver.state.x[p][1]}; }
      dem::Vec2    velocity(unsigned int p) const override { return {solver.state.v[p][0], solver.state.v[p][1]}; }
      double       mass(unsigned int p) const override { return solver.state.mass[p]; }
      unsigned int advance(double h, double load, const std::vector<dem::Vec2> &chain_force) override
      {
        solver.external[0].force = Tensor<1, 2>({0, load});
        for (std::size_t i = 0; i < chain_force.size(); ++i)
          solver.external[1 + i].force = Tensor<1, 2>({chain_force[i].x(), chain_force[i].y()});
        return solver.advance_to(solver.time + h);
      }
      void save_engine(CheckpointOut &ar) const override
      {
        ar << total_dissipation();
        solver.save(ar);
      }
      void load_engine(CheckpointIn &ar) override
      {
        double damped;
        ar >> damped;
        solver.load(ar);
        dissipation_offset = damped - solver.damping_dissipation() - solver.viscous_heat();
      }
      bool stop_damping() override
      {
        const bool had = !solver.damping.empty();
        solver.damping.clear();
        return had;
      }
      /// The compaction damping's work and the artificial viscosity's heat, J/m.
      double total_dissipation() const override
      {
        return dissipation_offset + solver.damping_dissipation() + solver.viscous_heat();
      }

      /// The strip: the particles of the bottom `rows` rows and of the `held` rows above
      /// them, the kernel's support 2 h_s, which keep their start velocities (imposed), so
      /// that every moving particle has its whole neighbourhood. A disturbance from the held
      /// rows reaches the chain after rows s / c_p; rows = ceil(depth c_p h / s) makes that
      /// depth contact steps. The strip takes its own adaptive steps.
      bool advance_strip(double h, const std::vector<dem::Vec2> &chain_force,
                         std::vector<dem::Vec2> &chain_position) override
      {
        const long rows = prm.particle.prediction_depth > 0 ? std::lround(std::ceil(prm.particle.prediction_depth * p_wave_speed(prm) * h / spacing)) : 0;
        const long held = std::lround(std::ceil(2 * prm.particle.smoothing_ratio));
        if (rows == 0 || rows + held >= ny)
          return false;
        const auto &full = solver.state;
        if (rows != strip_rows)
          {
            strip = std::make_unique<sph::Solver<2>>(solver.materials(), solver.parameters());
            strip_particles.clear();
            std::vector<unsigned int> index_in_strip(full.size(), 0);
            for (unsigned int i = 0; i < full.size(); ++i)
              if (row_of[i] < rows + held)
                {
                  index_in_strip[i] = strip_particles.size();
                  strip_particles.push_back(i);
                  if (row_of[i] >= rows)
                    strip->imposed.push_back({{index_in_strip[i]}, {}, 3, {}, false, {}});
                }
            strip->state = sph::ParticleState<2>{};
            for (const unsigned int i : strip_particles)
              strip->state.add(full.x[i], full.v[i], full.mass[i], full.rho[i], full.h[i], full.material[i], full.body[i]);
            for (const unsigned int p : chain)
              strip->external.push_back({{index_in_strip[p]}, {}, 0});
            strip_chain_index.resize(chain.size());
            for (std::size_t q = 0; q < chain.size(); ++q)
              strip_chain_index[q] = index_in_strip[chain[q]];
            strip_rows = rows;
          }
        auto &st = strip->state;
        for (std::size_t k = 0; k < strip_particles.size(); ++k)
          {
            const unsigned int i = strip_particles[k];
            st.x[k]   = full.x[i];
            st.v[k]   = full.v[i];
            st.rho[k] = full.rho[i];
            st.e[k]   = full.e[i];
            st.S[k]   = full.S[i];
            st.h[k]   = full.h[i];
          }
        for (auto &iv : strip->imposed)
          iv.velocity = st.v[iv.particles[0]];
        for (std::size_t q = 0; q < chain.size(); ++q)
          strip->external[q].force = Tensor<1, 2>({chain_force[q].x(), chain_force[q].y()});
        strip->damping = solver.damping;
        strip->time    = solver.time;
        strip->advance_to(solver.time + h);
        chain_position.resize(chain.size());
        for (std::size_t q = 0; q < chain.size(); ++q)
          chain_position[q] = {st.x[strip_chain_index[q]][0], st.x[strip_chain_index[q]][1]};
        return true;
      }

    private:
      /// The body's integrator is the leapfrog (sph::Integrator::leapfrog) at a Courant
      /// number C = 1.2 in dt = C h / (c (1 + 1.2 alpha) + beta max mu), 0.55 h / c with
      /// alpha = 1: four times the midpoint rule's 0.3 and below half the leapfrog's
      /// stability limit without viscosity, C = 1.5-2 at alpha = 0 (sph tests,
      /// LeapfrogKeepsTheVibrationsEnergyWhereTheMidpointRuleBlowsUp). On the 120-disc
      /// cell mu, the books' closure and the linearisation miss stay within the midpoint
      /// rule's errors; at the paper's size the body costs a fifth of the midpoint's
      /// time (docs/first_bodies.md, "Cost").
      static constexpr double courant = 1.2;

      static sph::SolverParameters parameters(const FirstBodyParameters &p)
      {
        sph::SolverParameters s;
        s.period     = p.length;
        s.integrator = sph::Integrator::leapfrog;
        s.courant    = courant;
        return s;
      }

      sph::Solver<2> solver;
      std::vector<long> row_of; ///< lattice row of each particle (0: the chain)
      std::unique_ptr<sph::Solver<2>> strip; ///< advance_strip()'s body
      std::vector<unsigned int> strip_particles, strip_chain_index; ///< full indices; the chain's in the strip
      long           strip_rows = 0;
      double         spacing = 0;
      long           ny      = 0;
      double         dissipation_offset = 0; ///< J/m, restored from a checkpoint
    };
  } // namespace

  std::unique_ptr<DeformableBody> make_sph_body(const FirstBodyParameters &p)
  {
    return std::make_unique<SphFirstBody>(p);
  }
} // namespace tribo::coupling
