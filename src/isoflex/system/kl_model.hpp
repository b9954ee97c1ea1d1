#pragma once
// The Kirchhoff–Love parts of a model (docs/model-files.md "kl_shells", "kl_loads") as elements
// and loads: shared by System::compile (dynamics) and the static shell analysis. Errors are
// CompileErrors at the model entry.
#include <memory>

#include "isoflex/elements/kl_shell_patch.hpp"
#include "isoflex/loads/kl_patch_loads.hpp"
#include "isoflex/model/model.hpp"

namespace isoflex::system {

// The (refined, placed) surface a shell names.
const geometry::NurbsSurface& kl_surface(const model::Model& m, const model::KLShell& s);
// The patch of shell `index` on its surface.
std::shared_ptr<elements::KLShellPatch> kl_patch(const model::Model& m, int index);
// The kl_loads of the model (all on the model's one patch for now).
loads::PatchLoads kl_patch_loads(const model::Model& m, const model::KLShell& s);
elements::KLKinematics kl_kinematics(const model::Model& m);

}  // namespace isoflex::system
