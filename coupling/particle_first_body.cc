#include "coupling/particle_first_body.h"
#include "coupling/models.h"

#include "core/errors.h"
#include "core/parameter_file.h"

#include <deal.II/base/parameter_handler.h>

#include <boost/archive/binary_iarchive.hpp>
#include <boost/archive/binary_oarchive.hpp>
#include <boost/serialization/vector.hpp>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace tribo::coupling
{
  void ParticleBodyParameters::declare(dealii::ParameterHandler &prm)
  {
    using dealii::Patterns::Double;
    prm.declare_entry("Upper body smoothing length ratio", "1.2", Double(),
                      "Smoothing length over particle spacing of the sph upper body (in [1, 2]).");
    prm.declare_entry("Upper body Verlet fraction", "0.05", Double(),
                      "Velocity-Verlet step of the mlp upper body as a fraction of its stability limit "
                      "2 / omega_max of the stiffest bond (in (0, 0.5]): smaller is more accurate and "
                      "slower. On the 120-disc cell at the fem body's step the energy books close to "
                      "0.03 % at 0.05 and to 0.17 % at 0.2, which is 3.5 times faster (docs/first_bodies.md).");
    prm.declare_entry("Upper body prediction depth", "3", Double(),
                      "sph and mlp upper bodies: the trial advances of each contact step (the chain's free "
                      "motion the contact solve predicts, and the columns of its compliance) run on the "
                      "bottom rows within this many wave reaches c_p h of the chain, the rows above them "
                      "within the interaction's reach carried at their start velocities, instead of on the "
                      "whole body (>= 0; 0: the whole body, also used when the strip would reach the top). "
                      "The real advance with the solved impulses is always the whole body's, so the books "
                      "are unchanged; a strip too thin shows as a larger linearisation miss. At 3 the "
                      "prediction is the whole body's to 1e-5 (unit tests; 1e-12 at every trial of a "
                      "sheared default-case mlp run) and a paper-size step costs 0.53 (sph) to 0.65 (mlp) "
                      "times as much (docs/first_bodies.md, \"Trial advances on a strip\"). May change on --resume.");
  }

  void ParticleBodyParameters::parse(const ParameterFile &f, FirstBodyParameters &p)
  {
    const auto entry = [&](const std::string &name) { return p.section.entry(name); };
    auto      &q     = p.particle;
    q.smoothing_ratio = f.get_checked(entry("Upper body smoothing length ratio"),
                                      [](double v) { return v >= 1 && v <= 2; }, "a ratio in [1, 2]");
    q.verlet_fraction = f.get_checked(entry("Upper body Verlet fraction"), [](double v) { return v > 0 && v <= 0.5; },
                                      "a fraction of the stability limit in (0, 0.5]");
    q.prediction_depth = f.get_checked(entry("Upper body prediction depth"), is_non_negative,
                                       "a depth >= 0 in wave reaches c_p h");
  }

  std::vector<std::string> ParticleBodyParameters::entries_that_may_change_on_resume()
  {
    return {"Upper body prediction depth"};
  }

  void check_mlp_body(const FirstBodyParameters &p)
  {
    if (p.poisson_ratio > 0.25 + 1e-12)
      throw InputError("entry '" + p.section.entry("Upper body Poisson ratio") + "' = '" + to_text(p.poisson_ratio) +
                       "': an mlp upper body needs nu <= 0.25 (its plane-strain 2D ratio nu/(1 - nu) must "
                       "be <= 1/3: return forces can only lower it); use 0.25 or less, or Upper body "
                       "model = fem or sph");
  }

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
    begin_velocity.assign(n, dem::Vec2::Zero());
    end_velocity.assign(n, dem::Vec2::Zero());
    mean_velocity.assign(n, dem::Vec2::Zero());
    for (unsigned int i = 0; i < n; ++i)
      {
        reference_x[i] = position(chain[i]).x();
        start[i]       = position(chain[i]);
      }
    G = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  }

  dem::Vec2 ParticleFirstBody::unwrapped(unsigned int i, dem::Vec2 x) const
  {
    const double dx = x.x() - reference_x[i];
    x.x()           = reference_x[i] + dx - prm.length * std::round(dx / prm.length);
    return x;
  }

  Eigen::VectorXd ParticleFirstBody::chain_displacement() const
  {
    Eigen::VectorXd d(2 * chain.size());
    for (unsigned int i = 0; i < chain.size(); ++i)
      d.segment<2>(2 * i) = unwrapped(i) - start[i];
    return d;
  }

  Eigen::VectorXd ParticleFirstBody::trial_displacement(double h, double load, const std::vector<dem::Vec2> &force)
  {
    if (advance_strip(h, force, strip_chain))
      {
        Eigen::VectorXd d(2 * chain.size());
        for (unsigned int i = 0; i < chain.size(); ++i)
          d.segment<2>(2 * i) = unwrapped(i, strip_chain[i]) - start[i];
        engine_free = false;
        return d;
      }
    // S_0 is kept only when the whole body leaves it (a strip trial never does).
    if (engine_at_start)
      start_state = snapshot();
    else
      restore(start_state);
    substeps        = advance(h, load, force);
    engine_at_start = false;
    engine_free     = false;
    return chain_displacement();
  }

  double ParticleFirstBody::top_load(double h) const
  {
    const double t_mid = time + 0.5 * h;
    const double ramp  = prm.pressure_ramp_time > 0 ? std::min(1.0, t_mid / prm.pressure_ramp_time) : 1.0;
    return -ramp * prm.pressure * prm.length / top.size();
  }

  std::string ParticleFirstBody::snapshot() const
  {
    std::ostringstream os;
    {
      CheckpointOut ar(os, boost::archive::no_header);
      save_engine(ar);
    }
    return os.str();
  }

  void ParticleFirstBody::restore(const std::string &state)
  {
    std::istringstream is(state);
    CheckpointIn       ar(is, boost::archive::no_header);
    load_engine(ar);
  }

  void ParticleFirstBody::build_compliance(double h, double load)
  {
    // Column 2j + c: advance from S_0 with the force eps e_c / h on chain particle j: eps =
    // P s h, the impulse a chain particle carries in a step under the load (a secant at
    // the contacts' amplitude); unloaded, eps moves a free particle by compliance_probe
    // spacings (eps h / (2 m)).
    const unsigned int n       = chain.size();
    const double       spacing = prm.length / n;
    Eigen::MatrixXd    D(2 * n, 2 * n);
    std::vector<dem::Vec2> force(n, dem::Vec2::Zero());
    for (unsigned int j = 0; j < n; ++j)
      for (int c = 0; c < 2; ++c)
        {
          const double eps = prm.pressure > 0 ? prm.pressure * spacing * h
                                              : 2 * mass(chain[j]) * compliance_probe * spacing / h;
          force[j][c] = eps / h;
          D.col(2 * j + c) = (trial_displacement(h, load, force) - free_displacement) / eps;
          force[j][c] = 0;
        }
    asymmetry   = (D - D.transpose()).norm() / D.norm();
    G             = positive_part(D) / (prm.theta * h);
    compliance_h  = h;
    stale         = false;
    recent_miss   = 0;
    ++builds;
  }

  Eigen::MatrixXd ParticleFirstBody::positive_part(const Eigen::MatrixXd &D)
  {
    // sym(D) is positive semi-definite for a linear conservative body (file comment);
    // round-off, the nonlinear terms and the secant updates may leave negative
    // eigenvalues: clip them.
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(0.5 * (D + D.transpose()));
    const Eigen::VectorXd lambda = eig.eigenvalues().cwiseMax(0.0);
    return eig.eigenvectors() * lambda.asDiagonal() * eig.eigenvectors().transpose();
  }

  void ParticleFirstBody::predict(double h)
  {
    const unsigned int n = chain.size();
    for (unsigned int i = 0; i < n; ++i)
      start[i] = unwrapped(i);
    top_start_y.resize(top.size());
    for (std::size_t q = 0; q < top.size(); ++q)
      top_start_y[q] = position(top[q]).y();
    dissipation_at_start = total_dissipation();
    engine_at_start      = true;
    step_h               = h;
    step_load            = top_load(h);

    free_displacement = trial_displacement(h, step_load, std::vector<dem::Vec2>(n, dem::Vec2::Zero()));
    engine_free       = !engine_at_start; // the whole body's free end state, kept if no impulse comes
    // v_b: the chain's mean velocity over the last step (file comment).
    const double th = prm.theta;
    for (unsigned int i = 0; i < n; ++i)
      {
        begin_velocity[i] = mean_velocity[i];
        free[i] = (free_displacement.segment<2>(2 * i) / h - (1 - th) * begin_velocity[i]) / th;
      }
    if (stale || h != compliance_h)
      build_compliance(h, step_load);
    in_step = true;
  }

  void ParticleFirstBody::finalize(const std::vector<dem::Vec2> &impulses)
  {
    const unsigned int n = chain.size();
    if (!impulses.empty() && impulses.size() != n)
      throw RunError("particle first body: " + std::to_string(impulses.size()) + " node impulses for " +
                     std::to_string(n) + " chain particles");
    const double h = step_h, th = prm.theta;
    Eigen::VectorXd R = Eigen::VectorXd::Zero(2 * n);
    for (std::size_t i = 0; i < impulses.size(); ++i)
      R.segment<2>(2 * i) = impulses[i];
    if (R.squaredNorm() > 0 || !engine_free)
      {
        if (!engine_at_start)
          restore(start_state);
        std::vector<dem::Vec2> force(n);
        for (unsigned int i = 0; i < n; ++i)
          force[i] = R.segment<2>(2 * i) / h;
        substeps = advance(h, step_load, force);
      }
    engine_free     = false;
    engine_at_start = false;
    in_step         = false;

    // The books of the real step.
    load_work = 0;
    for (std::size_t q = 0; q < top.size(); ++q)
      load_work += step_load * (position(top[q]).y() - top_start_y[q]);
    dissipated                = total_dissipation() - dissipation_at_start;
    const Eigen::VectorXd d   = chain_displacement();
    double                booked = 0;
    for (unsigned int i = 0; i < n; ++i)
      {
        end_velocity[i]  = (d.segment<2>(2 * i) / h - (1 - th) * begin_velocity[i]) / th;
        mean_velocity[i] = d.segment<2>(2 * i) / h;
        booked += R.segment<2>(2 * i).dot(0.5 * (begin_velocity[i] + end_velocity[i]));
      }
    extra_work = R.dot(d) / h - booked;

    // How well the linearisation predicted the chain's response.
    const Eigen::VectorXd response = th * h * (G * R);
    const double          scale    = response.lpNorm<Eigen::Infinity>();
    last_miss = scale > 0 ? (d - free_displacement - response).lpNorm<Eigen::Infinity>() / scale : 0.0;
    worst_miss = std::max(worst_miss, last_miss);
    if (scale > 0)
      {
        miss_sum += last_miss;
        ++steps_with_contacts;
        real_response_work += R.dot(d - free_displacement);
        predicted_response_work += R.dot(response);
        // The relaxed Powell-symmetric-Broyden update of sym(D) = theta h G towards this
        // step's secant, D R = d - d_free (file comment).
        const Eigen::VectorXd e  = d - free_displacement - response;
        const double          rr = R.squaredNorm();
        const Eigen::MatrixXd update =
          (e * R.transpose() + R * e.transpose()) / rr - (e.dot(R) / (rr * rr)) * (R * R.transpose());
        G = positive_part(th * h * G + secant_relaxation * update) / (th * h);
        recent_miss += (last_miss - recent_miss) / miss_memory;
        if (recent_miss > compliance_tolerance)
          stale = true;
      }
    ++steps;

    time += h;
    for (unsigned int i = 0; i < n; ++i)
      start[i] = unwrapped(i);
  }

  void ParticleFirstBody::start_shearing()
  {
    if (stop_damping())
      stale = true;
  }

  void ParticleFirstBody::summarize(JsonObject &j) const
  {
    j.set("upper_body_steps", long(steps));
    j.set("upper_body_compliance_builds", long(builds));
    j.set("upper_body_linearisation_miss_max", worst_miss);
    j.set("upper_body_linearisation_miss_mean", steps_with_contacts > 0 ? miss_sum / steps_with_contacts : 0.0);
    j.set("upper_body_compliance_asymmetry", asymmetry);
    j.set("upper_body_response_ratio",
          predicted_response_work > 0 ? real_response_work / predicted_response_work : 0.0);
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

  void ParticleFirstBody::save(CheckpointOut &ar) const
  {
    save_engine(ar);
    ar << time << step_h << load_work << dissipated << extra_work << compliance_h << stale << builds << steps
       << steps_with_contacts << miss_sum << worst_miss << asymmetry << real_response_work
       << predicted_response_work << recent_miss;
    const std::vector<double> g(G.data(), G.data() + G.size());
    ar << g;
    for (const std::vector<dem::Vec2> *v : {&end_velocity, &mean_velocity})
      for (const dem::Vec2 &u : *v)
        ar << u.x() << u.y();
  }

  void ParticleFirstBody::load(CheckpointIn &ar)
  {
    load_engine(ar);
    ar >> time >> step_h >> load_work >> dissipated >> extra_work >> compliance_h >> stale >> builds >> steps >>
      steps_with_contacts >> miss_sum >> worst_miss >> asymmetry >> real_response_work >>
      predicted_response_work >> recent_miss;
    std::vector<double> g;
    ar >> g;
    if (g.size() != std::size_t(G.size()))
      throw InputError("checkpoint: its particle-body compliance has " + std::to_string(g.size()) +
                       " entries, this case's chain needs " + std::to_string(G.size()));
    std::copy(g.begin(), g.end(), G.data());
    for (std::vector<dem::Vec2> *v : {&end_velocity, &mean_velocity})
      for (dem::Vec2 &u : *v)
        ar >> u.x() >> u.y();
    for (unsigned int i = 0; i < chain.size(); ++i)
      start[i] = unwrapped(i);
  }
} // namespace tribo::coupling
