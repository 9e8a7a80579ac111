#pragma once
/// @file APGS, the accelerated projected Gauss-Seidel method, on the frictionless contact
/// problem (dem/solvers/frictionless_problem.h): min f(x) = x.A x / 2 + b.x over x >= 0, and on
/// the problem with Coulomb friction (dem/solvers/sweep_problem.h), whose sweeps solve each
/// contact's 2x2 law exactly (ContactLaw::solve_coulomb()).
///
/// In the scaled variables of APGD (dem/solvers/apgd.h: y = D^(1/2) x, the operator A' + U'U'^T
/// with unit diagonal, b' = D^(-1/2) b, g = A'y + b'), one projected Gauss-Seidel sweep
/// S(v) visits the contacts in order and sets v_j = max(0, v_j - g_j(v)) with v already
/// updated before j (one pass over the operator, the walls' low-rank part kept current in
/// place). Nesterov's momentum is put on the sweeps: from y_0 = z_0 (the warm start), t_0 = 1,
///     y_{k+1} = S(z_k),
///     t_{k+1} = (1 + sqrt(1 + 4 t_k^2)) / 2,
///     z_{k+1} = y_{k+1} + (t_k - 1) / t_{k+1} (y_{k+1} - y_k),
/// with the gradient restart of O'Donoghue and Candès (2015): t_k = 1 (no momentum) when the
/// sweep's step opposes the momentum, (z_k - y_{k+1}).(y_{k+1} - y_k) > 0. Every
/// check_interval sweeps one product at y gives the natural map, and it stops as APGD does:
/// max_i |min(y_i, g_i)| / sqrt(D_i) at most SolverParameters::residual_target times the
/// mean loaded impulse, or after SolverParameters::max_iterations sweeps plus products.
///
/// A sweep's order: the contacts in detection order (rows of cells upwards) cut into
/// slab_count slabs of consecutive contacts, the even slabs first, then the odd ones. When
/// no contact couples slabs that are not neighbours and the walls' low-rank rows lie in one
/// slab (checked every solve), the slabs of one colour share no row and are swept
/// concurrently with SolverParameters::threads > 1, with the same bits on any number of
/// threads (SolveReport::concurrent says so); otherwise one slab holds every contact.
///
/// Local polish: after a check that fails, the contacts
/// above the target and their neighbours up to polish_rings rings away in A' (while they are
/// at most polish_fraction of all) get polish_passes projected Gauss-Seidel passes, in the
/// sweep's order, over them alone (y changed in place, z by the same amount, so the momentum
/// y - y_last is kept), then a new check of the rows the polish changed (the polished
/// contacts' rows of A', and the walls' low-rank rows when a polished contact is one of
/// them; the other contacts' map is still the last check's: the same bits as a whole check
/// at the polish's cost, not counted as a pass). Polishes
/// go on until polish_patience of them in a row have not lowered the map (at most
/// max_polishes); then a block of check_interval sweeps. The warm start's
/// worst contacts are a tail whose error grows with the sample (its largest |min(y_j, g_j)| over the mean impulse 6e-3, 1.2e-2, 2.1e-2 and 4.8e-2
/// at 1000, 4000, 16 000 and 64 000 grains, while its root mean square stays near 6e-4):
/// whole sweeps spent on that tail are what made the sweeps grow with the width, and the
/// polish works on it alone (docs/performance.md, "APGS's local polish").
///
/// With friction a contact is two rows (normal, tangent) and its natural map the norm of
/// (phi_n, phi_t) of dem/laws/law_residual.h, so the stopping test is the law residual itself.
/// The 2D Coulomb law is not associated: the sweep is no projected gradient step of a
/// potential and the momentum has no guarantee. A safeguard keeps the best iterate of the
/// whole checks and drops the momentum (t = 1, z = y) when a block of sweeps raises the map;
/// a solve that runs out of iterations returns the best iterate. The sweeps stop improving
/// near a law residual of 1e-9 on the unit tests' stacks, and on the deal.II block at a floor
/// that rises with the steps (1e-10 to 1e-7 over 60 steps): a slipping contact's normal
/// velocity stays at about 1e-8 of its impulse's scale; the cause is not known
/// (docs/laws.md).
///
/// A sweep carries a change along a whole force chain in the contacts' order, as NLGS does,
/// and the momentum accelerates it as APGD's accelerates the gradient (docs/performance.md:
/// on one core 0.51-0.67 times APGD's time per step at a residual of 1e-4 from 1000 to
/// 64 000 grains, 0.67-0.94 at 1e-3; on two threads, with the polish, 0.75 times at 4000
/// grains and 0.96 at 16 000 at 1e-3).

#include "dem/solvers/global_solver.h"

namespace tribo::dem
{
  class ApgsSolver : public GlobalSolver
  {
  public:
    using GlobalSolver::GlobalSolver;
    bool solves_friction() const override { return true; }
    /// Sweeps between natural-map checks.
    static constexpr unsigned int check_interval = 10;
    /// Slabs of consecutive contacts of a sweep (dem/solvers/apgs.cc): even ones, then odd ones.
    static constexpr long slab_count = 8;
    /// The local polish after a check that fails: passes over the contacts above the target
    /// and their neighbours, ...
    static constexpr unsigned int polish_passes = 3;
    /// ... and their neighbours up to this many rings away in A', ...
    static constexpr unsigned int polish_rings = 2;
    /// ... polishes (each followed by a check of the rows it changed) go on between two
    /// blocks of sweeps until this many in a row have not lowered the map below its lowest
    /// since the block (a polish that leaves the worst contact where it was still repairs
    /// others: stopping at the first such polish made more passes, docs/performance.md), ...
    static constexpr unsigned int polish_patience = 32;
    /// ... and at most this many of them,
    static constexpr unsigned int max_polishes = 1024;
    /// ... and only while those contacts are at most this fraction of all.
    static constexpr double polish_fraction = 0.05;

  protected:
    /// The report's iterations are the sweeps plus the whole checks (one product each); the
    /// polishes and their checks of the polished rows are not counted.
    SolveReport solve_problem(std::vector<Contact> &contacts, BodyState &state,
                              const ContactLaw &law) override;
  };
} // namespace tribo::dem
