#include "dem/nlgs.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>

namespace tribo::dem
{
  Eigen::Vector2d BodyState::boundary_local_velocity(const Contact &c) const
  {
    const Eigen::Vector3d &v1 = velocity[c.body[1]];
    const Vec2             t(-c.normal.y(), c.normal.x());
    const Vec2             dv = v1.head<2>() - half_disc_velocity(c);
    return {c.normal.dot(dv) + c.arm_n[1] * v1.z(), t.dot(dv) + c.arm_t[1] * v1.z()};
  }

  void BodyState::apply_boundary_impulse(const Contact &c, const Eigen::Vector2d &dr)
  {
    const Vec2 t(-c.normal.y(), c.normal.x());
    const Vec2 f = dr.x() * c.normal + dr.y() * t;
    const auto &im = inverse_mass[c.body[1]];
    Eigen::Vector3d &v = velocity[c.body[1]];
    v.x() += im[0] * f.x();
    v.y() += im[1] * f.y();
    v.z() += im[2] * (c.arm_n[1] * dr.x() + c.arm_t[1] * dr.y());
    // The nodes receive -(1 - xi) f and -xi f: two column pairs of the compliance.
    const Eigen::MatrixXd &G = *node_compliance;
    for (int k = 0; k < 2; ++k)
      node_velocity.noalias() -= G.middleCols<2>(2 * c.node[k]) * (c.node_weight[k] * f);
  }

  Eigen::Matrix2d BodyState::delassus_block(const Contact &c) const
  {
    const Vec2      t(-c.normal.y(), c.normal.x());
    Eigen::Matrix2d W = Eigen::Matrix2d::Zero();
    if (c.on_boundary())
      {
        // B: (r_n, r_t) -> impulses on the two nodes (4 components).
        Eigen::Matrix<double, 4, 2> B;
        for (int k = 0; k < 2; ++k)
          {
            B.block<2, 1>(2 * k, 0) = -c.node_weight[k] * c.normal;
            B.block<2, 1>(2 * k, 1) = -c.node_weight[k] * t;
          }
        Eigen::Matrix4d G;
        for (int a = 0; a < 2; ++a)
          for (int b = 0; b < 2; ++b)
            G.block<2, 2>(2 * a, 2 * b) = node_compliance->block<2, 2>(2 * c.node[a], 2 * c.node[b]);
        W = B.transpose() * G * B;
      }
    for (int s = c.on_boundary() ? 1 : 0; s < 2; ++s)
      {
        const auto &im = inverse_mass[c.body[s]];
        // Columns of H_b: generalized impulse (Fx, Fy, torque) of a unit r_n and r_t.
        const Eigen::Vector3d hn(c.normal.x(), c.normal.y(), c.arm_n[s]);
        const Eigen::Vector3d ht(t.x(), t.y(), c.arm_t[s]);
        const Eigen::Vector3d m(im[0], im[1], im[2]);
        W(0, 0) += hn.cwiseProduct(m).dot(hn);
        W(0, 1) += hn.cwiseProduct(m).dot(ht);
        W(1, 1) += ht.cwiseProduct(m).dot(ht);
      }
    W(1, 0) = W(0, 1);
    return W;
  }

  NlgsSolver::NlgsSolver(const NlgsParameters &p)
    : prm(p)
    , rng(p.seed)
  {}

  std::string NlgsSolver::random_state() const
  {
    std::ostringstream os;
    os << rng;
    return os.str();
  }

  void NlgsSolver::set_random_state(const std::string &state)
  {
    std::istringstream is(state);
    is >> rng;
  }

  namespace
  {
    /// The established code's convergence sums over one pass (docs/laws.md,
    /// "Convergence norms"), fed with each contact's impulse before and after its local
    /// solve.
    struct CheckSums
    {
      double       wrwr = 0, wrr = 0, dvdv = 0, dvdvrr = 0, dvor = 0;
      double       max_dvdv = 0, max_dvdvrr = 0;
      unsigned int active = 0; ///< contacts with a non-zero mean impulse

      void add(const Eigen::Matrix2d &W, const Eigen::Vector2d &r_old, const Eigen::Vector2d &r_new)
      {
        const Eigen::Vector2d r_bar = 0.5 * (r_old + r_new);
        if (r_bar.x() == 0 && r_bar.y() == 0)
          return;
        ++active;
        const Eigen::Vector2d dv     = W * (r_new - r_old);
        const Eigen::Vector2d wr_old = W * r_old, wr_new = W * r_new;
        const double          d2     = dv.squaredNorm();
        wrwr += 0.5 * (wr_old.squaredNorm() + wr_new.squaredNorm());
        wrr += 0.5 * (wr_old.dot(r_old) + wr_new.dot(r_new));
        dvdv += d2;
        dvdvrr += d2 * r_bar.squaredNorm();
        dvor += r_bar.dot(dv);
        max_dvdv   = std::max(max_dvdv, d2);
        max_dvdvrr = std::max(max_dvdvrr, d2 * r_bar.squaredNorm());
      }

      /// max(|MeanDVoR|, QuadDV, QuadDVR) (or the Maxm ones), relative to @p tol.
      double criterion(NlgsParameters::Norm norm, double tol) const
      {
        const double N         = active;
        const double quad_wr   = std::sqrt(wrwr / N);
        const double mean_wrr  = wrr / N;
        const double mean_dvor = wrr > 0 ? dvor / (wrr * tol) : 0;
        const bool   quad      = norm == NlgsParameters::Norm::quad;
        const double dv_norm   = quad_wr > 0 ? std::sqrt(quad ? dvdv / N : max_dvdv) / (quad_wr * tol) : 0;
        const double dvr_norm =
          mean_wrr > 0 ? std::sqrt(quad ? dvdvrr / N : max_dvdvrr) / (mean_wrr * tol) : 0;
        return std::max({std::abs(mean_dvor), dv_norm, dvr_norm});
      }
    };
  } // namespace

  NlgsReport NlgsSolver::solve(std::vector<Contact> &contacts, BodyState &state,
                               const ContactLaw &law, double theta_h)
  {
    NlgsReport report;
    const std::size_t n = contacts.size();
    if (n == 0)
      return report;
    order.resize(n);
    std::iota(order.begin(), order.end(), 0u);
    for (auto &c : contacts)
      c.u = state.local_velocity(c);

    const double tol      = prm.tolerance;
    const double omega    = prm.relaxation;
    const bool   iqs      = law.type == ContactLaw::Type::iqs;
    report.converged      = false;
    for (unsigned int sweep = 1; sweep <= prm.max_iterations; ++sweep)
      {
        if (prm.order == NlgsParameters::Order::random)
          std::shuffle(order.begin(), order.end(), rng);
        else if (prm.order == NlgsParameters::Order::alternating && sweep > 1)
          std::reverse(order.begin(), order.end());
        for (const unsigned int a : order)
          {
            Contact              &c       = contacts[a];
            const Eigen::Vector2d u_now   = state.local_velocity(c);
            const Eigen::Vector2d r_old   = c.r;
            const Eigen::Vector2d u_other = u_now - c.W * r_old;
            const ContactLaw::Terms terms{c.cohesion_impulse, c.shift, c.compliance};
            Eigen::Vector2d       r_new   = law.solve(c.W, u_other, terms);
            if (omega != 1.0)
              r_new = omega * r_new + (1 - omega) * r_old;
            const Eigen::Vector2d dr = r_new - r_old;
            if (dr.x() != 0 || dr.y() != 0)
              state.apply_impulse(c, dr);
            c.r = r_new;
            c.u = u_now + c.W * dr;
          }
        report.iterations = sweep;
        if (sweep % prm.check_interval != 0 && sweep != prm.max_iterations)
          continue;
        // The check pass: every contact's local solve against the state the sweeps left,
        // nothing applied (as the established code does: a sweep's own changes would
        // measure where the sweep went, not how far the state is from the solution).
        ++report.check_passes;
        CheckSums sums;
        double    max_violation = 0;
        for (const unsigned int a : order)
          {
            const Contact          &c       = contacts[a];
            const Eigen::Vector2d   u_now   = state.local_velocity(c);
            const ContactLaw::Terms terms{c.cohesion_impulse, c.shift, c.compliance};
            const Eigen::Vector2d   r_law   = law.solve(c.W, u_now - c.W * c.r, terms);
            if (iqs)
              max_violation = std::max(max_violation, -(u_now.x() + c.shift));
            sums.add(c.W, c.r, r_law);
          }
        report.gap_violation = theta_h * std::max(0.0, max_violation);
        const bool gaps_ok   = prm.gap_tolerance <= 0 || report.gap_violation <= prm.gap_tolerance;
        if (sums.active == 0)
          {
            report.converged = true;
            report.residual  = 0;
            break;
          }
        const double criterion = sums.criterion(prm.norm, tol);
        report.residual        = criterion * tol;
        if (criterion < 1 && gaps_ok)
          {
            report.converged = true;
            break;
          }
      }
    return report;
  }
} // namespace tribo::dem
