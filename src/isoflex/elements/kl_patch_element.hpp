#pragma once
// A Kirchhoff–Love shell patch as one element of `System` (docs/architecture.md): its nodes are
// point nodes, one per control point in the surface's numbering (i_u + n_u·i_v), so that the
// stacked coordinates are the patch's x (elements::KLShellPatch). Potential Π_int (3.22), its
// gradient (3.33), the discrete gradient of kl-shell.md §10 and the consistent mass (4.24), all
// in the patch's fixed sparse pattern.
#include <memory>
#include <vector>

#include "isoflex/elements/element.hpp"
#include "isoflex/elements/kl_shell_patch.hpp"

namespace isoflex::elements {

class KLPatchElement final : public Element {
 public:
  // nodes: the system's node of each control point. Throws std::invalid_argument if their number
  // is not the patch's.
  KLPatchElement(std::shared_ptr<const KLShellPatch> patch, KLKinematics kinematics,
                 std::vector<int> nodes);

  const KLShellPatch& patch() const { return *patch_; }
  const std::shared_ptr<const KLShellPatch>& shared_patch() const { return patch_; }
  KLKinematics kinematics() const { return kinematics_; }

  const std::vector<int>& nodes() const override { return nodes_; }
  double potential(const VecX& q) const override;
  VecX gradient(const VecX& q) const override;
  // Dense ∂DV/∂qₙ₊₁ (for tests; the system uses the pattern).
  VecX discrete_gradient(const VecX& qn, const VecX& qn1, MatX* dv_dqn1) const override;
  MatX mass() const override;

  SpMat pattern() const override { return patch_->pattern(); }
  VecX discrete_gradient_in_pattern(const VecX& qn, const VecX& qn1, double* values) const override;
  // ∇V = r (3.33) and ∇²V (3.35)–(3.36) from the patch (its discrete gradient is not symmetric
  // in its arguments).
  VecX gradient_in_pattern(const VecX& q, double* values) const override;
  SpMat sparse_mass() const override { return patch_->mass(); }
  // Kelvin–Voigt forces of the material's η (KLShellPatch::viscous_force_into).
  bool viscous() const override { return patch_->section().eta > 0.0; }
  VecX viscous_force_in_pattern(const VecX& q, const VecX& qdot, double cq, double cv,
                                double* values) const override {
    return patch_->viscous_force_into(q, qdot, kinematics_, cq, cv, values);
  }

 private:
  std::shared_ptr<const KLShellPatch> patch_;
  KLKinematics kinematics_;
  std::vector<int> nodes_;
};

}  // namespace isoflex::elements
