#include "coupling/particle_first_body.h"

#include "core/errors.h"

#include <boost/archive/binary_iarchive.hpp>
#include <boost/archive/binary_oarchive.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>

namespace tribo::coupling
{
  void ParticleFirstBody::set_rows(const std::vector<unsigned int> &bottom, const std::vector<unsigned int> &top_row)
  {
    chain = bottom;
    std::sort(chain.begin(), chain.end(),
              [&](unsigned int a, unsigned int b) { return position(a).x() < position(b).x(); });
    top = top_row;
    const unsigned int n = chain.size();
    reference_x.resize(n);
    start.resize(n);
    free.assign(n, dem::Vec2::Zero());
    G = Eigen::MatrixXd::Zero(2 * n, 2 * n);
    for (unsigned int i = 0; i < n; ++i)
      {
        reference_x[i] = position(chain[i]).x();
        start[i]       = position(chain[i]);
      }
    build_compliance(prm.time_step);
  }

  void ParticleFirstBody::build_compliance(double h)
  {
    const unsigned int n = chain.size();
    G                    = Eigen::MatrixXd::Zero(2 * n, 2 * n);
    for (unsigned int i = 0; i < n; ++i)
      G(2 * i, 2 * i) = G(2 * i + 1, 2 * i + 1) = 1 / mass(chain[i]);
    compliance_h = h;
  }

  dem::Vec2 ParticleFirstBody::unwrapped(unsigned int i) const
  {
    dem::Vec2    x  = position(chain[i]);
    const double dx = x.x() - reference_x[i];
    x.x()           = reference_x[i] + dx - prm.length * std::round(dx / prm.length);
    return x;
  }

  void ParticleFirstBody::predict(double h)
  {
    const unsigned int n = chain.size();
    if (h != compliance_h)
      build_compliance(h);
    for (unsigned int i = 0; i < n; ++i)
      start[i] = unwrapped(i);
    top_start_y.resize(top.size());
    for (std::size_t q = 0; q < top.size(); ++q)
      top_start_y[q] = position(top[q]).y();
    const double dissipated_before = total_dissipation();

    // The top load at mid-step, shared equally by the top particles (compressive).
    const double t_mid = time + 0.5 * h;
    const double ramp  = prm.pressure_ramp_time > 0 ? std::min(1.0, t_mid / prm.pressure_ramp_time) : 1.0;
    const double load  = -ramp * prm.pressure * prm.length / top.size();
    substeps           = advance(h, load);

    load_work = 0;
    for (std::size_t q = 0; q < top.size(); ++q)
      load_work += load * (position(top[q]).y() - top_start_y[q]);
    dissipated = total_dissipation() - dissipated_before;
    for (unsigned int i = 0; i < n; ++i)
      free[i] = velocity(chain[i]);
    step_h = h;
  }

  void ParticleFirstBody::finalize(const std::vector<dem::Vec2> &impulses)
  {
    if (!impulses.empty() && impulses.size() != chain.size())
      throw RunError("particle first body: " + std::to_string(impulses.size()) + " node impulses for " +
                     std::to_string(chain.size()) + " chain particles");
    const double stored_before = stored_energy();
    std::vector<dem::Vec2> dv(impulses.size()), dx(impulses.size());
    for (std::size_t i = 0; i < impulses.size(); ++i)
      {
        dv[i] = G(2 * i, 2 * i) * impulses[i];
        dx[i] = prm.theta * step_h * dv[i];
      }
    if (!impulses.empty())
      kick(chain, dv, dx);
    correction_work = impulses.empty() ? 0.0 : stored_energy() - stored_before;
    time += step_h;
    for (unsigned int i = 0; i < chain.size(); ++i)
      start[i] = unwrapped(i);
  }

  std::string ParticleFirstBody::overlap_hint(double h) const
  {
    const double s      = prm.length / chain.size();
    const double c      = p_wave_speed(prm);
    const double h_safe = particle_coupling_courant * s / c;
    std::ostringstream os;
    os << "With an " << prm.model << " upper body a grain that passes one radius may have gone through "
       << "its chain, whose particles are kicked once per contact step and give way in between: "
       << "here c_p h / s = " << c * h / s << " (c_p = " << c << " m/s, s = " << s << " m)";
    if (c * h / s > 0.5 * particle_coupling_courant)
      os << "; a smaller " << prm.time_step_entry << " holds them better (h = " << 0.5 * h_safe
         << " s is half the coupling limit; docs/first_bodies.md)";
    return os.str();
  }

  double ParticleFirstBody::mean_bottom_y() const
  {
    double y = 0;
    for (unsigned int p : chain)
      y += position(p).y();
    return y / chain.size();
  }

  double ParticleFirstBody::mean_bottom_vy() const
  {
    double vy = 0;
    for (unsigned int p : chain)
      vy += velocity(p).y();
    return vy / chain.size();
  }

  double ParticleFirstBody::kinetic_energy() const
  {
    double e = 0;
    for (unsigned int p = 0; p < n_particles(); ++p)
      e += 0.5 * mass(p) * velocity(p).squaredNorm();
    return e;
  }

  void ParticleFirstBody::save_base(CheckpointOut &ar) const
  {
    ar << time << step_h << load_work << dissipated << correction_work;
  }

  void ParticleFirstBody::load_base(CheckpointIn &ar)
  {
    ar >> time >> step_h >> load_work >> dissipated >> correction_work;
    for (unsigned int i = 0; i < chain.size(); ++i)
      start[i] = unwrapped(i);
  }
} // namespace tribo::coupling
