#pragma once
// Rows at most quadratic in the stacked coordinates of some nodes, Φ_r(q) = ½ qᵀ H_r q + b_rᵀ q
// + c_r: the joints at a point of a Kirchhoff–Love patch (system_compile.cpp), whose rows are the
// coincidence of two material points (linear: the patch's Σ R_A φ_A and a body's φ + X_I d_I) and
// dot products of two material vectors (bilinear: a patch tangent Σ R_A,α φ_A and a body vector
// Y_I d_I). Constant Hessians H_r; the Jacobian at the midpoint is an exact discrete derivative
// (DNSM-III (9)–(10)), so the rows hold at every time node and their forces do no work.
#include <vector>

#include "isoflex/joints/constraint.hpp"

namespace isoflex::joints {

class QuadraticRows final : public Constraint {
 public:
  // H: one symmetric n × n matrix per row (empty for a linear row), B: rows × n, c: rows entries,
  // n the stacked coordinates of `nodes`. Throws std::invalid_argument for inconsistent sizes, a
  // non-symmetric H_r or non-finite entries.
  QuadraticRows(std::vector<int> nodes, std::vector<MatX> H, MatX B, VecX c);

  const std::vector<int>& nodes() const override { return nodes_; }
  int constraint_count() const override { return static_cast<int>(B_.rows()); }
  VecX constraints(CRef q_c) const override;
  MatX jacobian(CRef q_c) const override;
  void add_constraint_hessian(CRef q_c, CRef lambda, MatX& H) const override;

 private:
  std::vector<int> nodes_;
  std::vector<MatX> H_;
  MatX B_;
  VecX c_;
};

}  // namespace isoflex::joints
