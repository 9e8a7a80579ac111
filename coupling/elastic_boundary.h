#pragma once
/// @file The deal.II first body (fem::ElasticBody) behind the solver's coupling
/// interface: its bottom-face nodes are the boundary nodes.

#include "coupling/deformable_body.h"
#include "fem/elastic_body.h"

namespace tribo::coupling
{
  /// Adapter: node positions are reference + displacement at the start of the step,
  /// node velocities those at the end of the previous step, the compliance is the
  /// body's condensed M~^-1 on its bottom nodes (m/s per N s/m).
  class ElasticBoundary : public DeformableBody
  {
  public:
    /// @p body must outlive the adapter; start_shearing() keeps its damping.
    explicit ElasticBoundary(fem::ElasticBody &body)
      : body(body), shear_mass_damping(body.parameters().rayleigh_mass),
        shear_stiffness_damping(body.parameters().rayleigh_stiffness)
    {}
    /// Owns @p owned; start_shearing() sets the Rayleigh coefficients to @p a (1/s), @p b (s).
    ElasticBoundary(std::unique_ptr<fem::ElasticBody> owned, double a, double b)
      : owned(std::move(owned)), body(*this->owned), shear_mass_damping(a), shear_stiffness_damping(b)
    {}

    unsigned int n_nodes() const override { return body.n_boundary_nodes(); }
    dem::Vec2    node_position(unsigned int i) const override
    {
      return body.boundary_position(i) + body.boundary_displacement(i);
    }
    dem::Vec2 node_velocity(unsigned int i) const override { return body.boundary_velocity(i); }
    void      predict(double h) override
    {
      body.set_time_step(h); // refactorises only when h changes
      body.predict();
    }
    dem::Vec2 node_free_velocity(unsigned int i) const override { return body.boundary_free_velocity(i); }
    const Eigen::MatrixXd &compliance() const override { return body.boundary_compliance(); }
    void finalize(const std::vector<dem::Vec2> &impulses) override { body.finalize(impulses); }
    /// Power of the top pressure over the last step, W/m.
    double external_power() const override { return body.load_power(); }
    /// Rayleigh damping, W/m.
    double internal_dissipation() const override { return body.damping_power(); }

    double mean_bottom_y() const override
    {
      return body.parameters().bottom + body.mean_bottom_displacement_y();
    }
    double mean_bottom_vy() const override
    {
      const unsigned int n  = n_nodes();
      double             vy = 0;
      for (unsigned int i = 0; i < n; ++i)
        vy += body.boundary_velocity(i).y() / n;
      return vy;
    }
    double kinetic_energy() const override { return body.kinetic_energy(); }
    double stored_energy() const override { return body.elastic_energy(); }
    void   start_shearing() override { body.set_damping(shear_mass_damping, shear_stiffness_damping); }
    std::string write_fields(const std::string &dir, unsigned int index) const override
    {
      const std::string name = deformable_body_snapshot_name(index);
      body.write_vtu(dir + "/" + name);
      return name;
    }
    std::string describe() const override;
    void        save(CheckpointOut &ar) const override { body.save(ar); }
    void        load(CheckpointIn &ar) override { body.load(ar); }

  private:
    std::unique_ptr<fem::ElasticBody> owned;
    fem::ElasticBody                 &body;
    double                            shear_mass_damping, shear_stiffness_damping;
  };
} // namespace tribo::coupling
