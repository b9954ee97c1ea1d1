#pragma once
// VTU output of a Kirchhoff–Love shell run: the deformed mid-surface tessellated per knot span
// (io/nurbs_vtk_writer.hpp, n × n VTK_QUAD per element, evaluated exactly), with point data
//   displacement                 x − X (3)
//   n, m                         membrane forces and bending moments per unit length in the local
//                                Cartesian frame (11, 22, 12) (IGA-thesis (3.47))
//   sigma_top, sigma_bottom      Cauchy stresses (11, 22, 12) on the top (+t/2 along a₃) and
//                                bottom surfaces (3.44)–(3.46)
//   principal_top, principal_bottom  principal stresses σ_I ≥ σ_II (3.48)–(3.49)
//   von_mises_top, von_mises_bottom  (3.50)
//   e1                           the frame's first axis (the direction of n₁₁, m₁₁, σ₁₁)
// and `parameters` (ξ, η). io::VtkSeriesWriter (vtk_writer.hpp) writes this file per patch as a
// part of each written step, static and dynamic runs alike.
#include <filesystem>
#include <string>

#include "isoflex/elements/kl_shell_patch.hpp"
#include "isoflex/model/model.hpp"

namespace isoflex::io {

// Quads per knot span and direction of the tessellation unless told otherwise.
inline constexpr int kKLShellQuadsPerSpan = 4;

// The .vtu text (in `format`) of the tessellated deformed patch at x (control points stacked as
// the patch's x) with the fields above; the stresses are recovered with kinematics `kin`. Throws
// std::invalid_argument when x does not have patch.dofs() entries.
std::string kl_shell_vtu(const elements::KLShellPatch& patch, elements::KLKinematics kin,
                         const VecX& x, int n_per_span, model::VtkFormat format);

}  // namespace isoflex::io
