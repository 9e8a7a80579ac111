/// @file The case entries of the contact law and of the contact solver, declared and read
/// here in the subsections the application names (ContactLaw::declare(), parse();
/// SolverParameters::declare(), parse()).

#include "core/parameter_file.h"
#include "dem/contact_law.h"
#include "dem/nlgs.h"

#include <deal.II/base/parameter_handler.h>

#include <cmath>

namespace tribo::dem
{
  using dealii::Patterns::Double;
  using dealii::Patterns::Integer;
  using dealii::Patterns::Selection;

  namespace
  {
    bool positive(double v) { return v > 0 && std::isfinite(v); }
    bool non_negative(double v) { return v >= 0 && std::isfinite(v); }
  } // namespace

  void ContactLaw::declare(dealii::ParameterHandler &prm)
  {
    prm.declare_entry("Law", "IQS", Selection("IQS|ELAS"),
                      "IQS: cohesive unilateral (inelastic quasi-shock), r_N + gamma >= 0, g >= 0, "
                      "(r_N + gamma) g = 0. ELAS: cohesive elastic, r_N + gamma = max(0, -k g). "
                      "r_N > 0 is compressive; see docs/laws.md.");
    prm.declare_entry("Cohesion", "0", Double(), "Cohesion gamma, N/m (force per unit depth), >= 0.");
    prm.declare_entry("Cohesion range", "0", Double(),
                      "Distance d_w over which the cohesion acts, m, >= 0 (needed if Cohesion > 0).");
    prm.declare_entry("Stiffness", "1e10", Double(),
                      "ELAS normal stiffness k, N/m^2 (force per unit depth per metre of overlap), > 0.");
    prm.declare_entry("Friction coefficient", "0", Double(),
                      "Coulomb friction coefficient between discs, >= 0 (0: frictionless, as in the paper).");
    prm.declare_entry("Overlap recovery", "0", Double(0, 1),
                      "IQS only: fraction in [0, 1] of an existing overlap pushed out per step. 0 freezes "
                      "overlaps as the paper's law does; under high pressure the NLGS's small velocity "
                      "errors then accumulate into overlaps step after step (docs/laws.md); 0.1 keeps "
                      "them at the size of one step's error.");
    prm.declare_entry("Detection distance", "0", Double(),
                      "Pairs closer than this gap (m) enter the contact list; 0 picks a tenth of the "
                      "smallest radius. Always at least the cohesion range.");
  }

  ContactLaw ContactLaw::parse(const ParameterFile &f, const std::string &section)
  {
    ContactLaw law;
    law.section       = {section};
    const auto entry  = [&](const std::string &name) { return law.section.entry(name); };
    law.type          = f.get(entry("Law")) == "IQS" ? Type::iqs : Type::elas;
    law.cohesion      = f.get_checked(entry("Cohesion"), non_negative, "a cohesion >= 0 in N/m");
    law.cohesion_range = f.get_checked(entry("Cohesion range"), non_negative, "a distance >= 0 in m");
    if (law.cohesion > 0 && law.cohesion_range == 0)
      f.fail(entry("Cohesion range"), "a positive range in m, since " + entry("Cohesion") + " > 0");
    law.stiffness        = f.get_checked(entry("Stiffness"), positive, "a positive stiffness in N/m^2");
    law.overlap_recovery = f.get_double(entry("Overlap recovery"));
    law.friction         = f.get_checked(entry("Friction coefficient"), non_negative, "a coefficient >= 0");
    law.detection_distance =
      f.get_checked(entry("Detection distance"), non_negative, "a distance >= 0 in m");
    return law;
  }

  void SolverParameters::declare(dealii::ParameterHandler &prm)
  {
    prm.declare_entry("Method", "apgs", Selection("nlgs|active-set|mprgp|interior-point|apgd|apgs"),
                      "Contact solver: 'apgs' (the default: projected Gauss-Seidel sweeps with "
                      "Nesterov momentum and a local polish of the worst contacts, both cores with "
                      "Threads = 2; the fastest measured on every shipped shear case that uses the "
                      "default, docs/performance.md), 'apgd' (matrix-free accelerated projected "
                      "gradient with restart, both cores with Threads = 2), 'nlgs' (nonlinear "
                      "Gauss-Seidel, the entries Tolerance to Streams below), 'active-set' (projected "
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
    prm.declare_entry("Regularization", "1e-8", Double(),
                      "Active set: relative regularisation delta in [0, 1e-4] of the Newton matrix "
                      "W_FF + delta diag(W_FF) (redundant contacts make W_FF singular); it changes "
                      "the Newton step, not the solution.");
    prm.declare_entry("Predictor sweeps", "10", Integer(0),
                      "Active set, MPRGP, interior point, APGD: NLGS sweeps before their iterations, >= 0 "
                      "(0 suits the interior point).");
    prm.declare_entry("Maximum factorizations", "50", Integer(1),
                      "Active set: Newton iterations (factorisations) per step before the step is "
                      "solved by NLGS instead; interior point: iterations before it stops, not "
                      "converged, >= 1.");
    prm.declare_entry("Tolerance", "1e-4", Double(), "NLGS tolerance, > 0 (relative, see Norm).");
    prm.declare_entry("Norm", "Quad", Selection("Quad|Maxm"),
                      "Convergence norm of the established NSCD code: 'Quad' (mean-square) or "
                      "'Maxm' (maximum over contacts).");
    prm.declare_entry("Relaxation", "1", Double(), "Relaxation omega in (0, 1]: r = omega r_law + (1 - omega) r_old.");
    prm.declare_entry("Check interval", "10", Integer(1), "Sweeps between convergence checks, >= 1.");
    prm.declare_entry("Maximum iterations", "10000", Integer(1),
                      "Maximum number of sweeps per step (MPRGP, APGD: products with the Delassus "
                      "operator), >= 1.");
    prm.declare_entry("Contact order", "fixed", Selection("fixed|alternating|random"),
                      "Order of the local solves: 'fixed' (detection order: cells by rows, bottom to "
                      "top), 'alternating' (that order and its reverse in turn, a symmetric Gauss-Seidel) "
                      "or 'random' (shuffled every sweep).");
    prm.declare_entry("Seed", "1", Integer(0), "Seed of the random contact order.");
    prm.declare_entry("Streams", "1", Integer(1),
                      "With Contact order = fixed: windows of 64 x Streams consecutive contacts, "
                      "each cut into this many streams solved one contact from each in turn, >= 1 "
                      "(1: the detection order itself). Contacts 64 apart rarely share a body, so "
                      "the processor overlaps their updates: 4 streams do 1.2-1.5 times more contact "
                      "updates per second for about 3 % more sweeps, and change the trajectory "
                      "(docs/performance.md).");
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
    prm.declare_entry("Gap tolerance", "0", Double(),
                      "NLGS: extra IQS convergence criterion, as a fraction of the smallest radius (>= 0; "
                      "0: off, the established code's norms only): every contact's gap violation "
                      "theta h max(0, -(u_n + shift)) must be below it. Limits the overlaps that the "
                      "norms let accumulate under high pressure, at the price of more sweeps.");
  }

  SolverParameters SolverParameters::parse(const ParameterFile &f, const std::string &section)
  {
    SolverParameters p;
    p.section              = {section};
    const auto entry       = [&](const std::string &name) { return p.section.entry(name); };
    const std::string method = f.get(entry("Method"));
    p.method = method == "active-set"       ? Method::active_set
               : method == "mprgp"          ? Method::mprgp
               : method == "interior-point" ? Method::interior_point
               : method == "apgd"           ? Method::apgd
               : method == "apgs"           ? Method::apgs
                                            : Method::nlgs;
    p.residual_target = f.get_checked(entry("Residual target"), [](double v) { return v > 0 && v < 1; },
                                      "a relative residual in (0, 1)");
    p.regularization = f.get_checked(entry("Regularization"), [](double v) { return v >= 0 && v <= 1e-4; },
                                     "a regularisation in [0, 1e-4]");
    p.max_factorizations = f.get_integer(entry("Maximum factorizations"));
    p.predictor_sweeps   = f.get_integer(entry("Predictor sweeps"));
    p.tolerance          = f.get_checked(entry("Tolerance"), positive, "a positive tolerance");
    p.norm               = f.get(entry("Norm")) == "Quad" ? Norm::quad : Norm::maxm;
    p.relaxation = f.get_checked(entry("Relaxation"), [](double v) { return v > 0 && v <= 1; },
                                 "a relaxation in (0, 1]");
    p.check_interval = f.get_integer(entry("Check interval"));
    p.max_iterations = f.get_integer(entry("Maximum iterations"));
    const std::string order = f.get(entry("Contact order"));
    p.order   = order == "random" ? Order::random : order == "alternating" ? Order::alternating : Order::fixed;
    p.seed    = f.get_integer(entry("Seed"));
    p.threads = f.get_integer(entry("Threads"));
    p.streams = f.get_integer(entry("Streams"));
    if (p.threads > 1 && p.order != Order::fixed)
      f.fail(entry("Threads"), "1 with " + entry("Contact order") + " = " + order +
                                 " (bands solved at once need the fixed order)");
    p.relative_gap_tolerance =
      f.get_checked(entry("Gap tolerance"), non_negative, "a fraction >= 0 of the smallest radius");
    p.relative_gap_target =
      f.get_checked(entry("Gap target"), non_negative, "a fraction >= 0 of the smallest radius");
    if (p.method != Method::nlgs)
      for (const char *name : {"Tolerance", "Norm", "Check interval", "Gap tolerance"})
        if (!f.is_default(entry(name)))
          p.unused_nlgs_entries += std::string(p.unused_nlgs_entries.empty() ? "" : ", ") + entry(name) +
                                   " (" + f.where(entry(name)) + ")";
    return p;
  }
} // namespace tribo::dem
