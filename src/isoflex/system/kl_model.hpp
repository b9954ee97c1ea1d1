#pragma once
// The Kirchhoff–Love parts of a model (docs/model-files.md "kl_shells", "kl_loads") as elements
// and loads: used by System::compile. Errors are
// CompileErrors at the model entry.
#include <functional>
#include <memory>

#include "isoflex/elements/kl_shell_patch.hpp"
#include "isoflex/loads/kl_patch_loads.hpp"
#include "isoflex/model/model.hpp"
#include "isoflex/system/kl_boundary_conditions.hpp"

namespace isoflex::system {

// The (refined, placed) surface a shell names.
const geometry::NurbsSurface& kl_surface(const model::Model& m, const model::KLShell& s);
// The patch of shell `index` on `g`: its surface, or the surface made conforming with its
// neighbours (system/kl_interfaces.hpp; the same geometry and parametrization).
std::shared_ptr<elements::KLShellPatch> kl_patch(const model::Model& m, int index,
                                                 const geometry::NurbsSurface& g);
// The kl_loads of the model on shell `s`, whose patch is on `g` (as above).
loads::PatchLoads kl_patch_loads(const model::Model& m, const model::KLShell& s,
                                 const geometry::NurbsSurface& g);
elements::KLKinematics kl_kinematics(const model::Model& m);
// The boundary conditions of the kl_supports entries for which `which` is true, on the patch of
// the given surface (docs/theory/kl-static.md §2); CompileError at the support entry.
KLBoundaryConditions kl_boundary_conditions(
    const model::Model& m, const geometry::NurbsSurface& g,
    const std::function<bool(const model::KLSupport&)>& which);

}  // namespace isoflex::system
