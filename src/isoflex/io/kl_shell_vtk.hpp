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
// and `parameters` (ξ, η). KLShellVtkWriter (the static analysis) writes one file per written
// load step (vtk/step_NNNNNN.vtu) and a ParaView collection results.pvd indexed by the load
// parameter t, rewritten atomically after each file; in a dynamic run io::VtkSeriesWriter writes
// the same file per patch as a second part of each time step (vtk_writer.hpp).
#include <filesystem>
#include <string>

#include "isoflex/elements/kl_shell_patch.hpp"
#include "isoflex/integrate/kl_shell_analysis.hpp"

namespace isoflex::io {

// Quads per knot span and direction of the tessellation unless told otherwise.
inline constexpr int kKLShellQuadsPerSpan = 4;

class KLShellVtkWriter {
 public:
  // every ≤ 0 writes nothing. n_per_span: quads per knot span and direction.
  KLShellVtkWriter(const std::filesystem::path& outdir, const integrate::KLShellAnalysis& a,
                   int every, int n_per_span = kKLShellQuadsPerSpan);
  // Writes step `step` (0 = reference) if step % every == 0 or `last`.
  void write(int step, double t, const VecX& x, bool last = false);

 private:
  std::filesystem::path outdir_;
  const integrate::KLShellAnalysis& a_;
  int every_, n_per_span_;
  std::string pvd_entries_;
  int last_written_ = -1;
};

// The .vtu text of the tessellated deformed patch at x (control points stacked as the patch's x)
// with the fields above; the stresses are recovered with kinematics `kin`. Throws
// std::invalid_argument when x does not have patch.dofs() entries.
std::string kl_shell_vtu(const elements::KLShellPatch& patch, elements::KLKinematics kin,
                         const VecX& x, int n_per_span);
// The same for the patch and kinematics of a static analysis.
std::string kl_shell_vtu(const integrate::KLShellAnalysis& a, const VecX& x, int n_per_span);

}  // namespace isoflex::io
