#pragma once
// A joint instance's rows as a Constraint (constraint.hpp): the joint between a parent node — or
// the ground, whose coordinates are constant and not part of q — and a child node, over the
// stacked coordinates of (parent, child), or of the child alone for the ground. System evaluates
// every row of the model through this one contract (Φ, G, the Hessians); the spanning forest
// uses the joint's own elimination (joint.hpp) for the tree joints.
#include <memory>
#include <vector>

#include "isoflex/joints/constraint.hpp"
#include "isoflex/joints/joint.hpp"

namespace isoflex::joints {

class JointRows final : public Constraint {
 public:
  // parent < 0: the ground, with coordinates `ground` (a frame at the origin).
  JointRows(std::shared_ptr<const Joint> joint, int parent, int child, VecX ground);

  const std::vector<int>& nodes() const override { return nodes_; }
  int constraint_count() const override { return joint_->constraint_count(); }
  VecX constraints(CRef q_c) const override;
  MatX jacobian(CRef q_c) const override;
  void add_constraint_hessian(CRef q_c, CRef lambda, MatX& H) const override;

 private:
  CRef parent_q(CRef q_c) const { return grounded() ? CRef(ground_) : q_c.head(na_); }
  CRef child_q(CRef q_c) const { return q_c.tail(nb_); }
  bool grounded() const { return nodes_.size() == 1; }

  std::shared_ptr<const Joint> joint_;
  std::vector<int> nodes_;
  VecX ground_;
  int na_ = 0, nb_ = 0;
};

}  // namespace isoflex::joints
