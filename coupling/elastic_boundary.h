#pragma once
/// @file The deal.II first body (fem::ElasticBody) behind the solver's coupling
/// interface (dem::BoundaryBody): its bottom-face nodes are the boundary nodes.

#include "dem/boundary.h"
#include "fem/elastic_body.h"

namespace tribo::coupling
{
  /// Adapter: node positions are reference + displacement at the start of the step,
  /// node velocities those at the end of the previous step, the compliance is the
  /// body's condensed M~^-1 on its bottom nodes (m/s per N s/m).
  class ElasticBoundary : public dem::BoundaryBody
  {
  public:
    /// @p body must outlive the adapter.
    explicit ElasticBoundary(fem::ElasticBody &body) : body(body) {}

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
    /// Kinetic plus elastic energy, J/m.
    double energy() const override { return body.kinetic_energy() + body.elastic_energy(); }
    /// Power of the top pressure over the last step, W/m.
    double external_power() const override { return body.load_power(); }
    /// Rayleigh damping, W/m.
    double internal_dissipation() const override { return body.damping_power(); }

  private:
    fem::ElasticBody &body;
  };
} // namespace tribo::coupling
