#include "dem/linalg/delassus.h"

#include "dem/engine/contact.h"
#include "dem/engine/body_state.h"

#include <deal.II/base/parallel.h>

#include <Eigen/Dense>

#include <algorithm>

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
                                                LowRankBodies *low_rank, unsigned int threads)
  {
    const Eigen::Index n     = static_cast<Eigen::Index>(contacts.size());
    const bool         full  = part == DelassusPart::full;
    const int          width = full ? 2 : 1;

    // Contacts of each body (a counting sort by body): (contact, side), and each side's
    // signed arms s_b H_b.
    const std::size_t         nb = state.inverse_mass.size();
    std::vector<unsigned int> start(nb + 1, 0);
    for (const Contact &c : contacts)
      for (int s = c.on_boundary() ? 1 : 0; s < 2; ++s)
        ++start[c.body[s] + 1];
    for (std::size_t b = 0; b < nb; ++b)
      start[b + 1] += start[b];
    std::vector<std::pair<unsigned int, int>>  sides(start[nb]);
    std::vector<Eigen::Matrix<double, 3, 2>>   h(start[nb]);
    std::vector<Eigen::Matrix<double, 2, 3>>   hm(start[nb]); // (M_b^-1 s_b H_b)^T
    std::vector<unsigned int>                  fill(start.begin(), start.end() - 1);
    std::vector<unsigned int>                  on_boundary;
    for (unsigned int i = 0; i < n; ++i)
      {
        const Contact &c = contacts[i];
        for (int s = c.on_boundary() ? 1 : 0; s < 2; ++s)
          {
            h[fill[c.body[s]]]       = signed_h(c, s);
            sides[fill[c.body[s]]++] = {i, s};
          }
        if (c.on_boundary())
          on_boundary.push_back(i);
      }

    // Which bodies couple their contacts in the sparse matrix: not the imposed ones, and
    // with @p low_rank not those with more than its limit, which become columns of U.
    std::vector<char>            couples(nb, 0);
    std::vector<Eigen::VectorXd> columns; // of U
    for (std::size_t b = 0; b < nb; ++b)
      {
        const auto           &im = state.inverse_mass[b];
        const Eigen::Vector3d m(im[0], im[1], im[2]);
        if (m.isZero())
          continue; // imposed velocity: no coupling through this body
        if (low_rank && start[b + 1] - start[b] > low_rank->contact_limit)
          {
            for (int dof = 0; dof < 3; ++dof)
              if (m[dof] > 0)
                {
                  Eigen::VectorXd u = Eigen::VectorXd::Zero(width * n);
                  for (unsigned int k = start[b]; k < start[b + 1]; ++k)
                    for (int a = 0; a < width; ++a)
                      u[width * sides[k].first + a] += h[k](dof, a) * std::sqrt(m[dof]);
                  columns.push_back(std::move(u));
                }
            continue;
          }
        couples[b] = 1;
        for (unsigned int k = start[b]; k < start[b + 1]; ++k)
          hm[k] = (m.asDiagonal() * h[k]).transpose();
      }
    if (low_rank)
      {
        low_rank->U.resize(width * n, columns.size());
        for (std::size_t k = 0; k < columns.size(); ++k)
          low_rank->U.col(k) = columns[k];
      }
    // The half-disc contacts' maps to their nodes, by contact.
    std::vector<Eigen::Matrix<double, 4, 2>> B(on_boundary.empty() ? 0 : n);
    for (const unsigned int i : on_boundary)
      B[i] = node_map(contacts[i]);

    // Column by column (contact q's width columns), in chunks of contacts computed
    // concurrently: the same entries on any number of threads. Each column's terms are
    // added in the order of the bodies (ascending), then the boundary body's; the diagonal
    // block is stored even where no body couples (a compliance goes there).
    struct Chunk
    {
      std::vector<Eigen::Index> column_end; ///< per column of the chunk, its entries' end
      std::vector<int>          rows;
      std::vector<double>       values;
    };
    const Eigen::Index n_chunks = threads > 1 ? std::min<Eigen::Index>(n, 8 * Eigen::Index(threads)) : 1;
    std::vector<Chunk> chunks(std::max<Eigen::Index>(n_chunks, 1));
    /// One term of contact q's columns: contact `row`'s block W_row,q (row-major, width x width).
    struct Term
    {
      Eigen::Index row;
      double       block[4];
    };
    const auto assemble_columns = [&](Eigen::Index first, Eigen::Index last, Chunk &out) {
      std::vector<Term> terms;
      out.column_end.clear();
      out.rows.clear();
      out.values.clear();
      out.rows.reserve(std::size_t(last - first) * 12 * width * width);
      out.values.reserve(out.rows.capacity());
      for (Eigen::Index q = first; q < last; ++q)
        {
          terms.clear();
          const Contact &cq = contacts[q];
          // Its rigid sides in ascending body order.
          int side_order[2] = {0, 1};
          if (cq.body[1] < cq.body[0])
            std::swap(side_order[0], side_order[1]);
          for (const int s : side_order)
            {
              if (s == 0 && cq.on_boundary())
                continue;
              const unsigned int b = cq.body[s];
              if (!couples[b])
                continue;
              const Eigen::Matrix<double, 3, 2> hq = signed_h(cq, s);
              for (unsigned int k = start[b]; k < start[b + 1]; ++k)
                {
                  Term t{sides[k].first, {0, 0, 0, 0}};
                  for (int a = 0; a < width; ++a)
                    for (int c = 0; c < width; ++c)
                      t.block[width * a + c] = hm[k](a, 0) * hq(0, c) + hm[k](a, 1) * hq(1, c) + hm[k](a, 2) * hq(2, c);
                  terms.push_back(t);
                }
            }
          if (cq.on_boundary())
            for (const unsigned int p : on_boundary)
              {
                const Contact &cp = contacts[p];
                if (cp.boundary_body != cq.boundary_body)
                  continue;
                Eigen::Matrix4d g;
                for (int a = 0; a < 2; ++a)
                  for (int b = 0; b < 2; ++b)
                    g.block<2, 2>(2 * a, 2 * b) = state.node_compliance(cp.boundary_body, cp.node[a], cq.node[b]);
                const Eigen::Matrix2d block = B[p].transpose() * g * B[q];
                Term                  t{p, {0, 0, 0, 0}};
                for (int a = 0; a < width; ++a)
                  for (int c = 0; c < width; ++c)
                    t.block[width * a + c] = block(a, c);
                terms.push_back(t);
              }
          terms.push_back(Term{q, {0, 0, 0, 0}});
          // By row, the terms of one row in the order added (an insertion sort: a column
          // holds a few terms, a half-disc's at most its body's contacts).
          for (std::size_t k = 1; k < terms.size(); ++k)
            for (std::size_t l = k; l > 0 && terms[l - 1].row > terms[l].row; --l)
              std::swap(terms[l - 1], terms[l]);
          for (int c = 0; c < width; ++c)
            {
              for (std::size_t k = 0; k < terms.size();)
                {
                  const Eigen::Index p      = terms[k].row;
                  double             sum[2] = {terms[k].block[c], width == 2 ? terms[k].block[width + c] : 0.0};
                  for (++k; k < terms.size() && terms[k].row == p; ++k)
                    for (int a = 0; a < width; ++a)
                      sum[a] += terms[k].block[width * a + c];
                  for (int a = 0; a < width; ++a)
                    {
                      out.rows.push_back(int(width * p + a));
                      out.values.push_back(sum[a]);
                    }
                }
              out.column_end.push_back(Eigen::Index(out.rows.size()));
            }
        }
    };
    if (n_chunks > 1)
      dealii::parallel::apply_to_subranges(
        Eigen::Index(0), n_chunks,
        [&](Eigen::Index begin, Eigen::Index end) {
          for (Eigen::Index k = begin; k < end; ++k)
            assemble_columns(k * n / n_chunks, (k + 1) * n / n_chunks, chunks[k]);
        },
        1);
    else
      assemble_columns(0, n, chunks[0]);

    // The chunks' columns one after another in compressed-column storage.
    Eigen::SparseMatrix<double> W(width * n, width * n);
    std::size_t                 nnz = 0;
    for (const Chunk &c : chunks)
      nnz += c.rows.size();
    W.resizeNonZeros(Eigen::Index(nnz));
    Eigen::Index column = 0, offset = 0;
    for (const Chunk &c : chunks)
      {
        for (const Eigen::Index end : c.column_end)
          W.outerIndexPtr()[++column] = int(offset + end);
        std::copy(c.rows.begin(), c.rows.end(), W.innerIndexPtr() + offset);
        std::copy(c.values.begin(), c.values.end(), W.valuePtr() + offset);
        offset += Eigen::Index(c.rows.size());
      }
    W.outerIndexPtr()[0] = 0;
    return W;
  }
} // namespace tribo::dem
