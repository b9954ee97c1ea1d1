#pragma once
// A model with a Kirchhoff–Love shell (docs/model-files.md "kl_shells") compiled for static
// analysis: the patch on its (refined, placed) surface, the loads of `kl_loads`, the boundary
// conditions of `kl_supports`, the probes on the shell and the load-stepping settings from
// `solver` (dt = load increment, t_end, linear, max_subdivisions = adaptive halvings,
// tolerances). One patch per model for now (multipatch coupling, IGA-thesis §4.4, comes later);
// Kirchhoff–Love shells are not yet combined with bodies, beams or director shells.
#include <memory>
#include <string>
#include <vector>

#include "isoflex/elements/kl_shell_patch.hpp"
#include "isoflex/integrate/kl_boundary_conditions.hpp"
#include "isoflex/integrate/kl_static_solver.hpp"
#include "isoflex/model/model.hpp"

namespace isoflex::integrate {

struct KLProbe {
  std::string name;
  double xi = 0.0, eta = 0.0;
  Vec3 reference = Vec3::Zero();  // the material point at t = 0
};

class KLShellAnalysis {
 public:
  // Throws system::CompileError ("FILE:LINE: KEY: message") for what the model reader cannot
  // check alone: more than one shell, shells mixed with other parts, conflicting supports.
  static KLShellAnalysis compile(const model::Model& m);

  const model::KLShell& shell() const { return shell_; }
  const elements::KLShellPatch& patch() const { return *patch_; }
  // Threads of the patch's assembly (elements::KLShellPatch::set_threads); call it before
  // solver(), whose problem refers to the patch.
  void set_threads(int threads);
  const PatchLoads& loads() const { return loads_; }
  const LinearConstraints& constraints() const { return constraints_; }
  elements::KLKinematics kinematics() const { return kinematics_; }
  const StaticSettings& settings() const { return settings_; }
  const std::vector<KLProbe>& probes() const { return probes_; }
  // The load-stepping solver of this analysis (its constraints are the ones computed here).
  KLStaticSolver solver() const {
    return KLStaticSolver(*patch_, loads_, constraints_, settings_, kinematics_);
  }

  int eliminated() const { return static_cast<int>(constraints_.eliminated.size()); }
  int multipliers() const { return constraints_.multipliers(); }
  // Newton unknowns: free control-point components plus multipliers.
  int unknowns() const { return patch_->dofs() - eliminated() + multipliers(); }
  // The mid-surface point of x at (ξ, η).
  Vec3 point(const VecX& x, double xi, double eta) const;

 private:
  model::KLShell shell_;
  std::shared_ptr<const elements::KLShellPatch> patch_;
  PatchLoads loads_;
  LinearConstraints constraints_;
  elements::KLKinematics kinematics_ = elements::KLKinematics::nonlinear;
  StaticSettings settings_;
  std::vector<KLProbe> probes_;
};

}  // namespace isoflex::integrate
