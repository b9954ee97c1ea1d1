#pragma once
// Joints whose child is a point node q = φ ∈ R³ (an IGA control point of a Kirchhoff–Love patch,
// a particle), against the generic contract joints/joint.hpp. The derivation, and why
// G(q)·P(q) = 0 on all of R^{n_A + n_B}, are in docs/theory/point-joints.md.
//
//   PointOnFrame   frame parent (body, beam node or ground), point child fixed to it   m 3, r 0
//                  (with the ground as parent: a fixed point)
//
// A point node has 3 velocities (φ̇) and P_int(q) = [I 0] in twist form: it ignores ω, so its
// rows and freedoms always add up to 3.
#include "isoflex/joints/joint.hpp"
#include "isoflex/math/frame_node.hpp"
#include "isoflex/math/types.hpp"

namespace isoflex::joints {

// A point node B rigidly attached to a frame node A (a body, a beam node or the ground, the frame
// at the origin with identity directors). Rows Φ = φ_B − φ_A − X_I d_I^A (3, linear in q), with
// the body coordinates X = D_A0ᵀ(φ_B0 − φ_A0) from t = 0. No freedoms:
// φ̇_B = φ̇_A + ω_A × (X_I d_I^A), ω_B = ω_A.
class PointOnFrame final : public Joint {
 public:
  // Throws std::invalid_argument if qa0 or phi_b0 has a non-finite entry.
  PointOnFrame(const frame_node::Q& qa0, const Vec3& phi_b0);

  NodeKind parent_kind() const override { return NodeKind::frame; }
  NodeKind child_kind() const override { return NodeKind::point; }
  int constraint_count() const override { return 3; }
  int freedom_count() const override { return 0; }
  VecX constraints(CRef qa, CRef qb) const override;
  MatX jacobian(CRef qa, CRef qb) const override;  // constant: [−I, −X₁I, −X₂I, −X₃I, I]
  void add_constraint_hessian(CRef lambda, MatX& H) const override;  // adds nothing (linear rows)
  Mat<6, 6> parent_block(CRef qa, CRef qb) const override;
  FreedomBlock freedom_block(CRef qa, CRef qb) const override;  // 6 × 0
  using Joint::update;
  NodeVec update(CRef qa_n, CRef qa_n1, const Mat3& step_a, CRef qb_n, CRef tau, Mat3* step_b,
                 const StepIncrement* parent, StepIncrement* child) const override;
  FreedomBlock update_freedom_block(CRef qa_n1, CRef qb_n, CRef qb_n1,
                                    CRef tau) const override;  // 6 × 0

  const Vec3& body_point() const { return X_; }  // X, in A's body coordinates

 private:
  Vec3 X_;
};

}  // namespace isoflex::joints
