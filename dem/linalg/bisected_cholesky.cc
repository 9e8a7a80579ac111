#include "dem/linalg/bisected_cholesky.h"

#include "dem/linalg/delassus.h"
#include "dem/engine/body_state.h"

#include <deal.II/base/parallel.h>

#include <Eigen/CholmodSupport>

#include <metis.h>

#include <algorithm>

namespace tribo::dem
{
  namespace
  {
    using ColumnMap = Eigen::Map<const Eigen::SparseMatrix<double, Eigen::ColMajor, int>>;

    /// CHOLMOD's simplicial LL^T factor as an Eigen column-major matrix (no copy; rows
    /// ascending in each column, the diagonal first).
    ColumnMap view(const cholmod_factor *L)
    {
      const auto n = Eigen::Index(L->n);
      return ColumnMap(n, n, static_cast<const int *>(L->p)[n], static_cast<const int *>(L->p),
                       static_cast<const int *>(L->i), static_cast<const double *>(L->x),
                       static_cast<const int *>(L->nz));
    }
  } // namespace

  namespace
  {
    /// The graph of the bodies that couple contacts in A' (bodies with a free dof and at
    /// most LowRankBodies::contact_limit contacts), in METIS's compressed form: an edge per
    /// pair of bodies in contact (repeats, e.g. a clump touching a grain twice, as edge
    /// weights), a vertex weighted by its contacts. Empty (no vertices) with a contact on a
    /// boundary body or fewer than two such bodies.
    struct GrainGraph
    {
      std::vector<idx_t> vertex; ///< per body: its vertex, or -1
      std::vector<idx_t> start{0}, adjacent, multiplicity, weight;
      idx_t              vertices = 0;

      GrainGraph(const std::vector<Contact> &contacts, const BodyState &state)
      {
        const std::size_t nb = state.inverse_mass.size();
        std::vector<int>  count(nb, 0);
        for (const Contact &c : contacts)
          {
            if (c.on_boundary())
              return;
            ++count[c.body[0]];
            ++count[c.body[1]];
          }
        const unsigned int limit = LowRankBodies{}.contact_limit;
        vertex.assign(nb, -1);
        for (std::size_t b = 0; b < nb; ++b)
          {
            const auto &im = state.inverse_mass[b];
            if (count[b] > 0 && count[b] <= int(limit) && (im[0] > 0 || im[1] > 0 || im[2] > 0))
              {
                vertex[b] = idx_t(weight.size());
                weight.push_back(count[b]);
              }
          }
        if (weight.size() < 2)
          return;
        std::vector<std::vector<idx_t>> neighbours(weight.size());
        for (const Contact &c : contacts)
          {
            const idx_t a = vertex[c.body[0]], b = vertex[c.body[1]];
            if (a >= 0 && b >= 0 && a != b)
              {
                neighbours[a].push_back(b);
                neighbours[b].push_back(a);
              }
          }
        for (auto &list : neighbours)
          {
            std::sort(list.begin(), list.end());
            for (std::size_t k = 0; k < list.size(); ++k)
              if (k > 0 && list[k] == list[k - 1])
                ++multiplicity.back();
              else
                {
                  adjacent.push_back(list[k]);
                  multiplicity.push_back(1);
                }
            start.push_back(idx_t(adjacent.size()));
          }
        vertices = idx_t(weight.size());
      }
    };
  } // namespace

  std::vector<int> grain_bisection(const std::vector<Contact> &contacts, const BodyState &state)
  {
    GrainGraph g(contacts, state);
    if (g.vertices < 2)
      return {};
    idx_t options[METIS_NOPTIONS];
    METIS_SetDefaultOptions(options);
    idx_t              constraints = 1, parts = 2, cut = 0;
    std::vector<idx_t> side(g.vertices);
    if (METIS_PartGraphRecursive(&g.vertices, &constraints, g.start.data(), g.adjacent.data(), g.weight.data(),
                                 nullptr, g.multiplicity.data(), &parts, nullptr, nullptr, options, &cut,
                                 side.data()) != METIS_OK)
      return {};
    std::vector<int> partition(contacts.size());
    for (std::size_t i = 0; i < contacts.size(); ++i)
      {
        const idx_t a = g.vertex[contacts[i].body[0]], b = g.vertex[contacts[i].body[1]];
        if (a >= 0 && b >= 0)
          partition[i] = side[a] == side[b] ? int(side[a]) : 2;
        else if (a >= 0 || b >= 0)
          partition[i] = int(side[a >= 0 ? a : b]);
        else
          partition[i] = 0; // couples nothing in A' (both bodies walls or imposed)
      }
    return partition;
  }

  std::vector<int> grain_dissection(const std::vector<Contact> &contacts, const BodyState &state)
  {
    GrainGraph g(contacts, state);
    if (g.vertices < 2 * grains_per_part)
      return {};
    int levels = 1; // 2^levels parts of at least grains_per_part grains
    while ((g.vertices >> (levels + 1)) >= grains_per_part)
      ++levels;
    idx_t options[METIS_NOPTIONS];
    METIS_SetDefaultOptions(options);
    idx_t              constraints = 1, parts = idx_t(1) << levels, cut = 0;
    std::vector<idx_t> part(g.vertices);
    if (METIS_PartGraphRecursive(&g.vertices, &constraints, g.start.data(), g.adjacent.data(), g.weight.data(),
                                 nullptr, g.multiplicity.data(), &parts, nullptr, nullptr, options, &cut,
                                 part.data()) != METIS_OK)
      return {};
    // METIS numbers the parts of a recursive bisection as its tree: parts p and q were
    // split at the level of the highest bit of p xor q.
    std::vector<int> level(contacts.size(), 0);
    for (std::size_t i = 0; i < contacts.size(); ++i)
      {
        const idx_t a = g.vertex[contacts[i].body[0]], b = g.vertex[contacts[i].body[1]];
        if (a >= 0 && b >= 0)
          for (auto x = unsigned(part[a] ^ part[b]); x > 0; x >>= 1)
            ++level[i];
      }
    return level;
  }

  Eigen::SparseMatrix<double> permuted_upper(const Eigen::SparseMatrix<double> &A, const int *order)
  {
    Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> P(A.rows());
    for (int k = 0; k < A.rows(); ++k)
      P.indices()[order[k]] = k; // Eigen's P moves row order[k] to k
    Eigen::SparseMatrix<double> upper(A.rows(), A.cols());
    upper.selfadjointView<Eigen::Upper>() = A.selfadjointView<Eigen::Lower>().twistedBy(P);
    // Eigen leaves the columns' rows unsorted; a change of storage order sorts them.
    return Eigen::SparseMatrix<double, Eigen::RowMajor>(upper);
  }

  BisectedCholesky::BisectedCholesky(const Eigen::SparseMatrix<double> &A, const std::vector<int> &part)
  {
    for (Side &s : sides)
      {
        cholmod_start(&s.common);
        s.common.print      = 0;
        s.common.supernodal = CHOLMOD_SIMPLICIAL;
        s.common.final_ll   = 1;
      }
    const Eigen::Index n = A.rows();
    if (n < min_rows || Eigen::Index(part.size()) != n)
      return;
    const auto m = Eigen::Index(std::count(part.begin(), part.end(), 2));
    if (m <= 0 || m > max_separator || double(m) > max_separator_fraction * double(n))
      return;
    std::vector<int> separator_index(n, -1);
    for (Eigen::Index j = 0; j < n; ++j)
      if (part[j] == 2)
        {
          separator_index[j] = int(separator.size());
          separator.push_back(int(j));
        }
    K_ss = Eigen::MatrixXd::Zero(m, m);
    for (long a = 0; a < m; ++a)
      for (Eigen::SparseMatrix<double>::InnerIterator e(A, separator[a]); e; ++e)
        if (separator_index[e.row()] >= 0)
          K_ss(separator_index[e.row()], a) = e.value();
    // Each side's block, ordering and analysis, the two concurrently.
    bool analysed[2] = {false, false};
    for_both_sides([&](int i) {
      Side            &s = sides[i];
      std::vector<int> local(n, -1);
      for (Eigen::Index j = 0; j < n; ++j)
        if (part[j] == i)
          {
            local[j] = int(s.rows.size());
            s.rows.push_back(int(j));
          }
      s.own = Eigen::Index(s.rows.size());
      if (s.own == 0)
        return; // analysed[i] stays false
      for (const int j : separator)
        {
          local[j] = int(s.rows.size());
          s.rows.push_back(j);
        }
      // E_i column by column in local order; a column's few entries sorted by local row.
      const auto size = Eigen::Index(s.rows.size());
      std::vector<int>    start(size + 1, 0), index;
      std::vector<double> value;
      std::vector<std::pair<int, double>> column;
      for (Eigen::Index q = 0; q < size; ++q)
        {
          column.clear();
          for (Eigen::SparseMatrix<double>::InnerIterator e(A, s.rows[q]); e; ++e)
            if (local[e.row()] >= 0)
              column.emplace_back(local[e.row()], e.value());
          std::sort(column.begin(), column.end());
          for (const auto &[r, a] : column)
            {
              index.push_back(r);
              value.push_back(a);
            }
          start[q + 1] = int(index.size());
        }
      s.E = Eigen::Map<const Eigen::SparseMatrix<double, Eigen::ColMajor, int>>(
        size, size, start[size], start.data(), index.data(), value.data());
      // CAMD with the separator as the last constraint set; E_i is then kept permuted by
      // that order and analysed as given (no postordering, which could interleave the
      // separator).
      std::vector<int> member(size, 0), order(size);
      std::fill(member.begin() + s.own, member.end(), 1);
      cholmod_sparse e = Eigen::viewAsCholmod(s.E);
      e.stype          = -1;
      if (!cholmod_camd(&e, nullptr, 0, member.data(), order.data(), &s.common))
        return; // analysed[i] stays false
      s.E = permuted_upper(s.E, order.data());
      s.diagonal.resize(size);
      s.unit.resize(size);
      for (Eigen::Index k = 0; k < size; ++k)
        {
          s.diagonal[k] = &s.E.coeffRef(k, k);
          s.unit[k]     = *s.diagonal[k];
        }
      s.common.nmethods           = 1;
      s.common.method[0].ordering = CHOLMOD_NATURAL;
      s.common.postorder          = 0;
      e       = Eigen::viewAsCholmod(s.E);
      e.stype = 1;
      s.L     = cholmod_analyze(&e, &s.common);
      if (!s.L)
        return; // analysed[i] stays false
      s.permutation = order;
      s.separator_at.resize(m);
      for (long q = 0; q < m; ++q)
        {
          if (s.permutation[s.own + q] < s.own)
            return; // the separator did not end last: analysed[i] stays false
          s.separator_at[q] = s.permutation[s.own + q] - int(s.own);
        }
      s.Ls.resize(m, m);
      s.LsLsT.resize(m, m);
      s.work.resize(size);
      analysed[i] = true;
    });
    if (!analysed[0] || !analysed[1])
      return;
    usable = true;
  }

  BisectedCholesky::~BisectedCholesky()
  {
    for (Side &s : sides)
      {
        if (s.L)
          cholmod_free_factor(&s.L, &s.common);
        for (cholmod_dense **d : {&s.X, &s.Y, &s.E_work})
          if (*d)
            cholmod_free_dense(d, &s.common);
        cholmod_finish(&s.common);
      }
  }

  template <typename F>
  void BisectedCholesky::for_both_sides(const F &f) const
  {
    dealii::parallel::apply_to_subranges(0, 2, [&](int first, int last) {
      for (int i = first; i < last; ++i)
        f(i);
    }, 1);
  }

  void BisectedCholesky::triangular(const Side &s, int system) const
  {
    cholmod_dense b = Eigen::viewAsCholmod(s.work);
    cholmod_solve2(system, s.L, &b, nullptr, &s.X, nullptr, &s.Y, &s.E_work, &s.common);
    s.work = Eigen::Map<const Eigen::VectorXd>(static_cast<const double *>(s.X->x), s.work.size());
  }

  bool BisectedCholesky::factorise(const Eigen::VectorXd &shift)
  {
    const auto m = Eigen::Index(separator.size());
    bool       ok[2];
    for_both_sides([&](int i) {
      Side &s = sides[i];
      for (Eigen::Index k = 0; k < Eigen::Index(s.rows.size()); ++k)
        *s.diagonal[k] = s.unit[k] + shift[s.rows[s.permutation[k]]];
      cholmod_sparse e = Eigen::viewAsCholmod(s.E);
      e.stype          = 1;
      cholmod_factorize(&e, s.L, &s.common);
      ok[i] = s.common.status == CHOLMOD_OK && s.L->minor == s.L->n && s.L->is_ll;
      if (!ok[i])
        return;
      // L_si: the trailing m x m block of the factor.
      const ColumnMap L = view(s.L);
      s.Ls.setZero();
      for (Eigen::Index c = 0; c < m; ++c)
        for (ColumnMap::InnerIterator a(L, s.own + c); a; ++a)
          s.Ls(a.row() - s.own, c) = a.value();
      s.LsLsT.setZero();
      s.LsLsT.selfadjointView<Eigen::Lower>().rankUpdate(s.Ls);
    });
    if (!ok[0] || !ok[1])
      return false;
    // S = L_s0 L_s0^T + L_s1 L_s1^T - K_ss in the separator's order.
    Eigen::MatrixXd S = -K_ss;
    for (Eigen::Index a = 0; a < m; ++a)
      S(a, a) -= shift[separator[a]];
    for (const Side &s : sides)
      for (Eigen::Index c = 0; c < m; ++c)
        for (Eigen::Index a = c; a < m; ++a)
          {
            S(s.separator_at[a], s.separator_at[c]) += s.LsLsT(a, c);
            if (a != c)
              S(s.separator_at[c], s.separator_at[a]) += s.LsLsT(a, c);
          }
    schur.compute(S);
    return schur.info() == Eigen::Success;
  }

  Eigen::VectorXd BisectedCholesky::solve(const Eigen::VectorXd &v) const
  {
    const auto      m = Eigen::Index(separator.size());
    Eigen::VectorXd t[2] = {Eigen::VectorXd(m), Eigen::VectorXd(m)};
    // t_i = K_si K_ii^-1 v_i = -L_si c_i.
    for_both_sides([&](int i) {
      const Side      &s = sides[i];
      Eigen::VectorXd &y = s.work;
      for (Eigen::Index q = 0; q < y.size(); ++q)
        y[q] = s.permutation[q] < s.own ? v[s.rows[s.permutation[q]]] : 0.0;
      triangular(s, CHOLMOD_L);
      const Eigen::VectorXd u = -(s.Ls.triangularView<Eigen::Lower>() * y.tail(m));
      for (Eigen::Index q = 0; q < m; ++q)
        t[i][s.separator_at[q]] = u[q];
    });
    Eigen::VectorXd x(v.size()), r(m);
    for (Eigen::Index a = 0; a < m; ++a)
      r[a] = v[separator[a]] - t[0][a] - t[1][a];
    const Eigen::VectorXd x_s = schur.solve(r);
    for (Eigen::Index a = 0; a < m; ++a)
      x[separator[a]] = x_s[a];
    // x_i = K_ii^-1 (v_i - K_is x_s) = L_ii^-T (a_i - W_i x_s): the backward solve of
    // L_i^T y = [a_i; L_si^T x_s], whose last m rows give y = x_s (W_i^T is the factor's
    // block below L_ii).
    for_both_sides([&](int i) {
      const Side      &s = sides[i];
      Eigen::VectorXd &y = s.work; // [a_i; c_i] from the forward solve
      Eigen::VectorXd  x_perm(m);
      for (Eigen::Index q = 0; q < m; ++q)
        x_perm[q] = x_s[s.separator_at[q]];
      y.tail(m) = s.Ls.transpose().triangularView<Eigen::Upper>() * x_perm;
      triangular(s, CHOLMOD_Lt);
      for (Eigen::Index q = 0; q < s.own; ++q)
        x[s.rows[s.permutation[q]]] = y[q];
    });
    return x;
  }
} // namespace tribo::dem
