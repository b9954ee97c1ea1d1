#pragma once
// AF-BS in a nonlinear analysis (IGA-thesis §5.1, (5.5b)): the forces of the bending strip of an
// interface as constraint rows, Φ(q) = s f_s(q) over the strip's control points (the interface's
// triples), with the nonlinear Kirchhoff–Love kinematics of the strip (E_s = E, β₁ = 1: the rows
// do not depend on it). Φ = 0 at the reference (the strip is unstressed there); G = s K_s(q), the
// strip's tangent; the Hessian term Σ λᵢ ∂²Φᵢ/∂q² = s D_λK_s(q) — K_s is the Hessian of the strip
// energy, so this is its derivative in the direction λ (a vector over the same coordinates),
// taken by a central difference of K_s (a third derivative of the energy the element does not
// provide). Which rows are independent changes with the configuration, and off the constraint
// manifold the strip's stress adds rank (its geometric stiffness), so the rows are chosen again
// at the start of every load step, as many as are independent at the reference (Conjecture 5.1:
// n + 1 where the patches continue flat, 3(n + 1) at a kink, less on supports; reselected(),
// System::reselected_groups(), integrate/static_equilibrium.cpp). With a compliance c > 0 they are
// the perturbed Lagrange rows s f_s − c λ = 0 of (5.24b) instead, all kept (the compliance makes
// the Newton matrix regular): λ = (s/c) f_s, a penalty on the strip forces. Static analyses only:
// the rows are neither quadratic nor given a discrete derivative.
#include <memory>
#include <vector>

#include "isoflex/elements/kl_shell_patch.hpp"
#include "isoflex/joints/constraint.hpp"

namespace isoflex::system {

class StripForceRows final : public joints::Constraint {
 public:
  // strip: the bending strip over the triples of `nodes` (three per triple, the strip's control
  // points in order); scale s of every row; compliance c (0: AF-BS).
  StripForceRows(std::shared_ptr<const elements::KLShellPatch> strip, std::vector<int> nodes,
                 double scale, double compliance = 0.0);

  const std::vector<int>& nodes() const override { return nodes_; }
  int constraint_count() const override { return static_cast<int>(3 * nodes_.size()); }
  VecX constraints(CRef q_c) const override;
  MatX jacobian(CRef q_c) const override;
  void add_constraint_hessian(CRef q_c, CRef lambda, MatX& H) const override;
  bool reselected() const override { return compliance_ == 0.0; }
  double compliance() const override { return compliance_; }

 private:
  std::shared_ptr<const elements::KLShellPatch> strip_;
  std::vector<int> nodes_;
  double scale_;
  double compliance_;
};

}  // namespace isoflex::system
