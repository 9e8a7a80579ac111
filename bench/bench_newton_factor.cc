// The interior point's Newton matrix of one step, K = A' + diag(barrier)
// (dem/solvers/interior_point.h: the scaled Delassus operator, the walls kept out as low-rank
// columns), factorised by the two candidates for the interior point across MPI ranks:
// - CHOLMOD on one core, as the method factorises it (ShiftedFactorisation, K whole, ordered
//   by a dissection of the grains), and in two halves on two threads (its BisectedCholesky);
// - MUMPS through PETSc (Cholesky, PCCHOLESKY with MATSOLVERMUMPS), K's rows split into N
//   consecutive ranges (the contacts' detection order: bands of the cell) over the N ranks.
// For each: the first factorisation (ordering and symbolic analysis included) and the later
// ones of the same step (numeric only, about 15 per step in the method), the best of
// REPEATS, and one solve. docs/scaling.md records it.
// Every rank runs the same serial trajectory of CASE for STEPS steps, then takes the last
// step's contacts. The barrier: 1e-3 on the contacts loaded in that step and 1e3 on the
// open ones (s / y near the end of a solve); a factorisation's cost depends on K's pattern.
// CHOLMOD is measured on one rank only.
// Usage: mpirun -np N bench_newton_factor [CASE.prm] [STEPS] [REPEATS] [--set "Section/Entry=value"]...
#include "bench/bench_case.h"
#include "dem/solvers/crossover.h"
#include "dem/linalg/bisected_cholesky.h"

#include <deal.II/base/mpi.h>
#include <deal.II/base/multithread_info.h>

#include <petscksp.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

using namespace tribo;
using Clock = std::chrono::steady_clock;

namespace
{
  double seconds_since(const Clock::time_point &start)
  {
    return std::chrono::duration<double>(Clock::now() - start).count();
  }

  void check(PetscErrorCode code, const char *what)
  {
    if (code != 0)
      {
        std::fprintf(stderr, "bench_newton_factor: PETSc failed in %s (error %d)\n", what, int(code));
        MPI_Abort(MPI_COMM_WORLD, 1);
      }
  }

  /// The slowest rank's time.
  double slowest(double t, MPI_Comm comm) { return dealii::Utilities::MPI::max(t, comm); }

  /// K's rows [first, last) of the whole @p K (every rank holds it), as a PETSc MPIAIJ matrix.
  Mat petsc_rows(const Eigen::SparseMatrix<double> &K, PetscInt first, PetscInt last, MPI_Comm comm)
  {
    // K is symmetric, so its column j is its row j.
    const PetscInt        n = K.rows();
    std::vector<PetscInt> diagonal(last - first, 0), off(last - first, 0);
    for (PetscInt j = first; j < last; ++j)
      for (Eigen::SparseMatrix<double>::InnerIterator it(K, j); it; ++it)
        ++(it.row() >= first && it.row() < last ? diagonal : off)[j - first];
    Mat A;
    check(MatCreateAIJ(comm, last - first, last - first, n, n, 0, diagonal.data(), 0, off.data(), &A), "MatCreateAIJ");
    std::vector<PetscInt>    columns;
    std::vector<PetscScalar> values;
    for (PetscInt j = first; j < last; ++j)
      {
        columns.clear();
        values.clear();
        for (Eigen::SparseMatrix<double>::InnerIterator it(K, j); it; ++it)
          {
            columns.push_back(PetscInt(it.row()));
            values.push_back(it.value());
          }
        check(MatSetValues(A, 1, &j, PetscInt(columns.size()), columns.data(), values.data(), INSERT_VALUES),
              "MatSetValues");
      }
    check(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
    check(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
    check(MatSetOption(A, MAT_SYMMETRIC, PETSC_TRUE), "MatSetOption");
    check(MatSetOption(A, MAT_SPD, PETSC_TRUE), "MatSetOption");
    return A;
  }
} // namespace

int main(int argc, char **argv)
{
  // deal.II's MPI_InitFinalize initialises PETSc too.
  dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  const MPI_Comm     world = MPI_COMM_WORLD;
  const unsigned int rank  = dealii::Utilities::MPI::this_mpi_process(world);
  const unsigned int ranks = dealii::Utilities::MPI::n_mpi_processes(world);

  bench::BenchCase   bench_case(argc, argv, "cases/shear/reference_bench_sample.prm");
  const std::string  case_file = bench_case.case_file("cases/shear/reference_bench_sample.prm");
  const unsigned     steps     = bench_case.count(1, 30);
  const unsigned     repeats   = bench_case.count(2, 5);
  dem::ParticleSystem &system  = bench_case.system;
  dem::MoreauJean     &mj      = *bench_case.integrator;
  app::NscdWorld       nscd{system};
  for (unsigned s = 0; s < steps; ++s)
    {
      nscd.step = s;
      bench_case.scene->before_step(nscd);
      mj.step(system, bench_case.h);
    }

  // The last step's problem, its impulses' effect in the state (the method's input).
  const std::vector<dem::Contact>         &contacts = mj.contacts();
  const dem::BodyState                     state    = dem::BodyState::of(system);
  const dem::FrictionlessProblem           lcp(contacts, state, true);
  const dem::FrictionlessProblem::Scaled   scaled = lcp.scaled();
  const Eigen::Index                       n      = scaled.A.rows();
  Eigen::VectorXd                          barrier(n);
  for (Eigen::Index i = 0; i < n; ++i)
    barrier[i] = contacts[i].r.x() > 0 ? 1e-3 : 1e3;
  Eigen::SparseMatrix<double> K = scaled.A;
  for (Eigen::Index i = 0; i < n; ++i)
    K.coeffRef(i, i) += barrier[i];
  const Eigen::VectorXd rhs = Eigen::VectorXd::Ones(n);
  if (rank == 0)
    std::printf("case %s after %u steps: %zu discs, %lld contacts (rows of K), %lld entries, %u ranks\n",
                case_file.c_str(), steps, system.discs.size(), static_cast<long long>(n),
                static_cast<long long>(K.nonZeros()), ranks);

  // CHOLMOD, as the interior point factorises K: whole (one core) and in halves (two threads);
  // run on one rank (on more, the others' waiting would share the cores).
  if (ranks == 1)
    for (const bool halves : {false, true})
      {
        // MPI_InitFinalize(.., 1) held TBB to one thread: the halves get two.
        dealii::MultithreadInfo::set_thread_limit(halves ? 2 : 1);
        const auto                 t0 = Clock::now();
        dem::ShiftedFactorisation  factor(scaled, halves ? dem::grain_bisection(contacts, state) : std::vector<int>{},
                                          halves ? std::vector<int>{} : dem::grain_dissection(contacts, state));
        const bool                 ok    = factor.factorise(barrier);
        const double               first = seconds_since(t0);
        double                     later = 1e300;
        for (unsigned k = 0; k < repeats; ++k)
          {
            const auto t1 = Clock::now();
            factor.factorise(barrier);
            later = std::min(later, seconds_since(t1));
          }
        const auto            t2    = Clock::now();
        const Eigen::VectorXd x     = factor.solve(rhs, false);
        const double          solve = seconds_since(t2);
        std::printf("CHOLMOD %s: first factorisation %.2f ms (%s), later %.2f ms, solve %.2f ms\n",
                    halves ? "in two halves, two threads" : "whole, one core", 1e3 * first, ok ? "ok" : "FAILED",
                    1e3 * later, 1e3 * solve);
        dealii::MultithreadInfo::set_thread_limit(1);
      }

  // MUMPS on all ranks, K's rows in consecutive ranges.
  const PetscInt first = PetscInt(n * rank / ranks), last = PetscInt(n * (rank + 1) / ranks);
  Mat            A     = petsc_rows(K, first, last, world);
  Vec            b, x;
  check(MatCreateVecs(A, &x, &b), "MatCreateVecs");
  check(VecSet(b, 1.0), "VecSet");
  KSP ksp;
  PC  pc;
  check(KSPCreate(world, &ksp), "KSPCreate");
  check(KSPSetOperators(ksp, A, A), "KSPSetOperators");
  check(KSPSetType(ksp, KSPPREONLY), "KSPSetType");
  check(KSPGetPC(ksp, &pc), "KSPGetPC");
  check(PCSetType(pc, PCCHOLESKY), "PCSetType");
  check(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS), "PCFactorSetMatSolverType");
  MPI_Barrier(world);
  auto t0 = Clock::now();
  check(KSPSetUp(ksp), "KSPSetUp (first)");
  const double first_factor = slowest(seconds_since(t0), world);
  double       later        = 1e300;
  for (unsigned k = 0; k < repeats; ++k)
    {
      // New values on the same pattern (as the barrier changes): a numeric factorisation only.
      check(MatShift(A, 1e-300), "MatShift");
      check(KSPSetOperators(ksp, A, A), "KSPSetOperators");
      MPI_Barrier(world);
      const auto t1 = Clock::now();
      check(KSPSetUp(ksp), "KSPSetUp");
      later = std::min(later, slowest(seconds_since(t1), world));
    }
  MPI_Barrier(world);
  t0 = Clock::now();
  check(KSPSolve(ksp, b, x), "KSPSolve");
  const double solve = slowest(seconds_since(t0), world);

  // The same solution as CHOLMOD's: the residual of K x = 1.
  Vec r;
  check(VecDuplicate(b, &r), "VecDuplicate");
  check(MatMult(A, x, r), "MatMult");
  check(VecAXPY(r, -1.0, b), "VecAXPY");
  PetscReal residual = 0;
  check(VecNorm(r, NORM_INFINITY, &residual), "VecNorm");
  if (rank == 0)
    std::printf("MUMPS on %u ranks: first factorisation %.2f ms, later %.2f ms, solve %.2f ms, |K x - 1|_inf %.1e\n",
                ranks, 1e3 * first_factor, 1e3 * later, 1e3 * solve, double(residual));
  VecDestroy(&r);
  VecDestroy(&x);
  VecDestroy(&b);
  KSPDestroy(&ksp);
  MatDestroy(&A);
  return 0;
}
