#include "isoflex/joints/joint_rows.hpp"

#include <cassert>
#include <utility>

namespace isoflex::joints {

JointRows::JointRows(std::shared_ptr<const Joint> joint, int parent, int child, VecX ground,
                     std::function<VecX(double)> d)
    : joint_(std::move(joint)),
      ground_(std::move(ground)),
      d_(std::move(d)),
      na_(coordinate_count(joint_->parent_kind())),
      nb_(coordinate_count(joint_->child_kind())) {
  if (parent >= 0) nodes_.push_back(parent);
  nodes_.push_back(child);
  assert(parent >= 0 || ground_.size() == na_);
}

VecX JointRows::constraints(CRef q_c) const {
  return joint_->constraints(parent_q(q_c), child_q(q_c));
}

MatX JointRows::jacobian(CRef q_c) const {
  MatX G = joint_->jacobian(parent_q(q_c), child_q(q_c));
  if (!grounded()) return G;
  return G.rightCols(nb_);
}

void JointRows::add_constraint_hessian(CRef, CRef lambda, MatX& H) const {
  if (!grounded()) {
    joint_->add_constraint_hessian(lambda, H);
    return;
  }
  MatX full = MatX::Zero(na_ + nb_, na_ + nb_);
  joint_->add_constraint_hessian(lambda, full);
  H += full.bottomRightCorner(nb_, nb_);
}

}  // namespace isoflex::joints
