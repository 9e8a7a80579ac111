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

    const double tol   = prm.tolerance;
    const double omega = prm.relaxation;
    report.converged   = false;
    for (unsigned int sweep = 1; sweep <= prm.max_iterations; ++sweep)
      {
        if (prm.order == NlgsParameters::Order::random)
          std::shuffle(order.begin(), order.end(), rng);
        else if (prm.order == NlgsParameters::Order::alternating && sweep > 1)
          std::reverse(order.begin(), order.end());
        const bool check = (sweep % prm.check_interval == 0) || sweep == prm.max_iterations;
        double     sum_wrwr = 0, sum_wrr = 0, sum_dvdv = 0, sum_dvdvrr = 0, sum_dvor = 0;
        double     max_dvdv = 0, max_dvdvrr = 0, max_violation = 0;
        const bool iqs = law.type == ContactLaw::Type::iqs;
        unsigned int active = 0;
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
            const Eigen::Vector2d u_after = u_now + c.W * dr;
            if (check && iqs)
              max_violation = std::max(max_violation, -(u_after.x() + c.shift));
            if (check && (r_new.x() != 0 || r_new.y() != 0))
              {
                ++active;
                const Eigen::Vector2d dv     = c.W * dr; // = u_after - u_now
                const Eigen::Vector2d r_bar  = 0.5 * (r_old + r_new);
                const Eigen::Vector2d wr_old = c.W * r_old, wr_new = c.W * r_new;
                const double wrr  = 0.5 * (wr_old.dot(r_old) + wr_new.dot(r_new));
                const double dvdv = dv.squaredNorm();
                sum_wrwr += 0.5 * (wr_old.squaredNorm() + wr_new.squaredNorm());
                sum_wrr += wrr;
                sum_dvdv += dvdv;
                sum_dvdvrr += dvdv * r_bar.squaredNorm();
                sum_dvor += r_bar.dot(dv);
                max_dvdv   = std::max(max_dvdv, dvdv);
                max_dvdvrr = std::max(max_dvdvrr, dvdv * r_bar.squaredNorm());
              }
            c.r = r_new;
            c.u = u_after;
          }
        report.iterations = sweep;
        if (!check)
          continue;
        report.gap_violation = theta_h * std::max(0.0, max_violation);
        const bool gaps_ok   = prm.gap_tolerance <= 0 || report.gap_violation <= prm.gap_tolerance;
        if (active == 0)
          {
            report.converged = true;
            report.residual  = 0;
            break;
          }
        const double N         = active;
        const double quad_wr   = std::sqrt(sum_wrwr / N);
        const double mean_wrr  = sum_wrr / N;
        const double mean_dvor = sum_wrr > 0 ? sum_dvor / (sum_wrr * tol) : 0;
        double dv_norm, dvr_norm;
        if (prm.norm == NlgsParameters::Norm::quad)
          {
            dv_norm  = quad_wr > 0 ? std::sqrt(sum_dvdv / N) / (quad_wr * tol) : 0;
            dvr_norm = mean_wrr > 0 ? std::sqrt(sum_dvdvrr / N) / (mean_wrr * tol) : 0;
          }
        else
          {
            dv_norm  = quad_wr > 0 ? std::sqrt(max_dvdv) / (quad_wr * tol) : 0;
            dvr_norm = mean_wrr > 0 ? std::sqrt(max_dvdvrr) / (mean_wrr * tol) : 0;
          }
        const double criterion = std::max({std::abs(mean_dvor), dv_norm, dvr_norm});
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
