// The deal.II elastic body: mesh, constraints, assembly, the two direct solvers
// (CHOLMOD, UMFPACK), the theta-scheme step, the boundary compliance, output.
#include "fem/elastic_body.h"

#include "core/errors.h"

#include <deal.II/base/function.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/work_stream.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/tria.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/arpack_solver.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/sparse_direct.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/sparsity_pattern.h>
#include <deal.II/lac/vector.h>
#include <deal.II/numerics/data_out.h>
#include <deal.II/numerics/vector_tools_boundary.h>
#include <deal.II/numerics/vector_tools_point_gradient.h>
#include <deal.II/numerics/vector_tools_point_value.h>

#include <boost/archive/binary_iarchive.hpp>
#include <boost/archive/binary_oarchive.hpp>

#include <cholmod.h>

#include <Eigen/QR>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>

namespace tribo::fem
{
  using namespace dealii;

  namespace
  {
    /// A sparse direct solver for the symmetric positive definite matrix Mt.
    class DirectSolver
    {
    public:
      virtual ~DirectSolver() = default;
      virtual void factorize(const SparseMatrix<double> &A) = 0;
      /// Overwrite the n x k column-major block @p b with A^-1 b.
      virtual void solve(double *b, unsigned int k) = 0;
    };

    /// deal.II's SparseDirectUMFPACK (LU of the whole matrix).
    class UmfpackSolver : public DirectSolver
    {
    public:
      void factorize(const SparseMatrix<double> &A) override
      {
        umfpack.factorize(A);
        column.reinit(A.m());
      }
      void solve(double *b, unsigned int k) override
      {
        const std::size_t n = column.size();
        for (unsigned int c = 0; c < k; ++c)
          {
            std::copy(b + c * n, b + (c + 1) * n, column.begin());
            umfpack.solve(column);
            std::copy(column.begin(), column.end(), b + c * n);
          }
      }

    private:
      SparseDirectUMFPACK umfpack;
      Vector<double>      column;
    };

    /// SuiteSparse CHOLMOD (Cholesky L L^T, fill-reducing ordering by CHOLMOD's
    /// defaults) through its C API. deal.II stores the diagonal of each row first and
    /// the other columns increasing, so the row-wise upper part of a symmetric CSR
    /// matrix is, column by column, its lower triangle in sorted CSC (stype -1).
    /// Constrained rows hold only a positive diagonal entry, so A is SPD.
    class CholmodSolver : public DirectSolver
    {
    public:
      CholmodSolver() { cholmod_start(&common); }
      ~CholmodSolver() override
      {
        cholmod_free_factor(&factor, &common);
        cholmod_free_dense(&x, &common);
        cholmod_free_dense(&y, &common);
        cholmod_free_dense(&e, &common);
        cholmod_finish(&common);
      }
      CholmodSolver(const CholmodSolver &) = delete;
      CholmodSolver &operator=(const CholmodSolver &) = delete;

      void factorize(const SparseMatrix<double> &A) override
      {
        const std::size_t n   = A.m();
        std::size_t       nnz = 0;
        for (std::size_t r = 0; r < n; ++r)
          for (auto it = A.begin(r); it != A.end(r); ++it)
            nnz += it->column() >= r;
        cholmod_sparse *L =
          cholmod_allocate_sparse(n, n, nnz, /*sorted*/ 1, /*packed*/ 1, /*stype*/ -1, CHOLMOD_REAL, &common);
        if (L == nullptr)
          throw RunError("CHOLMOD: cannot allocate the matrix (" + std::to_string(nnz) + " entries)");
        auto *p = static_cast<int *>(L->p);
        auto *i = static_cast<int *>(L->i);
        auto *v = static_cast<double *>(L->x);
        std::size_t k = 0;
        for (std::size_t r = 0; r < n; ++r)
          {
            p[r] = static_cast<int>(k);
            for (auto it = A.begin(r); it != A.end(r); ++it)
              if (it->column() >= r)
                {
                  i[k] = static_cast<int>(it->column());
                  v[k] = it->value();
                  ++k;
                }
          }
        p[n] = static_cast<int>(k);

        cholmod_free_factor(&factor, &common);
        factor = cholmod_analyze(L, &common);
        const bool ok = factor != nullptr && cholmod_factorize(L, factor, &common) && common.status == CHOLMOD_OK;
        cholmod_free_sparse(&L, &common);
        if (!ok)
          throw RunError("CHOLMOD: factorisation of the iteration matrix failed (status " +
                         std::to_string(common.status) + ", not positive definite or out of memory)");
        rows = n;
      }

      void solve(double *b, unsigned int k) override
      {
        cholmod_dense rhs;
        rhs.nrow  = rows;
        rhs.ncol  = k;
        rhs.nzmax = rows * k;
        rhs.d     = rows;
        rhs.x     = b;
        rhs.z     = nullptr;
        rhs.xtype = CHOLMOD_REAL;
        rhs.dtype = CHOLMOD_DOUBLE;
        if (!cholmod_solve2(CHOLMOD_A, factor, &rhs, nullptr, &x, nullptr, &y, &e, &common))
          throw RunError("CHOLMOD: solve failed (status " + std::to_string(common.status) + ")");
        std::memcpy(b, x->x, sizeof(double) * rows * k);
      }

    private:
      cholmod_common  common;
      cholmod_factor *factor = nullptr;
      cholmod_dense  *x = nullptr, *y = nullptr, *e = nullptr; // reused workspace
      std::size_t     rows = 0;
    };

    std::unique_ptr<DirectSolver> make_direct_solver(const std::string &name)
    {
      if (name == "cholmod")
        return std::make_unique<CholmodSolver>();
      return std::make_unique<UmfpackSolver>();
    }

    /// A linear operator given by its action, for deal.II's ArpackSolver.
    struct ActionOperator
    {
      std::function<void(Vector<double> &, const Vector<double> &)> action;
      void vmult(Vector<double> &dst, const Vector<double> &src) const { action(dst, src); }
    };

    constexpr types::boundary_id left_id = 0, right_id = 1, bottom_id = 2, top_id = 3;

    void check(bool ok, const std::string &what)
    {
      if (!ok)
        throw InputError("ElasticBody: " + what);
    }

    void check_parameters(const ElasticBodyParameters &p)
    {
      check(p.length > 0 && p.thickness > 0, "length and thickness must be > 0");
      check(p.youngs_modulus > 0 && p.density > 0, "Young's modulus and density must be > 0");
      check(p.poisson_ratio > -1 && p.poisson_ratio < 0.5, "Poisson ratio must lie in (-1, 0.5)");
      check(p.cells_x >= 1 && p.cells_y >= 1 && p.degree >= 1, "cells and degree must be >= 1");
      check(p.rayleigh_mass >= 0 && p.rayleigh_stiffness >= 0, "Rayleigh coefficients must be >= 0");
      check(p.theta >= 0.5 && p.theta <= 1, "theta must lie in [0.5, 1]");
      check(p.time_step > 0, "time step must be > 0");
      check(p.pressure_ramp_time >= 0, "pressure ramp time must be >= 0");
      check(p.solver == "cholmod" || p.solver == "umfpack",
            "solver must be \"cholmod\" or \"umfpack\", not \"" + p.solver + "\"");
      check(!p.reduced || p.cells_y >= 2, "the reduced model needs at least 2 cells along y");
    }

    /// A column of the constraint matrix Z: the unconstrained dofs (and weights) a
    /// dof's value is made of, v_d = sum_m w_m v_m; a load on d is w_m on each m.
    using ZColumn = std::vector<std::pair<types::global_dof_index, double>>;
  } // namespace

  struct ElasticBody::Impl
  {
    ElasticBodyParameters prm;
    double                lambda, mu;
    double                assembly_seconds = 0;

    Triangulation<2>          tria;
    FESystem<2>               fe;
    DoFHandler<2>             dof;
    AffineConstraints<double> constraints;
    SparsityPattern           sparsity;
    SparseMatrix<double>      M, K, Mt; // condensed: Z^T A Z on masters, a diagonal on constrained rows
    Vector<double>            f_unit;   // Z^T f for P = 1 Pa, N/m per Pa

    // Reduced model (prm.reduced): M, K, Mt, f_unit, the state and node_z are in the
    // coordinates q of T; constraints then has no lines. basis holds T (n_dofs x r,
    // columns with the mesh's constraints distributed), boundary_dofs the dofs of u_b.
    Eigen::MatrixXd                      basis;
    std::vector<types::global_dof_index> boundary_dofs;
    std::vector<double>                  omega;

    Vector<double> u, v, v_free, v_prev; // v_prev: velocity at the start of the last step
    Vector<double> rhs, tmp;
    std::unique_ptr<DirectSolver> solver;

    std::vector<Point<2>> node_position;
    std::vector<ZColumn>  node_z; // 2n columns of Z, index 2i + component

    double t = 0, h = 0;
    bool   predicted = false;

    mutable Eigen::MatrixXd compliance;
    mutable bool            compliance_valid = false;

    double p_load = 0, p_contact = 0, p_damping = 0;
    double w_load = 0, w_contact = 0, w_damping = 0;

    explicit Impl(const ElasticBodyParameters &p)
      : prm(p)
      , lambda(p.youngs_modulus * p.poisson_ratio / ((1 + p.poisson_ratio) * (1 - 2 * p.poisson_ratio)))
      , mu(p.youngs_modulus / (2 * (1 + p.poisson_ratio)))
      , fe(FE_Q<2>(p.degree), 2)
      , h(p.time_step)
    {}

    void make_mesh();
    void make_constraints(AffineConstraints<double> &c, bool static_problem) const;
    void assemble(const AffineConstraints<double> &c, SparseMatrix<double> *mass, SparseMatrix<double> &stiffness,
                  Vector<double> &load) const;
    void find_boundary_nodes();

    /// Craig-Bampton reduction (ElasticBodyParameters::reduced): u = T q with
    /// q = (u_b, eta, zeta), T = [I 0 0; Psi Phi X]; M, K, f become T^T M T, T^T K T,
    /// T^T f. Each step below is one member function.
    void reduce();
    /// The interior problem of the reduction: the mesh's stiffness K_ii and mass M_ii
    /// with the boundary unknowns u_b held at 0 (the mesh's own constraints kept), K_ii
    /// factorised. Not movable: the matrices refer to the sparsity pattern.
    struct Interior
    {
      AffineConstraints<double>     held; ///< u_b = 0 merged with the mesh's constraints
      SparsityPattern               sparsity;
      SparseMatrix<double>          K, M; ///< K_ii (N/m^2), M_ii (kg/m) per unit depth, condensed like K, M
      std::unique_ptr<DirectSolver> solver; ///< factorisation of K_ii

      /// Number of interior unknowns: the mesh's dofs less the held and constrained ones.
      std::size_t n_unknowns() const { return K.m() - held.n_constraints(); }
      /// x := K_ii^-1 x on the interior unknowns, 0 on the held ones.
      void solve(Vector<double> &x)
      {
        held.set_zero(x);
        solver->solve(x.data(), 1);
        held.set_zero(x);
      }
      /// w := M_ii x, 0 on the held rows.
      void vmult_mass(Vector<double> &w, const Vector<double> &x) const
      {
        M.vmult(w, x);
        held.set_zero(w);
      }
    };
    /// boundary_dofs: the dof of each bottom node component (u_b, index 2i + component);
    /// throws RunError if one is not a single unconstrained dof.
    void collect_boundary_dofs();
    /// Assemble K_ii and M_ii with u_b held (the same assembly as the mesh's) and
    /// factorise K_ii.
    void assemble_interior(Interior &interior) const;
    /// Column @p column of T from the mesh vector @p x, the mesh's constraints
    /// distributed into x first.
    void store_basis_column(Vector<double> &x, unsigned int column);
    /// Columns 0 .. 2n-1 of T: the constraint modes, the static shape of a unit
    /// displacement of boundary unknown j, u_i = Psi e_j = -K_ii^-1 K_ib e_j, u_b = e_j.
    void add_constraint_modes(Interior &interior);
    /// Columns 2n .. 2n+k-1 of T and omega: the k = modes lowest fixed-interface modes,
    /// K_ii phi = omega^2 M_ii phi (u_b = 0), by ARPACK in shift-invert mode about 0,
    /// M-orthonormal (phi^T M_ii phi = 1), omega in rad/s.
    void add_fixed_interface_modes(Interior &interior);
    /// Column 2n+k of T: the load mode, the interior's static response to the unit top
    /// pressure, x = K_ii^-1 f_i, made M-orthogonal to Phi,
    /// x := x - sum_m (x^T M_ii phi_m) phi_m, and M-normalised, x^T M_ii x = 1.
    void add_load_mode(Interior &interior);
    /// The reduced matrix T^T A T (r x r) of the mesh's condensed @p A, symmetrised,
    /// (P + P^T) / 2, against round-off.
    Eigen::MatrixXd project(const SparseMatrix<double> &A) const;
    /// Make q the model's unknowns: M := T^T M T, K := T^T K T, f_unit := T^T f_unit as
    /// dense r x r (r-vector) in deal.II's sparse format, node i's components the
    /// unknowns 2i, 2i + 1 of q, and no constraints left.
    void use_reduced_coordinates();
    /// The mesh's dof vector of a model vector: T x (reduced) or x itself.
    Vector<double> full(const Vector<double> &x) const
    {
      if (basis.size() == 0)
        return x;
      Vector<double>                      y(dof.n_dofs());
      Eigen::Map<Eigen::VectorXd>         ye(y.data(), y.size());
      Eigen::Map<const Eigen::VectorXd>   xe(x.data(), x.size());
      ye.noalias() = basis * xe;
      return y;
    }
    void factorize();
    void solve(Vector<double> &b); // b := Mt^-1 b, then the constraints are distributed

    /// w := A x restricted to unconstrained rows (constrained rows zeroed).
    void vmult_free(const SparseMatrix<double> &A, const Vector<double> &x, Vector<double> &w) const
    {
      A.vmult(w, x);
      constraints.set_zero(w);
    }
    double quadratic(const SparseMatrix<double> &A, const Vector<double> &x) const
    {
      Vector<double> w(x.size());
      vmult_free(A, x, w);
      return 0.5 * (x * w);
    }
    Eigen::Vector2d node_value(const Vector<double> &x, unsigned int i) const
    {
      Eigen::Vector2d r;
      for (unsigned int c = 0; c < 2; ++c)
        {
          r[c] = 0;
          for (const auto &[m, w] : node_z[2 * i + c])
            r[c] += w * x[m];
        }
      return r;
    }
  };

  void ElasticBody::Impl::make_mesh()
  {
    const Point<2> p0(0, prm.bottom), p1(prm.length, prm.bottom + prm.thickness);
    GridGenerator::subdivided_hyper_rectangle(tria, {prm.cells_x, prm.cells_y}, p0, p1, /*colorize*/ true);
    dof.reinit(tria);
    dof.distribute_dofs(fe);
  }

  void ElasticBody::Impl::make_constraints(AffineConstraints<double> &c, bool static_problem) const
  {
    c.clear();
    DoFTools::make_periodicity_constraints(dof, left_id, right_id, /*direction x*/ 0, c);
    const FEValuesExtractors::Scalar x(0), y(1);
    // Dirichlet lines are only added for dofs not yet constrained; close() then
    // resolves periodic lines that point to a Dirichlet dof.
    if (prm.top_fixed_in_x)
      VectorTools::interpolate_boundary_values(dof, top_id, Functions::ZeroFunction<2>(2), c, fe.component_mask(x));
    if (static_problem)
      {
        VectorTools::interpolate_boundary_values(dof, bottom_id, Functions::ZeroFunction<2>(2), c,
                                                 fe.component_mask(y));
        if (!prm.top_fixed_in_x) // pin x at node 0 (or at its master) against the rigid x-translation
          for (const auto &[m, w] : node_z[0])
            if (!c.is_constrained(m))
              {
                c.add_line(m);
                break;
              }
      }
    c.close();
  }

  namespace
  {
    /// Per-thread work space of the assembly: the cell's and the top face's FEValues.
    struct AssemblyScratch
    {
      AssemblyScratch(const FiniteElement<2> &fe, unsigned int degree)
        : fv(fe, QGauss<2>(degree + 1), update_values | update_gradients | update_JxW_values)
        , ffv(fe, QGauss<1>(degree + 1), update_values | update_JxW_values)
      {}
      AssemblyScratch(const AssemblyScratch &other)
        : fv(other.fv.get_fe(), other.fv.get_quadrature(), other.fv.get_update_flags())
        , ffv(other.ffv.get_fe(), other.ffv.get_quadrature(), other.ffv.get_update_flags())
      {}
      FEValues<2>     fv;
      FEFaceValues<2> ffv;
    };

    /// One cell's mass, stiffness and unit-load contributions and its dofs.
    struct AssemblyCopy
    {
      explicit AssemblyCopy(unsigned int nd)
        : cm(nd, nd)
        , ck(nd, nd)
        , cf(nd)
        , dofs(nd)
      {}
      FullMatrix<double>                   cm, ck;
      Vector<double>                       cf;
      std::vector<types::global_dof_index> dofs;
    };
  } // namespace

  void ElasticBody::Impl::assemble(const AffineConstraints<double> &c, SparseMatrix<double> *mass,
                                   SparseMatrix<double> &stiffness, Vector<double> &load) const
  {
    const FEValuesExtractors::Vector disp(0);

    // The cells are integrated concurrently (deal.II's WorkStream over TBB); the copier
    // adds them to the global matrices one at a time, in cell order.
    const auto integrate = [&](const DoFHandler<2>::active_cell_iterator &cell, AssemblyScratch &scratch,
                               AssemblyCopy &copy) {
      FEValues<2> &fv = scratch.fv;
      fv.reinit(cell);
      const unsigned int nd = copy.dofs.size();
      copy.cm = 0;
      copy.ck = 0;
      copy.cf = 0;
      for (unsigned int q = 0; q < fv.n_quadrature_points; ++q)
        {
          const double dx = fv.JxW(q);
          for (unsigned int i = 0; i < nd; ++i)
            {
              const auto   phi_i = fv[disp].value(i, q);
              const auto   eps_i = fv[disp].symmetric_gradient(i, q);
              const double div_i = fv[disp].divergence(i, q);
              for (unsigned int j = i; j < nd; ++j)
                {
                  copy.cm(i, j) += prm.density * (phi_i * fv[disp].value(j, q)) * dx;
                  copy.ck(i, j) += (lambda * div_i * fv[disp].divergence(j, q) +
                                    2 * mu * scalar_product(eps_i, fv[disp].symmetric_gradient(j, q))) * dx;
                }
            }
        }
      for (unsigned int i = 0; i < nd; ++i)
        for (unsigned int j = 0; j < i; ++j)
          {
            copy.cm(i, j) = copy.cm(j, i);
            copy.ck(i, j) = copy.ck(j, i);
          }
      for (const auto f : cell->face_indices())
        if (cell->face(f)->at_boundary() && cell->face(f)->boundary_id() == top_id)
          {
            FEFaceValues<2> &ffv = scratch.ffv;
            ffv.reinit(cell, f);
            for (unsigned int q = 0; q < ffv.n_quadrature_points; ++q)
              for (unsigned int i = 0; i < nd; ++i) // traction (0, -1 Pa)
                copy.cf(i) -= ffv[disp].value(i, q)[1] * ffv.JxW(q);
          }
      cell->get_dof_indices(copy.dofs);
    };
    const auto add = [&](const AssemblyCopy &copy) {
      if (mass)
        c.distribute_local_to_global(copy.cm, copy.dofs, *mass);
      c.distribute_local_to_global(copy.ck, copy.cf, copy.dofs, stiffness, load);
    };
    WorkStream::run(dof.begin_active(), dof.end(), integrate, add, AssemblyScratch(fe, prm.degree),
                    AssemblyCopy(fe.n_dofs_per_cell()));
  }

  void ElasticBody::Impl::find_boundary_nodes()
  {
    const unsigned int n   = prm.cells_x;
    const double       dx  = prm.length / n;
    const unsigned int dpv = fe.n_dofs_per_vertex(); // 2: x then y (FESystem of two FE_Q)
    std::vector<std::array<types::global_dof_index, 2>> vertex_dofs(n);
    std::vector<bool>                                   found(n, false);
    node_position.assign(n, Point<2>());
    for (const auto &cell : dof.active_cell_iterators())
      for (const auto f : cell->face_indices())
        if (cell->face(f)->at_boundary() && cell->face(f)->boundary_id() == bottom_id)
          for (const auto v : cell->vertex_indices())
            {
              const Point<2> p = cell->vertex(v);
              if (std::abs(p[1] - prm.bottom) > 1e-9 * prm.thickness)
                continue;
              const auto k = static_cast<unsigned int>(std::lround(p[0] / dx));
              if (k >= n) // x = L: the periodic image of node 0
                continue;
              for (unsigned int d = 0; d < dpv; ++d)
                vertex_dofs[k][fe.system_to_component_index(v * dpv + d).first] = cell->vertex_dof_index(v, d);
              node_position[k] = Point<2>(k * dx, prm.bottom);
              found[k]         = true;
            }
    AssertThrow(std::all_of(found.begin(), found.end(), [](bool b) { return b; }),
                ExcMessage("ElasticBody: a bottom node was not found"));

    node_z.assign(2 * n, ZColumn());
    for (unsigned int k = 0; k < n; ++k)
      for (unsigned int c = 0; c < 2; ++c)
        {
          const auto d = vertex_dofs[k][c];
          if (!constraints.is_constrained(d))
            node_z[2 * k + c] = {{d, 1.0}};
          else
            for (const auto &entry : *constraints.get_constraint_entries(d))
              node_z[2 * k + c].emplace_back(entry.first, entry.second);
        }
  }

  // Craig-Bampton: T = [I 0 0; Psi Phi X] on q = (u_b, eta, zeta) (elastic_body.h).
  void ElasticBody::Impl::reduce()
  {
    collect_boundary_dofs();
    Interior interior;
    assemble_interior(interior);
    const std::size_t n_interior = interior.n_unknowns();
    if (prm.modes + 2 > n_interior)
      throw InputError("ElasticBody: " + std::to_string(prm.modes) + " modes asked of a body with " +
                       std::to_string(n_interior) + " interior unknowns: at most " +
                       std::to_string(n_interior - 2));
    basis.setZero(dof.n_dofs(), boundary_dofs.size() + prm.modes + 1);
    add_constraint_modes(interior);
    add_fixed_interface_modes(interior);
    add_load_mode(interior);
    use_reduced_coordinates();
  }

  void ElasticBody::Impl::collect_boundary_dofs()
  {
    const unsigned int nb = node_z.size();
    boundary_dofs.resize(nb);
    for (unsigned int j = 0; j < nb; ++j)
      {
        if (node_z[j].size() != 1 || node_z[j][0].second != 1.0)
          throw RunError("ElasticBody: the reduced model needs each bottom node component to be one dof; "
                         "component " + std::to_string(j % 2) + " of node " + std::to_string(j / 2) + " is not");
        boundary_dofs[j] = node_z[j][0].first;
      }
  }

  void ElasticBody::Impl::assemble_interior(Interior &interior) const
  {
    const std::size_t          N    = dof.n_dofs();
    AffineConstraints<double> &held = interior.held;
    for (const auto d : boundary_dofs)
      held.add_line(d);
    held.close();
    held.merge(constraints, AffineConstraints<double>::no_conflicts_allowed);
    held.close();
    DynamicSparsityPattern dsp(N);
    DoFTools::make_sparsity_pattern(dof, dsp, held, false);
    interior.sparsity.copy_from(dsp);
    interior.K.reinit(interior.sparsity);
    interior.M.reinit(interior.sparsity);
    Vector<double> f_held(N);
    assemble(held, &interior.M, interior.K, f_held);
    interior.solver = make_direct_solver(prm.solver);
    interior.solver->factorize(interior.K);
  }

  void ElasticBody::Impl::store_basis_column(Vector<double> &x, unsigned int column)
  {
    constraints.distribute(x);
    std::copy(x.begin(), x.end(), basis.col(column).data());
  }

  void ElasticBody::Impl::add_constraint_modes(Interior &interior)
  {
    const std::size_t N = dof.n_dofs();
    Vector<double>    x(N), w(N);
    for (unsigned int j = 0; j < boundary_dofs.size(); ++j)
      {
        w                   = 0;
        w[boundary_dofs[j]] = 1;
        K.vmult(x, w);
        x *= -1;
        interior.solve(x);
        x[boundary_dofs[j]] = 1;
        store_basis_column(x, j);
      }
  }

  void ElasticBody::Impl::add_fixed_interface_modes(Interior &interior)
  {
    const unsigned int k = prm.modes, nb = boundary_dofs.size();
    if (k == 0)
      return;
    const std::size_t    N = dof.n_dofs();
    Vector<double>       x(N), w(N);
    const ActionOperator inverse{[&](Vector<double> &dst, const Vector<double> &src) {
      dst = src;
      interior.solve(dst);
    }};
    const ActionOperator mass{[&](Vector<double> &dst, const Vector<double> &src) { interior.vmult_mass(dst, src); }};
    // Lanczos vectors: 2k + 2 (at least 20), at most the interior's dimension.
    const unsigned int arnoldi = std::min<std::size_t>(interior.n_unknowns(), std::max(2 * k + 2, 20U));
    SolverControl      control(10 * N, 1e-10);
    ArpackSolver       arpack(control, ArpackSolver::AdditionalData(arnoldi, ArpackSolver::largest_magnitude, true));
    std::vector<std::complex<double>> lambda(k);
    std::vector<Vector<double>>       phi(k, Vector<double>(N));
    arpack.solve(interior.K, mass, inverse, lambda, phi, k);
    std::vector<unsigned int> order(k);
    for (unsigned int i = 0; i < k; ++i)
      order[i] = i;
    std::sort(order.begin(), order.end(), [&](unsigned a, unsigned b) { return lambda[a].real() < lambda[b].real(); });
    omega.clear();
    for (unsigned int i = 0; i < k; ++i)
      {
        x = phi[order[i]];
        interior.held.set_zero(x);
        mass.vmult(w, x);
        x /= std::sqrt(x * w); // M-orthonormal
        omega.push_back(std::sqrt(lambda[order[i]].real()));
        store_basis_column(x, nb + i);
      }
  }

  void ElasticBody::Impl::add_load_mode(Interior &interior)
  {
    const unsigned int k = prm.modes, nb = boundary_dofs.size();
    const std::size_t  N = dof.n_dofs();
    Vector<double>     x(f_unit), w(N);
    interior.solve(x);
    Eigen::Map<Eigen::VectorXd> xe(x.data(), N);
    for (unsigned int i = 0; i < k; ++i)
      {
        Vector<double> p(N);
        std::copy(basis.col(nb + i).data(), basis.col(nb + i).data() + N, p.begin());
        interior.held.set_zero(p);
        interior.vmult_mass(w, p);
        x.add(-(x * w), p);
      }
    interior.vmult_mass(w, x);
    const double norm = std::sqrt(x * w);
    if (norm > 0)
      xe /= norm;
    store_basis_column(x, nb + k);
  }

  Eigen::MatrixXd ElasticBody::Impl::project(const SparseMatrix<double> &A) const
  {
    const std::size_t N = dof.n_dofs();
    const Eigen::Index r = basis.cols();
    Vector<double>    x(N), w(N);
    Eigen::MatrixXd   AT(N, r);
    for (Eigen::Index c = 0; c < r; ++c)
      {
        std::copy(basis.col(c).data(), basis.col(c).data() + N, x.begin());
        vmult_free(A, x, w);
        std::copy(w.begin(), w.end(), AT.col(c).data());
      }
    Eigen::MatrixXd P = basis.transpose() * AT;
    return Eigen::MatrixXd(0.5 * (P + P.transpose()));
  }

  void ElasticBody::Impl::use_reduced_coordinates()
  {
    const std::size_t  N = dof.n_dofs();
    const unsigned int r = basis.cols(), nb = boundary_dofs.size();
    const Eigen::MatrixXd M_r = project(M), K_r = project(K);
    Eigen::Map<const Eigen::VectorXd> f(f_unit.data(), N);
    const Eigen::VectorXd             f_r = basis.transpose() * f;

    // Dense r x r matrices in deal.II's sparse format (CHOLMOD factorises them as
    // before), boundary unknowns first, no constraints.
    DynamicSparsityPattern full_pattern(r, r);
    for (unsigned int i = 0; i < r; ++i)
      for (unsigned int j = 0; j < r; ++j)
        full_pattern.add(i, j);
    sparsity.copy_from(full_pattern);
    M.reinit(sparsity);
    K.reinit(sparsity);
    Mt.reinit(sparsity);
    for (unsigned int i = 0; i < r; ++i)
      for (unsigned int j = 0; j < r; ++j)
        {
          M.set(i, j, M_r(i, j));
          K.set(i, j, K_r(i, j));
        }
    f_unit.reinit(r);
    std::copy(f_r.data(), f_r.data() + r, f_unit.begin());
    for (unsigned int j = 0; j < nb; ++j)
      node_z[j] = {{j, 1.0}};
    constraints.clear();
    constraints.close();
  }

  void ElasticBody::Impl::factorize()
  {
    const double th = prm.theta;
    Mt.copy_from(M);
    Mt *= 1 + th * h * prm.rayleigh_mass;
    Mt.add(th * h * prm.rayleigh_stiffness + th * th * h * h, K);
    if (!solver)
      solver = make_direct_solver(prm.solver);
    solver->factorize(Mt);
    compliance_valid = false;
  }

  void ElasticBody::Impl::solve(Vector<double> &b)
  {
    constraints.set_zero(b);
    solver->solve(b.data(), 1);
    constraints.distribute(b);
  }

  ElasticBody::ElasticBody(const ElasticBodyParameters &parameters)
  {
    check_parameters(parameters);
    impl = std::make_unique<Impl>(parameters);
    Impl &m = *impl;
    m.make_mesh();
    m.make_constraints(m.constraints, false);
    m.find_boundary_nodes();

    DynamicSparsityPattern dsp(m.dof.n_dofs());
    DoFTools::make_sparsity_pattern(m.dof, dsp, m.constraints, /*keep_constrained_dofs*/ false);
    m.sparsity.copy_from(dsp);
    m.M.reinit(m.sparsity);
    m.K.reinit(m.sparsity);
    m.Mt.reinit(m.sparsity);
    m.f_unit.reinit(m.dof.n_dofs());
    const auto start = std::chrono::steady_clock::now();
    m.assemble(m.constraints, &m.M, m.K, m.f_unit);
    m.assembly_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (m.prm.reduced)
      m.reduce();

    for (auto *x : {&m.u, &m.v, &m.v_free, &m.v_prev, &m.rhs, &m.tmp})
      x->reinit(m.M.m());
    m.factorize();
  }

  ElasticBody::~ElasticBody()                                  = default;
  ElasticBody::ElasticBody(ElasticBody &&) noexcept            = default;
  ElasticBody &ElasticBody::operator=(ElasticBody &&) noexcept = default;

  const ElasticBodyParameters &ElasticBody::parameters() const { return impl->prm; }
  unsigned int ElasticBody::n_dofs() const { return impl->dof.n_dofs(); }
  unsigned int ElasticBody::n_model_dofs() const { return impl->M.m(); }
  const std::vector<double> &ElasticBody::mode_frequencies() const { return impl->omega; }
  double ElasticBody::lame_lambda() const { return impl->lambda; }
  double ElasticBody::assembly_seconds() const { return impl->assembly_seconds; }
  double ElasticBody::shear_modulus() const { return impl->mu; }
  double ElasticBody::time() const { return impl->t; }
  double ElasticBody::time_step() const { return impl->h; }

  void ElasticBody::set_damping(double a, double b)
  {
    if (!(a >= 0) || !(b >= 0))
      throw InputError("ElasticBody: Rayleigh coefficients must be >= 0, not a = " + to_text(a) +
                       ", b = " + to_text(b));
    if (a == impl->prm.rayleigh_mass && b == impl->prm.rayleigh_stiffness)
      return;
    impl->prm.rayleigh_mass      = a;
    impl->prm.rayleigh_stiffness = b;
    impl->factorize();
    impl->predicted = false;
  }

  double ElasticBody::pressure(double t) const
  {
    const auto &p = impl->prm;
    if (t < 0)
      return 0;
    return p.pressure_ramp_time > 0 ? p.top_pressure * std::min(1.0, t / p.pressure_ramp_time) : p.top_pressure;
  }

  void ElasticBody::set_time_step(double h)
  {
    if (!(h > 0))
      throw InputError("ElasticBody: time step must be > 0, not " + to_text(h));
    if (h == impl->h)
      return;
    impl->h = h;
    impl->prm.time_step = h;
    impl->factorize();
    impl->predicted = false;
  }

  // Mt (v_free - v) = h (f - a M v - K (u + (theta h + b) v)), the increment form of
  // Mt v_free = (M - h(1-theta) C - h^2 theta(1-theta) K) v - h K u + h f.
  void ElasticBody::predict()
  {
    Impl      &m  = *impl;
    const auto &p = m.prm;
    m.tmp = m.u;
    m.tmp.add(p.theta * m.h + p.rayleigh_stiffness, m.v);
    m.K.vmult(m.rhs, m.tmp);
    if (p.rayleigh_mass != 0)
      {
        m.M.vmult(m.tmp, m.v);
        m.rhs.add(p.rayleigh_mass, m.tmp);
      }
    m.rhs.sadd(-m.h, m.h * pressure(m.t + p.theta * m.h), m.f_unit);
    m.solve(m.rhs);
    m.v_free = m.v;
    m.v_free += m.rhs;
    m.predicted = true;
  }

  // v_end = v_free + Mt^-1 Z^T R,  u_end = u + h (theta v_end + (1 - theta) v).
  void ElasticBody::finalize(const std::vector<Eigen::Vector2d> &R)
  {
    Impl       &m = *impl;
    const auto &p = m.prm;
    const unsigned int n = n_boundary_nodes();
    if (!m.predicted)
      throw RunError("ElasticBody::finalize: predict() was not called for this step");
    if (!R.empty() && R.size() != n)
      throw RunError("ElasticBody::finalize: " + std::to_string(R.size()) + " impulses for " +
                     std::to_string(n) + " boundary nodes");
    const bool has_impulses = std::any_of(R.begin(), R.end(), [](const Eigen::Vector2d &r) { return r != Eigen::Vector2d::Zero(); });

    double contact_work = 0; // sum_i R_i . (v_i + v_end,i) / 2
    for (unsigned int i = 0; i < R.size(); ++i)
      contact_work += 0.5 * R[i].dot(m.node_value(m.v, i));

    std::swap(m.v_prev, m.v); // v_prev: start of the step
    m.v = m.v_free;
    if (has_impulses)
      {
        m.rhs = 0;
        for (unsigned int i = 0; i < n; ++i)
          for (unsigned int c = 0; c < 2; ++c)
            for (const auto &[d, w] : m.node_z[2 * i + c])
              m.rhs[d] += w * R[i][c];
        m.solve(m.rhs);
        m.v += m.rhs;
      }
    for (unsigned int i = 0; i < R.size(); ++i)
      contact_work += 0.5 * R[i].dot(m.node_value(m.v, i));
    m.u.add(m.h * p.theta, m.v, m.h * (1 - p.theta), m.v_prev);

    // vbar = (v + v_end) / 2 in rhs; f(t + theta h).vbar
    m.rhs = m.v;
    m.rhs += m.v_prev;
    m.rhs *= 0.5;
    m.p_load    = pressure(m.t + p.theta * m.h) * (m.f_unit * m.rhs);
    m.p_contact = contact_work / m.h;
    m.p_damping = 0;
    if (p.rayleigh_mass != 0 || p.rayleigh_stiffness != 0)
      {
        Vector<double> v_theta(m.v), cv(m.v.size());
        v_theta.sadd(p.theta, 1 - p.theta, m.v_prev);
        m.M.vmult(m.tmp, v_theta);
        m.K.vmult(cv, v_theta);
        cv.sadd(p.rayleigh_stiffness, p.rayleigh_mass, m.tmp);
        m.constraints.set_zero(cv);
        m.p_damping = m.rhs * cv;
      }
    m.w_load += m.h * m.p_load;
    m.w_contact += contact_work;
    m.w_damping += m.h * m.p_damping;
    m.t += m.h;
    m.predicted = false;
  }

  unsigned int ElasticBody::n_boundary_nodes() const { return impl->node_position.size(); }

  Eigen::Vector2d ElasticBody::boundary_position(unsigned int i) const
  {
    const auto &x = impl->node_position.at(i);
    return {x[0], x[1]};
  }
  Eigen::Vector2d ElasticBody::boundary_displacement(unsigned int i) const { return impl->node_value(impl->u, i); }
  Eigen::Vector2d ElasticBody::boundary_free_velocity(unsigned int i) const { return impl->node_value(impl->v_free, i); }
  Eigen::Vector2d ElasticBody::boundary_velocity(unsigned int i) const { return impl->node_value(impl->v, i); }

  // G = Z_b^T Mt^-1 Z_b, solved in blocks of columns.
  const Eigen::MatrixXd &ElasticBody::boundary_compliance() const
  {
    Impl &m = *impl;
    if (m.compliance_valid)
      return m.compliance;
    const unsigned int  nc = m.node_z.size(), block = 32;
    const std::size_t   N  = m.M.m();
    std::vector<double> B(N * block);
    m.compliance.resize(nc, nc);
    for (unsigned int start = 0; start < nc; start += block)
      {
        const unsigned int k = std::min(block, nc - start);
        std::fill(B.begin(), B.end(), 0.0);
        for (unsigned int c = 0; c < k; ++c)
          for (const auto &[d, w] : m.node_z[start + c])
            B[c * N + d] += w;
        m.solver->solve(B.data(), k);
        for (unsigned int c = 0; c < k; ++c)
          for (unsigned int r = 0; r < nc; ++r)
            {
              double g = 0;
              for (const auto &[d, w] : m.node_z[r])
                g += w * B[c * N + d];
              m.compliance(r, start + c) = g;
            }
      }
    m.compliance_valid = true;
    return m.compliance;
  }

  double ElasticBody::kinetic_energy() const { return impl->quadratic(impl->M, impl->v); }
  double ElasticBody::elastic_energy() const { return impl->quadratic(impl->K, impl->u); }
  double ElasticBody::load_power() const { return impl->p_load; }
  double ElasticBody::contact_power() const { return impl->p_contact; }
  double ElasticBody::damping_power() const { return impl->p_damping; }
  double ElasticBody::load_work() const { return impl->w_load; }
  double ElasticBody::contact_work() const { return impl->w_contact; }
  double ElasticBody::damping_dissipation() const { return impl->w_damping; }

  double ElasticBody::mean_bottom_displacement_y() const
  {
    double s = 0;
    for (unsigned int i = 0; i < n_boundary_nodes(); ++i)
      s += boundary_displacement(i)[1];
    return s / n_boundary_nodes();
  }

  Eigen::Vector2d ElasticBody::displacement_at(const Eigen::Vector2d &x) const
  {
    Vector<double> value(2);
    VectorTools::point_value(impl->dof, impl->full(impl->u), Point<2>(x[0], x[1]), value);
    return {value[0], value[1]};
  }

  Eigen::Vector2d ElasticBody::velocity_at(const Eigen::Vector2d &x) const
  {
    Vector<double> value(2);
    VectorTools::point_value(impl->dof, impl->full(impl->v), Point<2>(x[0], x[1]), value);
    return {value[0], value[1]};
  }

  Eigen::Matrix2d ElasticBody::strain_at(const Eigen::Vector2d &x) const
  {
    std::vector<Tensor<1, 2>> grad(2);
    VectorTools::point_gradient(impl->dof, impl->full(impl->u), Point<2>(x[0], x[1]), grad);
    Eigen::Matrix2d eps;
    for (unsigned int a = 0; a < 2; ++a)
      for (unsigned int b = 0; b < 2; ++b)
        eps(a, b) = 0.5 * (grad[a][b] + grad[b][a]);
    return eps;
  }

  void ElasticBody::static_solve()
  {
    Impl                     &m = *impl;
    AffineConstraints<double> c;
    m.make_constraints(c, true);
    DynamicSparsityPattern dsp(m.dof.n_dofs());
    DoFTools::make_sparsity_pattern(m.dof, dsp, c, false);
    SparsityPattern sp;
    sp.copy_from(dsp);
    SparseMatrix<double> Ks(sp);
    Vector<double>       f(m.dof.n_dofs());
    m.assemble(c, nullptr, Ks, f);
    f *= m.prm.top_pressure;
    SparseDirectUMFPACK direct;
    direct.initialize(Ks);
    direct.solve(f);
    c.distribute(f);
    if (m.basis.size() == 0)
      m.u = f;
    else
      {
        // q_b is u at the boundary dofs; the rest is the least-squares fit of the
        // remainder by the other columns of T, exact when it lies in their span.
        const unsigned int nb = m.boundary_dofs.size(), r = m.basis.cols();
        Eigen::Map<const Eigen::VectorXd> fe(f.data(), f.size());
        Eigen::VectorXd                   q(r);
        for (unsigned int j = 0; j < nb; ++j)
          q[j] = f[m.boundary_dofs[j]];
        const Eigen::VectorXd rest = fe - m.basis.leftCols(nb) * q.head(nb);
        q.tail(r - nb)             = m.basis.rightCols(r - nb).colPivHouseholderQr().solve(rest);
        std::copy(q.data(), q.data() + r, m.u.begin());
      }
    m.v         = 0;
    m.predicted = false;
  }

  void ElasticBody::save(CheckpointOut &ar) const
  {
    const Impl &m = *impl;
    ar << m.prm.rayleigh_mass << m.prm.rayleigh_stiffness << m.t << m.u << m.v << m.v_prev;
    ar << m.p_load << m.p_contact << m.p_damping << m.w_load << m.w_contact << m.w_damping;
  }

  void ElasticBody::load(CheckpointIn &ar)
  {
    Impl  &m = *impl;
    double a, b;
    ar >> a >> b;
    set_damping(a, b);
    const auto n = m.u.size();
    ar >> m.t >> m.u >> m.v >> m.v_prev;
    if (m.u.size() != n)
      throw InputError("checkpoint: the deformable body has " + std::to_string(m.u.size() / 2) +
                       " nodes in it, this case builds " + std::to_string(n / 2));
    ar >> m.p_load >> m.p_contact >> m.p_damping >> m.w_load >> m.w_contact >> m.w_damping;
    m.predicted = false;
  }

  void ElasticBody::write_vtu(const std::string &filename) const
  {
    const Impl          &m = *impl;
    const Vector<double> u = m.full(m.u), v = m.full(m.v);
    const double nu = m.prm.poisson_ratio;
    const unsigned int nc = m.tria.n_active_cells();
    Vector<double> sxx(nc), syy(nc), sxy(nc), szz(nc), mises(nc);
    const QGauss<2> quad(m.prm.degree + 1);
    FEValues<2>     fv(m.fe, quad, update_gradients | update_JxW_values);
    std::vector<SymmetricTensor<2, 2>> eps(quad.size());
    const FEValuesExtractors::Vector   disp(0);
    for (const auto &cell : m.dof.active_cell_iterators())
      {
        fv.reinit(cell);
        fv[disp].get_function_symmetric_gradients(u, eps);
        double area = 0, exx = 0, eyy = 0, exy = 0;
        for (unsigned int q = 0; q < quad.size(); ++q)
          {
            area += fv.JxW(q);
            exx += eps[q][0][0] * fv.JxW(q);
            eyy += eps[q][1][1] * fv.JxW(q);
            exy += eps[q][0][1] * fv.JxW(q);
          }
        const auto   k  = cell->active_cell_index();
        const double tr = (exx + eyy) / area;
        sxx[k]          = m.lambda * tr + 2 * m.mu * exx / area;
        syy[k]          = m.lambda * tr + 2 * m.mu * eyy / area;
        sxy[k]          = 2 * m.mu * exy / area;
        szz[k]          = nu * (sxx[k] + syy[k]);
        mises[k]        = std::sqrt(0.5 * (std::pow(sxx[k] - syy[k], 2) + std::pow(syy[k] - szz[k], 2) +
                                    std::pow(szz[k] - sxx[k], 2)) + 3 * sxy[k] * sxy[k]);
      }

    DataOut<2> out;
    out.attach_dof_handler(m.dof);
    const std::vector<DataComponentInterpretation::DataComponentInterpretation> vector_field(
      2, DataComponentInterpretation::component_is_part_of_vector);
    out.add_data_vector(u, std::vector<std::string>(2, "displacement"), DataOut<2>::type_dof_data, vector_field);
    out.add_data_vector(v, std::vector<std::string>(2, "velocity"), DataOut<2>::type_dof_data, vector_field);
    out.add_data_vector(sxx, "sigma_xx", DataOut<2>::type_cell_data);
    out.add_data_vector(syy, "sigma_yy", DataOut<2>::type_cell_data);
    out.add_data_vector(sxy, "sigma_xy", DataOut<2>::type_cell_data);
    out.add_data_vector(szz, "sigma_zz", DataOut<2>::type_cell_data);
    out.add_data_vector(mises, "von_mises", DataOut<2>::type_cell_data);
    out.build_patches(m.prm.degree);

    const std::string tmp_name = filename + ".tmp";
    {
      std::ofstream file(tmp_name);
      if (!file)
        throw RunError("ElasticBody::write_vtu: cannot open " + tmp_name);
      out.write_vtu(file);
      if (!file)
        throw RunError("ElasticBody::write_vtu: cannot write " + tmp_name);
    }
    if (std::rename(tmp_name.c_str(), filename.c_str()) != 0)
      throw RunError("ElasticBody::write_vtu: cannot rename " + tmp_name + " to " + filename);
  }
} // namespace tribo::fem
