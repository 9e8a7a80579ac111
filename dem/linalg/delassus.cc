#include "dem/linalg/delassus.h"

#include "dem/engine/contact.h"
#include "dem/engine/body_state.h"

#include <Eigen/Dense>

#include <cmath>

namespace tribo::dem
{
  namespace
  {
    /// Contact @p i's two columns of s_b H_b (generalized impulse (Fx, Fy, torque) on body
    /// b of a unit r_n and r_t) for side @p side.
    Eigen::Matrix<double, 3, 2> signed_h(const Contact &c, int side)
    {
      const double sign = side == 0 ? -1.0 : 1.0;
      Eigen::Matrix<double, 3, 2> h;
      h << c.normal.x(), -c.normal.y(), c.normal.y(), c.normal.x(), c.arm_n[side], c.arm_t[side];
      return sign * h;
    }

    /// Impulses on the two edge nodes (4 components) of a unit r_n and r_t of half-disc
    /// contact @p c: B = [-J_A^T n, -J_A^T t; -J_B^T n, -J_B^T t].
    Eigen::Matrix<double, 4, 2> node_map(const Contact &c)
    {
      const Vec2                  t(-c.normal.y(), c.normal.x());
      Eigen::Matrix<double, 4, 2> B;
      for (int k = 0; k < 2; ++k)
        {
          B.block<2, 1>(2 * k, 0) = -c.node_map[k].transpose() * c.normal;
          B.block<2, 1>(2 * k, 1) = -c.node_map[k].transpose() * t;
        }
      return B;
    }
  } // namespace

  Eigen::SparseMatrix<double> assemble_delassus(const std::vector<Contact> &contacts,
                                                const BodyState &state, DelassusPart part,
                                                LowRankBodies *low_rank)
  {
    const std::size_t n     = contacts.size();
    const bool        full  = part == DelassusPart::full;
    const int         width = full ? 2 : 1;
    std::vector<Eigen::Triplet<double>> entries;
    auto add_block = [&](std::size_t i, std::size_t j, const Eigen::Matrix2d &block) {
      if (!full)
        entries.emplace_back(i, j, block(0, 0));
      else
        for (int a = 0; a < 2; ++a)
          for (int b = 0; b < 2; ++b)
            entries.emplace_back(2 * i + a, 2 * j + b, block(a, b));
    };

    // Contacts of each body (a counting sort by body): (contact, side).
    const std::size_t         nb = state.inverse_mass.size();
    std::vector<unsigned int> start(nb + 1, 0);
    for (const Contact &c : contacts)
      for (int s = c.on_boundary() ? 1 : 0; s < 2; ++s)
        ++start[c.body[s] + 1];
    for (std::size_t b = 0; b < nb; ++b)
      start[b + 1] += start[b];
    std::vector<std::pair<unsigned int, int>> sides(start[nb]);
    std::vector<unsigned int>                 fill(start.begin(), start.end() - 1);
    std::vector<unsigned int>                 on_boundary;
    for (unsigned int i = 0; i < n; ++i)
      {
        const Contact &c = contacts[i];
        for (int s = c.on_boundary() ? 1 : 0; s < 2; ++s)
          sides[fill[c.body[s]]++] = {i, s};
        if (c.on_boundary())
          on_boundary.push_back(i);
      }
    std::size_t reserve = 0;
    for (std::size_t b = 0; b < nb; ++b)
      reserve += std::size_t(start[b + 1] - start[b]) * (start[b + 1] - start[b]);
    entries.reserve(width * width * (reserve + on_boundary.size() * on_boundary.size()));

    // Rigid bodies: s_i s_j H_i^T M^-1 H_j for every pair of contacts on the body.
    std::vector<Eigen::Matrix<double, 3, 2>> h;
    std::vector<Eigen::VectorXd>             columns; // of U
    for (std::size_t b = 0; b < nb; ++b)
      {
        const auto           &im = state.inverse_mass[b];
        const Eigen::Vector3d m(im[0], im[1], im[2]);
        if (m.isZero())
          continue; // imposed velocity: no coupling through this body
        h.clear();
        for (unsigned int k = start[b]; k < start[b + 1]; ++k)
          h.push_back(signed_h(contacts[sides[k].first], sides[k].second));
        if (low_rank && start[b + 1] - start[b] > low_rank->contact_limit)
          {
            for (int dof = 0; dof < 3; ++dof)
              if (m[dof] > 0)
                {
                  Eigen::VectorXd u = Eigen::VectorXd::Zero(width * n);
                  for (unsigned int k = start[b]; k < start[b + 1]; ++k)
                    for (int a = 0; a < width; ++a)
                      u[width * sides[k].first + a] += h[k - start[b]](dof, a) * std::sqrt(m[dof]);
                  columns.push_back(std::move(u));
                }
            continue;
          }
        for (unsigned int p = start[b]; p < start[b + 1]; ++p)
          {
            const Eigen::Matrix<double, 2, 3> hm = (m.asDiagonal() * h[p - start[b]]).transpose();
            for (unsigned int q = start[b]; q < start[b + 1]; ++q)
              add_block(sides[p].first, sides[q].first, hm * h[q - start[b]]);
          }
      }

    // The boundary bodies: B_i^T G B_j over every pair of half-disc contacts on one body
    // (two bodies' nodes do not share a compliance block).
    if (!on_boundary.empty())
      {
        std::vector<Eigen::Matrix<double, 4, 2>> B;
        for (const unsigned int i : on_boundary)
          B.push_back(node_map(contacts[i]));
        for (std::size_t p = 0; p < on_boundary.size(); ++p)
          for (std::size_t q = 0; q < on_boundary.size(); ++q)
            {
              const Contact &ci = contacts[on_boundary[p]], &cj = contacts[on_boundary[q]];
              if (ci.boundary_body != cj.boundary_body)
                continue;
              Eigen::Matrix4d g;
              for (int a = 0; a < 2; ++a)
                for (int b = 0; b < 2; ++b)
                  g.block<2, 2>(2 * a, 2 * b) = state.node_compliance(ci.boundary_body, ci.node[a], cj.node[b]);
              add_block(on_boundary[p], on_boundary[q], B[p].transpose() * g * B[q]);
            }
      }

    if (low_rank)
      {
        low_rank->U.resize(width * n, columns.size());
        for (std::size_t k = 0; k < columns.size(); ++k)
          low_rank->U.col(k) = columns[k];
      }
    Eigen::SparseMatrix<double> W(width * n, width * n);
    W.setFromTriplets(entries.begin(), entries.end());
    return W;
  }
} // namespace tribo::dem
