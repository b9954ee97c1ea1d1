#pragma once
// Static equilibrium of one Kirchhoff–Love shell patch (elements::KLShellPatch) under patch loads
// (loads/kl_patch_loads.hpp) and Dirichlet conditions (kl_boundary_conditions.hpp), by Newton's
// method with load stepping (static_newton.hpp; IGA-thesis §6.2 without the mass terms,
// docs/theory/kl-static.md):
//
//   r(x, t) = f_int(x) − Σ_L λ_L(t) f_L(x) = 0,   K = ∂f_int/∂x − Σ_L λ_L(t) ∂f_L/∂x,
//
// f_int = ∂Π_int/∂x (3.33)–(3.36) from the patch, in the patch's fixed pattern (the follower
// tangent lies inside it: it couples control points sharing an element). Linear kinematics with
// dead loads is one solve per load step; with follower loads the tangent is not symmetric and the
// LU path is taken. The patch and the loads must outlive the solver.
#include <memory>
#include <vector>

#include "isoflex/elements/kl_shell_patch.hpp"
#include "isoflex/integrate/static_newton.hpp"
#include "isoflex/loads/kl_patch_loads.hpp"
#include "isoflex/system/kl_boundary_conditions.hpp"

namespace isoflex::integrate {

using system::KLBoundaryConditions;

using loads::PatchLoads;

// The provider: (x, t) → (r, K, ‖f_ext‖∞). Throws std::invalid_argument if a load does not
// have the patch's number of dofs.
StaticProblem kl_static_problem(const elements::KLShellPatch& patch, PatchLoads loads,
                                elements::KLKinematics kinematics);

class KLStaticSolver {
 public:
  KLStaticSolver(const elements::KLShellPatch& patch, PatchLoads loads,
                 const KLBoundaryConditions& bcs, StaticSettings settings,
                 elements::KLKinematics kinematics = elements::KLKinematics::nonlinear);
  // The same with the conditions already turned into constraints (bcs.constraints()).
  KLStaticSolver(const elements::KLShellPatch& patch, PatchLoads loads,
                 LinearConstraints constraints, StaticSettings settings,
                 elements::KLKinematics kinematics = elements::KLKinematics::nonlinear);
  // Final x (full, 3·ncp), multipliers, per-step statistics; observer(stats, x) per load step.
  StaticResult solve(const StaticObserver& observer = {}) { return solver_.solve(observer); }
  const DofMap& dofs() const { return solver_.dofs(); }

 private:
  StaticNewtonSolver solver_;
};

}  // namespace isoflex::integrate
