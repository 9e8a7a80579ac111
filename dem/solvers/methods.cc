#include "dem/solvers/methods.h"

#include "core/parameter_file.h"
#include "dem/solvers/active_set.h"
#include "dem/solvers/apgd.h"
#include "dem/solvers/apgs.h"
#include "dem/solvers/interior_point.h"
#include "dem/solvers/mprgp.h"
#include "dem/solvers/nlgs.h"

#include <deal.II/base/parameter_handler.h>

#include <stdexcept>

namespace tribo::dem
{
  namespace
  {
    template <typename Solver>
    std::unique_ptr<ContactSolver> make(const SolverParameters &prm)
    {
      return std::make_unique<Solver>(prm);
    }
  } // namespace

  const std::vector<SolverMethod> &solver_methods()
  {
    using Method = SolverParameters::Method;
    static const std::vector<SolverMethod> rows = {
      {Method::nlgs, "nlgs", "NLGS sweeps", NlgsSolver::declare, NlgsSolver::parse, make<NlgsSolver>},
      {Method::active_set, "active-set", "NLGS sweeps", ActiveSetSolver::declare, ActiveSetSolver::parse,
       make<ActiveSetSolver>},
      {Method::mprgp, "mprgp", "NLGS sweeps and MPRGP products", nullptr, nullptr, make<MprgpSolver>},
      {Method::interior_point, "interior-point", "NLGS sweeps", nullptr, nullptr, make<InteriorPointSolver>},
      {Method::apgd, "apgd", "NLGS sweeps and APGD products", nullptr, nullptr, make<ApgdSolver>},
      {Method::apgs, "apgs", "NLGS sweeps, APGS sweeps and products", nullptr, nullptr, make<ApgsSolver>},
    };
    return rows;
  }

  using dealii::Patterns::Double;
  using dealii::Patterns::Integer;
  using dealii::Patterns::Selection;

  void SolverParameters::declare(dealii::ParameterHandler &prm)
  {
    std::string names;
    for (const SolverMethod &row : solver_methods())
      names += (names.empty() ? "" : "|") + std::string(row.name);
    prm.declare_entry("Method", method_name(SolverParameters{}.method), Selection(names),
                      "Contact solver: 'apgs' (the default: projected Gauss-Seidel sweeps with "
                      "Nesterov momentum and a local polish of the worst contacts, both cores with "
                      "Threads = 2; the fastest measured on every shipped shear case that uses the "
                      "default, docs/performance.md), 'apgd' (matrix-free accelerated projected "
                      "gradient with restart, both cores with Threads = 2), 'nlgs' (nonlinear "
                      "Gauss-Seidel, with its entries Tolerance, Norm, Relaxation, Check interval, "
                      "Contact order, Seed, Streams and Gap tolerance), 'active-set' (projected "
                      "Newton method on the frictionless problem, the sparse Delassus operator "
                      "factorised by CHOLMOD), 'mprgp' (matrix-free projected conjugate gradient with "
                      "proportioning) or "
                      "'interior-point' (Mehrotra's predictor-corrector, CHOLMOD: the one that "
                      "reaches 1e-8 on dense packings). All but nlgs stop at Residual target; "
                      "nlgs and apgs solve Coulomb friction, with friction the others' steps use "
                      "NLGS and the log says so.");
    prm.declare_entry("Residual target", "1e-3", Double(),
                      "Active set, MPRGP, interior point, APGD, APGS: the solve ends when the law residual, max over "
                      "contacts of |min(r~, u~ / W_nn)| over the mean loaded impulse r~ "
                      "(dimensionless, docs/laws.md), is below this, in (0, 1). The default is "
                      "below the 1.2-1.5e-3 NLGS leaves on average at its default Tolerance (1e-4, "
                      "Quad) in steady shear, where MPRGP at 1.5e-3 let overlaps grow past a radius "
                      "(docs/performance.md); 1e-11 is a converged solve.");
    prm.declare_entry("Predictor sweeps", "10", Integer(0),
                      "Active set, MPRGP, interior point, APGD: NLGS sweeps before their iterations, >= 0 "
                      "(0 suits the interior point).");
    prm.declare_entry("Maximum factorizations", "50", Integer(1),
                      "Active set: Newton iterations (factorisations) per step before the step is "
                      "solved by NLGS instead; interior point: iterations before it stops, not "
                      "converged, >= 1.");
    prm.declare_entry("Maximum iterations", "10000", Integer(1),
                      "Maximum number of sweeps per step (MPRGP, APGD: products with the Delassus "
                      "operator), >= 1.");
    prm.declare_entry("Threads", "1", Integer(1),
                      "Bands of contacts solved at once, >= 1 (1: the serial sweep). T > 1 cuts the "
                      "contacts (rows of cells, bottom to top) into 2T bands and solves the even bands "
                      "concurrently, then the odd ones: a Gauss-Seidel sweep in that band order, the "
                      "same result on any number of cores. Needs Contact order = fixed. The contact "
                      "detection also runs in T threads (the same contacts whatever T). APGD, APGS: "
                      "their passes over both cores, the same bits. Interior point: from 4000 "
                      "contacts its Newton matrix is factorised in two halves at once (its rounding "
                      "then differs from one thread's).");
    prm.declare_entry("Gap target", "0.01", Double(),
                      "Every method: the largest gap violation theta h max(0, -(u_n + shift)) an IQS "
                      "step may keep and count as converged, as a fraction of the smallest radius "
                      "(>= 0; 0: off). The law residual is relative to the mean impulse, which a few "
                      "large impulses (a heavy body stopped in one step) inflate; a step above this "
                      "target is not converged, the log says why, and summary.json counts it "
                      "(gap_target_exceeded).");
    for (const SolverMethod &row : solver_methods())
      if (row.declare)
        row.declare(prm);
  }

  SolverParameters SolverParameters::parse(const ParameterFile &f, const std::string &section)
  {
    SolverParameters p;
    p.section              = {section};
    const auto entry       = [&](const std::string &name) { return p.section.entry(name); };
    const std::string name = f.get(entry("Method"));
    for (const SolverMethod &row : solver_methods())
      if (name == row.name)
        p.method = row.method;
    p.residual_target = f.get_checked(entry("Residual target"), [](double v) { return v > 0 && v < 1; },
                                      "a relative residual in (0, 1)");
    p.predictor_sweeps   = f.get_integer(entry("Predictor sweeps"));
    p.max_factorizations = f.get_integer(entry("Maximum factorizations"));
    p.max_iterations     = f.get_integer(entry("Maximum iterations"));
    p.threads            = f.get_integer(entry("Threads"));
    p.relative_gap_target =
      f.get_checked(entry("Gap target"), is_non_negative, "a fraction >= 0 of the smallest radius");
    for (const SolverMethod &row : solver_methods())
      if (row.parse)
        row.parse(f, p);
    return p;
  }

  const SolverMethod &solver_method(SolverParameters::Method method)
  {
    for (const SolverMethod &row : solver_methods())
      if (row.method == method)
        return row;
    throw std::logic_error("a solver method without its row in dem/solvers/methods.cc");
  }

  std::unique_ptr<ContactSolver> make_contact_solver(const SolverParameters &prm)
  {
    return solver_method(prm.method).make(prm);
  }

  bool solves_friction(SolverParameters::Method method)
  {
    SolverParameters prm;
    prm.method = method;
    return make_contact_solver(prm)->solves_friction();
  }

  std::string method_name(SolverParameters::Method method) { return solver_method(method).name; }
} // namespace tribo::dem
