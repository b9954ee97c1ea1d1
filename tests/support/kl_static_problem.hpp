#pragma once
// One bare Kirchhoff–Love patch (elements::KLShellPatch) under patch loads as a StaticProblem
// (integrate/static_newton.hpp), without a System: a fixture of the patch's own unit tests and
// of the assembly bench (bench/kl_shell_bench.cpp), not part of the library — every model goes
// through System and integrate::StaticEquilibrium, whose
// residual is the same sum (System::static_force):
//
//   r(x, t) = f_int(x) − Σ_L λ_L(t) f_L(x) = 0,   K = ∂f_int/∂x − Σ_L λ_L(t) ∂f_L/∂x,
//
// f_int = ∂Π_int/∂x (3.33)–(3.36) in the patch's fixed pattern (the follower tangent lies inside
// it). The patch and the loads must outlive the problem.
#include <memory>
#include <vector>

#include "isoflex/elements/kl_shell_patch.hpp"
#include "isoflex/integrate/static_newton.hpp"
#include "isoflex/loads/kl_patch_loads.hpp"

namespace isoflex::test {

using loads::PatchLoads;

// The provider: (x, t) → (r, K, ‖f_ext‖∞). Throws std::invalid_argument if a load does not
// have the patch's number of dofs.
integrate::StaticProblem kl_static_problem(const elements::KLShellPatch& patch, PatchLoads loads,
                                           elements::KLKinematics kinematics);

}  // namespace isoflex::test
