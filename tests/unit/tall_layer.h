#pragma once
// A test problem shared by the NLGS band tests and the distributed solve's tests: a loaded
// hexagonal stack of discs between two walls, and its contacts after 20 steps.
#include "dem/engine/moreau_jean.h"

#include <cmath>
#include <vector>

namespace tribo::dem::test
{
  inline constexpr double rho = 7800, radius = 0.5e-6;

  /// A hexagonal stack of @p columns x @p rows discs (d = 1 um, 2 % gaps) between a sliding
  /// lower wall (1 m/s) and an upper wall loaded by 100 N/m per column, period @p columns um:
  /// 8 x 24 is tall enough for four bands of contacts. Without @p upper_wall, the stack's
  /// top is free (for a boundary body instead).
  inline ParticleSystem tall_layer(int columns = 8, int rows = 24, bool upper_wall = true)
  {
    ParticleSystem s;
    s.period = columns * 1e-6;
    std::vector<Vec2>   c;
    std::vector<double> rad;
    for (int i = 0; i < columns; ++i)
      {
        c.push_back({(i + 0.5) * 1e-6, 0});
        rad.push_back(radius);
      }
    const unsigned lower = s.add_clump(c, rad, rho);
    for (auto &d : s.bodies[lower].drive)
      d = Drive::velocity;
    s.bodies[lower].velocity = {1.0, 0};
    const double dy = 1.02e-6 * std::sqrt(3.0) / 2;
    for (int j = 0; j < rows; ++j)
      for (int i = 0; i < columns; ++i)
        s.add_disc({(i + 0.5 * (j % 2)) * 1.02e-6, 1.02e-6 + j * dy}, radius, rho);
    if (!upper_wall)
      return s;
    for (auto &p : c)
      p.y() = 1.02e-6 + rows * dy;
    const unsigned upper = s.add_clump(c, rad, rho);
    s.bodies[upper].drive    = {{Drive::velocity, Drive::force, Drive::velocity}};
    s.bodies[upper].load[1]  = -100.0 * columns;
    s.bodies[upper].velocity = {0, -1.0};
    return s;
  }

  /// The contacts of tall_layer() after 20 steps, with their impulses reset (a cold
  /// start: the sweeps have real work to do), and the state they act on,
  /// BodyState::of(system): their free velocities are that state's.
  struct ColdStart
  {
    ParticleSystem       system;
    ContactLaw           law;
    std::vector<Contact> contacts;
    explicit ColdStart(ContactLaw law_ = {}, int columns = 8, int rows = 24)
      : system(tall_layer(columns, rows))
      , law(law_)
    {
      SolverParameters prm;
      prm.method    = SolverParameters::Method::nlgs;
      prm.tolerance = 1e-3;
      MoreauJean mj(0.5, law, prm, 5e-8);
      for (int i = 0; i < 20; ++i)
        mj.step(system, 1e-9);
      contacts              = mj.contacts();
      const BodyState state = BodyState::of(system);
      for (auto &c : contacts)
        {
          c.r.setZero();
          c.u_free = state.local_velocity(c);
        }
    }
  };

  /// Exactly @p sweeps NLGS sweeps (a tolerance never met).
  inline SolverParameters fixed_sweeps(unsigned int sweeps)
  {
    SolverParameters p;
    p.method         = SolverParameters::Method::nlgs;
    p.tolerance      = 1e-300;
    p.max_iterations = sweeps;
    return p;
  }
} // namespace tribo::dem::test
