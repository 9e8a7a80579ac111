#pragma once
// A boundary body for the tests of the half-disc coupling: free point masses on a line.
#include "dem/engine/boundary.h"

#include <Eigen/Core>

#include <vector>

namespace tribo::dem::test
{
  /// n free point masses m on y = y_face at x = i L / n, with a load per node.
  class LumpedChain : public BoundaryBody
  {
  public:
    LumpedChain(unsigned int n, double L, double y_face, double m, Vec2 load = Vec2::Zero(), double theta = 0.5)
      : m(m), load(load), theta(theta), x(n), v(n, Vec2::Zero()), v_free(n), G(Eigen::MatrixXd::Identity(2 * n, 2 * n) / m)
    {
      for (unsigned int i = 0; i < n; ++i)
        x[i] = {i * L / n, y_face};
    }
    unsigned int n_nodes() const override { return x.size(); }
    Vec2 node_position(unsigned int i) const override { return x[i]; }
    Vec2 node_velocity(unsigned int i) const override { return v[i]; }
    void predict(double h_) override
    {
      h = h_;
      for (unsigned int i = 0; i < x.size(); ++i)
        v_free[i] = v[i] + h * load / m;
    }
    Vec2 node_free_velocity(unsigned int i) const override { return v_free[i]; }
    const Eigen::MatrixXd &compliance() const override { return G; }
    void finalize(const std::vector<Vec2> &R) override
    {
      power = 0;
      for (unsigned int i = 0; i < x.size(); ++i)
        {
          const Vec2 v_end = v_free[i] + R[i] / m;
          power += load.dot(0.5 * (v[i] + v_end));
          x[i] += h * (theta * v_end + (1 - theta) * v[i]);
          v[i] = v_end;
        }
    }
    double energy() const override
    {
      double e = 0;
      for (const Vec2 &vi : v)
        e += 0.5 * m * vi.squaredNorm();
      return e;
    }
    double external_power() const override { return power; }
    double internal_dissipation() const override { return 0; }
    Vec2 momentum() const
    {
      Vec2 p = Vec2::Zero();
      for (const Vec2 &vi : v)
        p += m * vi;
      return p;
    }

    double m;
    Vec2   load;
    double theta, h = 0, power = 0;
    std::vector<Vec2> x, v, v_free;
    Eigen::MatrixXd   G;
  };
} // namespace tribo::dem::test
