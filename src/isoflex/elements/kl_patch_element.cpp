#include "isoflex/elements/kl_patch_element.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace isoflex::elements {

KLPatchElement::KLPatchElement(std::shared_ptr<const KLShellPatch> patch, KLKinematics kinematics,
                               std::vector<int> nodes)
    : patch_(std::move(patch)), kinematics_(kinematics), nodes_(std::move(nodes)) {
  if (!patch_) throw std::invalid_argument("KLPatchElement: no patch");
  if (static_cast<int>(nodes_.size()) != patch_->control_points())
    throw std::invalid_argument("KLPatchElement: " + std::to_string(nodes_.size()) + " nodes for " +
                                std::to_string(patch_->control_points()) + " control points");
}

double KLPatchElement::potential(const VecX& q) const {
  return patch_->energy(q, kinematics_);
}

VecX KLPatchElement::gradient(const VecX& q) const {
  return patch_->internal_force_into(q, kinematics_, nullptr);
}

VecX KLPatchElement::discrete_gradient(const VecX& qn, const VecX& qn1, MatX* dv_dqn1) const {
  if (!dv_dqn1) return patch_->discrete_gradient_into(qn, qn1, kinematics_, nullptr);
  SpMat K;
  const VecX dv = patch_->discrete_gradient(qn, qn1, kinematics_, &K);
  *dv_dqn1 = MatX(K);
  return dv;
}

VecX KLPatchElement::discrete_gradient_in_pattern(const VecX& qn, const VecX& qn1,
                                                  double* values) const {
  return patch_->discrete_gradient_into(qn, qn1, kinematics_, values);
}

VecX KLPatchElement::gradient_in_pattern(const VecX& q, double* values) const {
  return patch_->internal_force_into(q, kinematics_, values);
}

MatX KLPatchElement::mass() const {
  return MatX(patch_->mass());
}

}  // namespace isoflex::elements
