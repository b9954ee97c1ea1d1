#pragma once
// A joint instance's rows as a Constraint (constraint.hpp): the joint between a parent node — or
// the ground, whose coordinates are constant and not part of q — and a child node, over the
// stacked coordinates of (parent, child), or of the child alone for the ground. System evaluates
// every row of the model through this one contract (Φ, G, the Hessians); the spanning forest
// uses the joint's own elimination (joint.hpp) for the tree joints. With a prescribed right-hand
// side d(t) the rows are rheonomic, Φ(q) = d(t) (a spherical joint whose ground point moves:
// system/joint_drivers.hpp); such a joint is never a tree joint.
#include <functional>
#include <memory>
#include <vector>

#include "isoflex/joints/constraint.hpp"
#include "isoflex/joints/joint.hpp"

namespace isoflex::joints {

class JointRows final : public Constraint {
 public:
  // parent < 0: the ground, with coordinates `ground` (a frame at the origin).
  // d: the prescribed right-hand side (constraint_count() entries), empty for 0.
  JointRows(std::shared_ptr<const Joint> joint, int parent, int child, VecX ground,
            std::function<VecX(double)> d = {});

  const std::vector<int>& nodes() const override { return nodes_; }
  int constraint_count() const override { return joint_->constraint_count(); }
  VecX constraints(CRef q_c) const override;
  MatX jacobian(CRef q_c) const override;
  void add_constraint_hessian(CRef q_c, CRef lambda, MatX& H) const override;
  bool rheonomic() const override { return static_cast<bool>(d_); }
  VecX prescribed(double t) const override { return d_ ? d_(t) : VecX::Zero(constraint_count()); }

 private:
  CRef parent_q(CRef q_c) const { return grounded() ? CRef(ground_) : q_c.head(na_); }
  CRef child_q(CRef q_c) const { return q_c.tail(nb_); }
  bool grounded() const { return nodes_.size() == 1; }

  std::shared_ptr<const Joint> joint_;
  std::vector<int> nodes_;
  VecX ground_;
  std::function<VecX(double)> d_;
  int na_ = 0, nb_ = 0;
};

}  // namespace isoflex::joints
