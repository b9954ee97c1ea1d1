#pragma once
// Linear rows C (q_c − Q_c) = d(t) over the stacked coordinates of some nodes: the
// Kirchhoff–Love supports that are not rigid attachments (single components, symmetry edges,
// the slope rows of a clamp, prescribed displacements; system/kl_boundary_conditions.hpp) in a
// dynamic run. Jacobian C, Hessian 0: linear rows hold exactly at every time node of the midpoint
// rule. With d = 0 their forces Cᵀλ do no work on the motions they allow, so energy stays
// conserved (momentum is not: a support holds the body); a prescribed d(t) does the work
// −λᵀ(d(tₙ₊₁) − d(tₙ)) in a step.
#include <functional>
#include <string>
#include <vector>

#include "isoflex/joints/constraint.hpp"

namespace isoflex::joints {

class LinearRows final : public Constraint {
 public:
  // C: rows × Q.size(); Q the stacked reference coordinates of `nodes`; d: the right-hand side
  // (rows entries), empty for 0. Throws std::invalid_argument for inconsistent sizes or
  // non-finite entries.
  LinearRows(std::vector<int> nodes, MatX C, VecX Q, std::function<VecX(double)> d = {});

  const std::vector<int>& nodes() const override { return nodes_; }
  int constraint_count() const override { return static_cast<int>(C_.rows()); }
  VecX constraints(CRef q_c) const override { return C_ * (q_c - Q_); }
  MatX jacobian(CRef) const override { return C_; }
  void add_constraint_hessian(CRef, CRef, MatX&) const override {}
  bool rheonomic() const override { return static_cast<bool>(d_); }
  double compliance() const override { return compliance_; }
  void set_compliance(double c) { compliance_ = c; }
  // Throws std::runtime_error when d(t) has the wrong size or is not finite.
  VecX prescribed(double t) const override;

 private:
  std::vector<int> nodes_;
  MatX C_;
  VecX Q_;
  std::function<VecX(double)> d_;
  double compliance_ = 0.0;
};

}  // namespace isoflex::joints
