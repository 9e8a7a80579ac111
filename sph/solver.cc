#include "sph/solver.h"

#include "core/errors.h"
#include "core/serialization.h"

#include <deal.II/base/parallel.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>
#include <type_traits>

namespace tribo::sph
{
  namespace
  {
    template <int dim>
    std::string vec_text(const Tensor<1, dim> &a)
    {
      std::string s = "(";
      for (unsigned int d = 0; d < dim; ++d)
        s += (d ? ", " : "") + to_text(a[d]);
      return s + ")";
    }

    template <int dim>
    void resize(Rates<dim> &k, unsigned int n)
    {
      k.dx.assign(n, Tensor<1, dim>());
      k.dv.assign(n, Tensor<1, dim>());
      k.drho.assign(n, 0);
      k.de.assign(n, 0);
      k.dS.assign(n, SymmetricTensor<2, dim>());
      k.boundary_force.assign(n, Tensor<1, dim>());
      k.pressure.assign(n, 0);
      k.velocity_moment.resize(n);
      k.signal.assign(n, 0);
      k.viscous_heating.assign(n, 0);
    }

    /// Monaghan's Pi_ij (m^5/(kg s^2), as sigma/rho^2) of the pair (i, j) with velocity
    /// difference dv = v_i - v_j at separation r = x_i - x_j (r2 = |r|^2, hij the mean
    /// smoothing length, c the longitudinal sound speeds): for dv.r < 0,
    /// mu_ij = h_ij dv.r / (r2 + eps h_ij^2) and Pi_ij = (-alpha cbar mu_ij + beta mu_ij^2) /
    /// rhobar, else 0. Raises @p max_mu to -mu_ij.
    template <int dim>
    inline __attribute__((always_inline)) double monaghan_pi(const ParticleState<dim> &s, unsigned int i, unsigned int j, const Tensor<1, dim> &dv,
                       const Tensor<1, dim> &r, double r2, double hij, const std::vector<double> &c, double alpha,
                       double beta, double eps, double &max_mu)
    {
      const double vr = dv * r;
      if (vr >= 0)
        return 0;
      // mu = h vr / D and Pi = (-alpha c mu + beta mu^2) / rho, one division.
      const double D   = r2 + eps * hij * hij;
      const double rho = 0.5 * (s.rho[i] + s.rho[j]);
      const double inv = 1 / (D * rho);
      const double mu  = hij * vr * rho * inv;
      max_mu           = std::max(max_mu, -mu);
      return (-alpha * 0.5 * (c[i] + c[j]) * mu + beta * mu * mu) * D * inv;
    }

    template <typename F>
    void parallel_for(unsigned int n, F &&f)
    {
      dealii::parallel::apply_to_subranges(
        0U, n,
        [&](unsigned int b, unsigned int e) {
          for (unsigned int i = b; i < e; ++i)
            f(i);
        },
        128);
    }
  } // namespace

  template <int dim>
  Solver<dim>::Solver(const std::vector<Material> &materials, const SolverParameters &parameters)
    : mats(materials)
    , prm(parameters)
    , search(parameters.period)
  {
    if (mats.empty())
      throw InputError("SPH solver: no material given");
  }

  template <int dim>
  std::string Solver<dim>::describe_particle(const ParticleState<dim> &s, unsigned int i) const
  {
    return "particle " + std::to_string(i) + " (x = " + vec_text(s.x[i]) +
           " m, v = " + vec_text(s.v[i]) + " m/s, rho = " + to_text(s.rho[i]) + " kg/m^3)";
  }

  template <int dim>
  void Solver<dim>::update_neighbours(const ParticleState<dim> &s, double cutoff)
  {
    const unsigned int n = s.size();
    double             moved2 = 0;
    if (x_at_build.size() == n)
      for (unsigned int i = 0; i < n; ++i)
        moved2 = std::max(moved2, search.separation(s.x[i], x_at_build[i]).norm_square());
    if (x_at_build.size() == n && search.period == prm.period &&
        cutoff + 2 * std::sqrt(moved2) <= built_cutoff)
      return;
    search.period = prm.period;
    built_cutoff  = cutoff * (1 + prm.neighbour_skin);
    search.build(s.x, built_cutoff);
    x_at_build = s.x;
    ++builds;
  }

  template <int dim>
  void Solver<dim>::compute_rates(const ParticleState<dim> &s, double t, Rates<dim> &k, bool viscosity)
  {
    evaluate<Pass::all>(s, t, k, viscosity);
  }

  template <int dim>
  template <typename Solver<dim>::Pass pass>
  void Solver<dim>::evaluate(const ParticleState<dim> &s, double t, Rates<dim> &k, bool viscosity)
  {
    constexpr bool kinematics = pass != Pass::forces, forces = pass != Pass::kinematics;
    const unsigned int n = s.size();
    resize(k, n);
    double h_max = 0;
    for (unsigned int i = 0; i < n; ++i)
      h_max = std::max(h_max, s.h[i]);
    update_neighbours(s, std::max(2 * h_max, prm.boundary.range()));

    // Per-particle pressure, longitudinal sound speed, sigma/rho^2, volume m/rho and 1/h:
    // loaded in the pair loop rather than recomputed per pair.
    std::vector<double>                  c(forces ? n : 0), volume(n), inv_h(n);
    std::vector<SymmetricTensor<2, dim>> A(forces ? n : 0); // the velocity gradient needs neither
    parallel_for(n, [&](unsigned int i) {
      if constexpr (forces)
        {
          const Material &m  = mats[s.material[i]];
          const auto      ps = m.evaluate(s.rho[i], s.e[i]);
          k.pressure[i]      = ps.pressure;
          c[i] = std::sqrt(ps.sound_speed * ps.sound_speed + 4 * m.shear_modulus / (3 * s.rho[i]));
          A[i] = (s.S[i] - ps.pressure * dealii::unit_symmetric_tensor<dim>()) / (s.rho[i] * s.rho[i]);
        }
      volume[i] = s.mass[i] / s.rho[i];
      inv_h[i]  = 1 / s.h[i];
    });

    const BoundaryForce &bf        = prm.boundary;
    const double         bf_range2 = bf.range() * bf.range();
    const double         alpha = viscosity ? prm.alpha : 0.0, beta = viscosity ? prm.beta : 0.0;
    const double         eps   = prm.av_epsilon;
    // One body of one smoothing length (the first bodies, the plate): the pair loop skips
    // the body test and takes h_ij = h_i (the same values, fewer loads per pair).
    bool uniform = true;
    for (unsigned int i = 1; i < n && uniform; ++i)
      uniform = s.body[i] == s.body[0] && s.h[i] == s.h[0];
    const auto particle = [&](unsigned int i, auto one_body) {
      constexpr bool same = decltype(one_body)::value;
      Tensor<1, dim> acc, fb;
      Tensor<2, dim> L, M, T;
      double         drho = 0, de = 0, heating = 0, max_mu = 0;
      for (unsigned int q = search.start[i]; q < search.start[i + 1]; ++q)
        {
          const unsigned int   j  = search.list[q];
          const Tensor<1, dim> r  = search.separation(s.x[i], s.x[j]);
          const double         r2 = r.norm_square();
          if (!same && s.body[i] != s.body[j])
            {
              if constexpr (forces)
                {
                  if (r2 < bf_range2 && r2 > 0)
                    {
                      const double dist  = std::sqrt(r2);
                      const double scale = bf.per_unit_mass() ? 0.5 * (s.mass[i] + s.mass[j]) : 1.0;
                      fb += (scale * bf.value(dist) / dist) * r;
                    }
                  const double hij = 0.5 * (s.h[i] + s.h[j]);
                  if (prm.interface_viscosity && r2 < 4 * hij * hij)
                    {
                      const Tensor<1, dim> dv = s.v[i] - s.v[j];
                      const double         Pi = monaghan_pi(s, i, j, dv, r, r2, hij, c, alpha, beta, eps, max_mu);
                      if (Pi != 0)
                        {
                          const Tensor<1, dim> g   = CubicSplineKernel<dim>::gradient(r, r2, 1 / hij);
                          const double         dvg = dv * g;
                          fb -= (s.mass[i] * s.mass[j] * Pi) * g;
                          if constexpr (pass == Pass::all)
                            de += s.mass[j] * 0.5 * Pi * dvg;
                          heating += s.mass[j] * 0.5 * Pi * dvg;
                        }
                    }
                }
              continue;
            }
          const double hij = same ? s.h[i] : 0.5 * (s.h[i] + s.h[j]);
          if (r2 >= 4 * hij * hij)
            continue;
          const double         inv_hij = same || s.h[i] == s.h[j] ? inv_h[i] : 1 / hij;
          const Tensor<1, dim> g       = CubicSplineKernel<dim>::gradient(r, r2, inv_hij);
          const Tensor<1, dim> dv = s.v[i] - s.v[j];
          const double         mj = s.mass[j];
          const double         dvg = dv * g;
          if constexpr (pass == Pass::all)
            {
              drho += mj * dvg;
              const double Pi = monaghan_pi(s, i, j, dv, r, r2, hij, c, alpha, beta, eps, max_mu);
              const SymmetricTensor<2, dim> pair = A[i] + A[j];
              acc += mj * (pair * g - Pi * g);
              de += mj * (-(dv * (A[i] * g)) + 0.5 * Pi * dvg);
              heating += mj * 0.5 * Pi * dvg;
              L -= volume[j] * dealii::outer_product(dv, g);
              M -= volume[j] * dealii::outer_product(r, g);
            }
          else if constexpr (pass == Pass::kinematics)
            {
              drho += mj * dvg;
              T += mj * dealii::outer_product(dv, g);
              L -= volume[j] * dealii::outer_product(dv, g);
              M -= volume[j] * dealii::outer_product(r, g);
            }
          else
            {
              const double Pi = monaghan_pi(s, i, j, dv, r, r2, hij, c, alpha, beta, eps, max_mu);
              const SymmetricTensor<2, dim> pair = A[i] + A[j];
              acc += mj * (pair * g - Pi * g);
              heating += mj * 0.5 * Pi * dvg;
            }
        }
      if constexpr (kinematics)
        {
          if (prm.corrected_gradient)
            {
              const double det = dealii::determinant(M);
              if (std::isfinite(det) && det > std::pow(0.05, dim))
                L = L * dealii::invert(M);
            }
          const double G = mats[s.material[i]].shear_modulus;
          const SymmetricTensor<2, dim> eps_dot = dealii::symmetrize(L);
          const Tensor<2, dim>          omega   = 0.5 * (L - dealii::transpose(L));
          const Tensor<2, dim>          S(s.S[i]);
          const Tensor<2, dim>          rot = omega * S - S * omega;
          k.dS[i] = 2 * G * (eps_dot - dealii::trace(eps_dot) / 3.0 * dealii::unit_symmetric_tensor<dim>()) +
                    dealii::symmetrize(rot);
          k.drho[i] = drho;
          k.dx[i]   = s.v[i];
          if constexpr (pass == Pass::kinematics)
            k.velocity_moment[i] = T;
        }
      if constexpr (pass == Pass::forces)
        de = heating; // the viscous heat is this pass's whole share of de
      if constexpr (forces)
        {
          k.dv[i]              = acc + fb / s.mass[i];
          k.boundary_force[i]  = fb;
          k.viscous_heating[i] = heating;
          k.signal[i]          = c[i] * (1 + 1.2 * alpha) + beta * max_mu;
        }
      k.de[i] = de;
    };
    if (uniform)
      parallel_for(n, [&](unsigned int i) { particle(i, std::true_type()); });
    else
      parallel_for(n, [&](unsigned int i) { particle(i, std::false_type()); });

    if constexpr (forces)
      add_loads(s, t, k);
  }

  template <int dim>
  void Solver<dim>::add_loads(const ParticleState<dim> &s, double t, Rates<dim> &k) const
  {
    for (const auto &ef : external)
      {
        const double ramp = ef.tau > 0 ? 1 - std::exp(-t / ef.tau) : 1.0;
        for (unsigned int i : ef.particles)
          k.dv[i] += (ramp / s.mass[i]) * ef.force;
      }
    k.imposed_force.assign(imposed.size(), Tensor<1, dim>());
    for (unsigned int e = 0; e < imposed.size(); ++e)
      for (unsigned int i : imposed[e].particles)
        for (unsigned int c = 0; c < dim; ++c)
          if (!imposed[e].between_steps && (imposed[e].components & (1u << c)))
            {
              k.imposed_force[e][c] -= s.mass[i] * k.dv[i][c];
              k.dv[i][c] = 0;
            }
  }

  template <int dim>
  double Solver<dim>::stable_step(const ParticleState<dim> &s, const Rates<dim> &k,
                                  std::string &lim, std::vector<unsigned int> &worst) const
  {
    const unsigned int  n = s.size();
    std::vector<double> dt_i(n);
    std::vector<char>   by_acc(n, 0);
    for (unsigned int i = 0; i < n; ++i)
      {
        const double dt_c = prm.courant * s.h[i] / k.signal[i];
        const double a    = k.dv[i].norm();
        const double dt_a = a > 0 ? prm.acceleration_factor * std::sqrt(s.h[i] / a)
                                  : std::numeric_limits<double>::infinity();
        dt_i[i]   = std::min(dt_c, dt_a);
        by_acc[i] = dt_a < dt_c;
      }
    std::vector<unsigned int> order(n);
    std::iota(order.begin(), order.end(), 0U);
    const unsigned int n_worst = std::min(5U, n);
    std::partial_sort(order.begin(), order.begin() + n_worst, order.end(),
                      [&](unsigned int a, unsigned int b) {
                        return dt_i[a] < dt_i[b] || (dt_i[a] == dt_i[b] && a < b);
                      });
    worst.assign(order.begin(), order.begin() + n_worst);
    if (n == 0)
      {
        lim = "dt_max";
        return prm.dt_max;
      }
    lim = by_acc[order[0]] ? "acceleration" : "CFL";
    return dt_i[order[0]];
  }

  template <int dim>
  void Solver<dim>::apply_imposed(ParticleState<dim> &s, double t, bool count, bool stage)
  {
    for (auto &iv : imposed)
      if (!(stage && iv.between_steps))
        for (unsigned int i : iv.particles)
          {
            const Tensor<1, dim> v = iv.field ? iv.field(s.x[i], t) : iv.velocity;
            for (unsigned int c = 0; c < dim; ++c)
              if (iv.components & (1u << c))
                {
                  if (count)
                    iv.impulse[c] += s.mass[i] * (v[c] - s.v[i][c]);
                  s.v[i][c] = v[c];
                }
          }
  }

  template <int dim>
  void Solver<dim>::apply_damping(ParticleState<dim> &s, double dt)
  {
    if (damping.empty())
      return;
    std::vector<char> fixed(s.size(), 0);
    for (const auto &iv : imposed)
      if (iv.components == (1u << dim) - 1)
        for (unsigned int i : iv.particles)
          fixed[i] = 1;
    const double kinetic_before = s.kinetic_energy();
    for (const auto &d : damping)
      {
        Tensor<1, dim> p;
        double         m = 0;
        for (unsigned int i = 0; i < s.size(); ++i)
          if (s.body[i] == d.body)
            {
              p += s.mass[i] * s.v[i];
              m += s.mass[i];
            }
        if (m == 0)
          continue;
        Tensor<1, dim> vcm = p / m;
        if (!d.relative_to_centre_of_mass)
          for (unsigned int c = 0; c < dim; ++c)
            vcm[c] = d.reference_velocity[c];
        const double         f   = std::exp(-d.gamma * dt);
        for (unsigned int i = 0; i < s.size(); ++i)
          if (s.body[i] == d.body && !fixed[i])
            s.v[i] = vcm + f * (s.v[i] - vcm);
      }
    damped_energy += kinetic_before - s.kinetic_energy();
  }

  template <int dim>
  void Solver<dim>::check_finite(const ParticleState<dim> &s, const std::string &where) const
  {
    std::vector<unsigned int> bad;
    for (unsigned int i = 0; i < s.size() && bad.size() < 5; ++i)
      {
        bool ok = std::isfinite(s.rho[i]) && s.rho[i] > 0 && std::isfinite(s.e[i]);
        for (unsigned int d = 0; d < dim; ++d)
          ok = ok && std::isfinite(s.x[i][d]) && std::isfinite(s.v[i][d]);
        for (unsigned int a = 0; a < dim; ++a)
          for (unsigned int b = a; b < dim; ++b)
            ok = ok && std::isfinite(s.S[i][a][b]);
        if (!ok)
          bad.push_back(i);
      }
    if (bad.empty())
      return;
    std::string msg = "SPH: NaN/Inf or non-positive density " + where + " at t = " +
                      to_text(time) + " s in";
    for (unsigned int i : bad)
      msg += " " + describe_particle(s, i) + ";";
    throw RunError(msg);
  }

  template <int dim>
  void Solver<dim>::check_rates(const Rates<dim> &k) const
  {
    std::vector<unsigned int> bad;
    for (unsigned int i = 0; i < state.size() && bad.size() < 5; ++i)
      {
        bool ok = std::isfinite(k.drho[i]) && std::isfinite(k.de[i]);
        for (unsigned int d = 0; d < dim; ++d)
          ok = ok && std::isfinite(k.dv[i][d]);
        if (!ok)
          bad.push_back(i);
      }
    if (bad.empty())
      return;
    std::string msg = "SPH: NaN/Inf rate at t = " + to_text(time) + " s in";
    for (unsigned int i : bad)
      msg += " " + describe_particle(state, i) + ";";
    throw RunError(msg);
  }

  template <int dim>
  double Solver<dim>::step_size(const Rates<dim> &k, double dt_limit)
  {
    std::vector<unsigned int> worst;
    double                    dt = stable_step(state, k, limiter, worst);
    if (prm.fixed_step > 0)
      {
        dt      = prm.fixed_step;
        limiter = "fixed";
      }
    else if (dt < prm.dt_min)
      {
        std::string msg = "SPH time step " + to_text(dt) + " s fell below the step floor dt_min = " +
                          to_text(prm.dt_min) + " s, limited by the " + limiter +
                          " condition, at t = " + to_text(time) + " s; smallest steps in";
        for (unsigned int i : worst)
          msg += " " + describe_particle(state, i) + ";";
        throw RunError(msg);
      }
    if (prm.dt_max < dt)
      {
        dt      = prm.dt_max;
        limiter = "dt_max";
      }
    if (dt_limit < dt)
      {
        dt      = dt_limit;
        limiter = "dt_limit";
      }
    return dt;
  }

  template <int dim>
  double Solver<dim>::step(double dt_limit)
  {
    forces_current = false;
    return prm.integrator == Integrator::leapfrog ? leapfrog_step(dt_limit) : midpoint_step(dt_limit);
  }

  template <int dim>
  double Solver<dim>::midpoint_step(double dt_limit)
  {
    const unsigned int n = state.size();
    apply_imposed(state, time);
    compute_rates(state, time, k1);
    check_rates(k1);
    const double dt = step_size(k1, dt_limit);

    // Predictor to the midpoint.
    mid = state;
    parallel_for(n, [&](unsigned int i) {
      const double hdt = 0.5 * dt;
      mid.x[i] += hdt * k1.dx[i];
      mid.v[i] += hdt * k1.dv[i];
      mid.rho[i] += hdt * k1.drho[i];
      mid.e[i] += hdt * k1.de[i];
      mid.S[i] += hdt * k1.dS[i];
    });
    apply_imposed(mid, time + 0.5 * dt, false, true);
    compute_rates(mid, time + 0.5 * dt, k2);
    parallel_for(n, [&](unsigned int i) {
      state.x[i] += dt * k2.dx[i];
      state.v[i] += dt * k2.dv[i];
      state.rho[i] += dt * k2.drho[i];
      state.e[i] += dt * k2.de[i];
      state.S[i] += dt * k2.dS[i];
      if (prm.period > 0)
        state.x[i][0] -= prm.period * std::floor(state.x[i][0] / prm.period);
    });
    double step_heat = 0;
    for (unsigned int i = 0; i < n; ++i)
      step_heat += state.mass[i] * k2.viscous_heating[i];
    heat += dt * step_heat;
    for (unsigned int e = 0; e < imposed.size(); ++e)
      imposed[e].impulse += dt * k2.imposed_force[e];
    finish_step(dt);
    return dt;
  }

  template <int dim>
  double Solver<dim>::leapfrog_step(double dt_limit)
  {
    const unsigned int n = state.size();
    if (!forces_current)
      {
        apply_imposed(state, time);
        evaluate<Pass::forces>(state, time, k2);
        check_rates(k2);
      }
    const double dt = step_size(k2, dt_limit), hdt = 0.5 * dt;

    // Kick to v_{n+1/2}; the kinematic rates at the midpoint x_n + dt/2 v_{n+1/2}.
    mid = state;
    parallel_for(n, [&](unsigned int i) { mid.v[i] += hdt * k2.dv[i]; });
    apply_imposed(mid, time + hdt, false, true);
    parallel_for(n, [&](unsigned int i) { mid.x[i] += hdt * mid.v[i]; });
    evaluate<Pass::kinematics>(mid, time + hdt, k1);
    // Drift, and the velocity v_{n+1/2} + dt/2 a_n that the viscosity sees at the end.
    // The stress power -A : T with A = sigma / rho^2 the mean of its values at the step's
    // ends (A at the start alone would take the elastic energy's increment at the start's
    // stress, an error of first order in dt that always has one sign).
    parallel_for(n, [&](unsigned int i) {
      const auto stress = [&](double rho, double e, const SymmetricTensor<2, dim> &S) {
        const double P = mats[state.material[i]].evaluate(rho, e).pressure;
        return (S - P * dealii::unit_symmetric_tensor<dim>()) / (rho * rho);
      };
      const Tensor<2, dim> T = k1.velocity_moment[i];
      const Tensor<2, dim> A0((state.S[i] - k2.pressure[i] * dealii::unit_symmetric_tensor<dim>()) /
                              (state.rho[i] * state.rho[i]));
      state.rho[i] += dt * k1.drho[i];
      state.S[i] += dt * k1.dS[i];
      const double e1 = state.e[i] - dt * dealii::scalar_product(A0, T); // predictor
      const Tensor<2, dim> A1(stress(state.rho[i], e1, state.S[i]));
      state.e[i] += -dt * dealii::scalar_product(0.5 * (A0 + A1), T) + hdt * k2.de[i];
      state.x[i] += dt * mid.v[i];
      state.v[i] = mid.v[i] + hdt * k2.dv[i];
      if (prm.period > 0)
        state.x[i][0] -= prm.period * std::floor(state.x[i][0] / prm.period);
    });
    apply_imposed(state, time + dt, false, true);
    double step_heat = 0;
    for (unsigned int i = 0; i < n; ++i)
      step_heat += state.mass[i] * k2.viscous_heating[i];
    std::vector<Tensor<1, dim>> imposed_impulse(imposed.size());
    for (unsigned int e = 0; e < imposed.size(); ++e)
      imposed_impulse[e] = hdt * k2.imposed_force[e];

    // The forces at the end, and the second kick.
    evaluate<Pass::forces>(state, time + dt, k2);
    check_rates(k2);
    parallel_for(n, [&](unsigned int i) {
      state.v[i] = mid.v[i] + hdt * k2.dv[i];
      state.e[i] += hdt * k2.de[i];
    });
    for (unsigned int i = 0; i < n; ++i)
      step_heat += state.mass[i] * k2.viscous_heating[i];
    heat += hdt * step_heat;
    for (unsigned int e = 0; e < imposed.size(); ++e)
      imposed[e].impulse += imposed_impulse[e] + hdt * k2.imposed_force[e];
    finish_step(dt);
    forces_current = true;
    return dt;
  }

  template <int dim>
  void Solver<dim>::finish_step(double dt)
  {
    apply_damping(state, dt);
    time += dt;
    apply_imposed(state, time, true);
    check_finite(state, "after the step");
  }

  template <int dim>
  void Solver<dim>::save(CheckpointOut &ar) const
  {
    const auto &s = state;
    ar << s.x << s.v << s.mass << s.rho << s.e << s.S << s.h << s.material << s.body;
    ar << time << damped_energy << heat << limiter << std::size_t(damping.size());
    for (const Damping &d : damping)
      ar << d.body << d.gamma << d.relative_to_centre_of_mass << d.reference_velocity;
    ar << search.period << search.start << search.list << x_at_build << built_cutoff << builds;
  }

  template <int dim>
  void Solver<dim>::load(CheckpointIn &ar)
  {
    const unsigned int n = state.size();
    auto              &s = state;
    ar >> s.x >> s.v >> s.mass >> s.rho >> s.e >> s.S >> s.h >> s.material >> s.body;
    if (s.size() != n || s.v.size() != n || s.S.size() != n || s.body.size() != n)
      throw InputError("checkpoint: it holds " + std::to_string(s.size()) +
                       " SPH particles, this case builds " + std::to_string(n));
    std::size_t n_damping;
    ar >> time >> damped_energy >> heat >> limiter >> n_damping;
    damping.resize(n_damping);
    for (Damping &d : damping)
      ar >> d.body >> d.gamma >> d.relative_to_centre_of_mass >> d.reference_velocity;
    ar >> search.period >> search.start >> search.list >> x_at_build >> built_cutoff >> builds;
    forces_current = false;
  }

  template <int dim>
  unsigned int Solver<dim>::advance_to(double t_end)
  {
    unsigned int steps = 0;
    forces_current     = false;
    while (time < t_end * (1 - 1e-14))
      {
        prm.integrator == Integrator::leapfrog ? leapfrog_step(t_end - time) : midpoint_step(t_end - time);
        ++steps;
      }
    forces_current = false;
    return steps;
  }

  template <int dim>
  std::vector<double> interpolate(const ParticleState<dim> &s, const NeighbourSearch<dim> &ns,
                                  const std::vector<double> &f)
  {
    const unsigned int  n = s.size();
    std::vector<double> out(n);
    parallel_for(n, [&](unsigned int i) {
      double sum = s.mass[i] / s.rho[i] * f[i] * CubicSplineKernel<dim>::value(0, s.h[i]);
      for (unsigned int q = ns.start[i]; q < ns.start[i + 1]; ++q)
        {
          const unsigned int j = ns.list[q];
          if (s.body[j] != s.body[i])
            continue;
          const double r = ns.separation(s.x[i], s.x[j]).norm();
          sum += s.mass[j] / s.rho[j] * f[j] *
                 CubicSplineKernel<dim>::value(r, 0.5 * (s.h[i] + s.h[j]));
        }
      out[i] = sum;
    });
    return out;
  }

  template class Solver<2>;
  template class Solver<3>;
  template std::vector<double> interpolate<2>(const ParticleState<2> &, const NeighbourSearch<2> &,
                                              const std::vector<double> &);
  template std::vector<double> interpolate<3>(const ParticleState<3> &, const NeighbourSearch<3> &,
                                              const std::vector<double> &);
} // namespace tribo::sph
