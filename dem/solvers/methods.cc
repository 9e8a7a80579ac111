#include "dem/solvers/methods.h"

#include "dem/solvers/active_set.h"
#include "dem/solvers/apgd.h"
#include "dem/solvers/apgs.h"
#include "dem/solvers/interior_point.h"
#include "dem/solvers/mprgp.h"
#include "dem/solvers/nlgs.h"

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
} // namespace tribo::dem
