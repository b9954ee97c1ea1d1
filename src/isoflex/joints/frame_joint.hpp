#pragma once
// Joints between two frame nodes (rigid bodies, beam nodes) or a frame node and the ground.
//
// Every joint is described by the same few ingredients (docs/theory/joints.md derives them):
//   body-fixed joint frames a_k = C_A(I,k) d_I^A on the parent A and b_k = C_B(I,k) d_I^B on the
//   child B, coinciding at t = 0, and joint points x_A = φ_A + ρ_A, x_B = φ_B + ρ_B
//   (ρ = X_I d_I), r = x_B − x_A;
//   constraint rows of three kinds, all at most quadratic in q (so 𝖦 = G(q_{n+½}), DNSM-III (23)):
//     point coincidence x_B − x_A (3 rows), frame products a_i·b_j, plane rows r·a_i;
//   a velocity analysis t_B = A(q) t_A + B(q) τ that makes G(q)·P(q) vanish identically on R²⁴,
//   not only on the constraint manifold, so that the midpoint evaluation is a discrete null space
//   (DNSM-III Table 3, iii.1);
//   an update map q_B,n+1 = F(q_A,n+1, q_A,n, q_B,n, τ-increments) that keeps every row at zero.
#include <vector>

#include "isoflex/joints/joint.hpp"
#include "isoflex/math/frame_node.hpp"
#include "isoflex/math/types.hpp"

namespace isoflex::joints {

enum class Kind {
  spherical,
  revolute,
  prismatic,
  cylindrical,
  planar,
  universal,
  rigid,
  point_on_line,
};

struct FrameJointGeometry {
  Vec3 X_A = Vec3::Zero();      // joint point in parent body coordinates
  Mat3 C_A = Mat3::Identity();  // joint frame (columns a₁ a₂ a₃) in parent body coordinates
  Vec3 X_B = Vec3::Zero();
  Mat3 C_B = Mat3::Identity();
};

class FrameJoint final : public Joint {
 public:
  using Q = frame_node::Q;
  // Up to two directions, the columns (joint axes, slide directions; no heap allocation).
  using Directions = Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::ColMajor, 3, 2>;
  FrameJoint(Kind kind, const FrameJointGeometry& g);

  Kind kind() const { return kind_; }
  const FrameJointGeometry& geometry() const { return g_; }
  NodeKind parent_kind() const override { return NodeKind::frame; }
  NodeKind child_kind() const override { return NodeKind::frame; }
  int constraint_count() const override { return m_; }
  int freedom_count() const override { return r_; }  // joint velocities τ
  // Entries of τ that are a rotation vector θ ∈ R³ (updated by Rodrigues): their position or −1.
  int rotation_vector_offset() const { return rotvec_; }

  VecX constraints(CRef qa, CRef qb) const override;
  // [∂Φ/∂q_A, ∂Φ/∂q_B], m × 24 (m ≤ 6; the fixed-size form allocates nothing).
  using Rows = Eigen::Matrix<double, Eigen::Dynamic, 24, Eigen::ColMajor, 6, 24>;
  Rows fixed_jacobian(const Q& qa, const Q& qb) const;
  MatX jacobian(CRef qa, CRef qb) const override;
  // H += Σ λᵢ ∂²Φᵢ/∂(q_A,q_B)², 24 × 24 (constant).
  void add_constraint_hessian(CRef lambda, Mat<24, 24>& H) const;
  void add_constraint_hessian(CRef lambda, MatX& H) const override;

  // Velocity analysis: t_B = A t_A + B τ (t = (φ̇, ω)).
  Mat<6, 6> parent_block(CRef qa, CRef qb) const override;
  FreedomBlock freedom_block(CRef qa, CRef qb) const override;  // 6 × r

  // Update map: child configuration at t_{n+1} from the parent at t_n and t_{n+1}, the child at
  // t_n and the joint increments. ∂q_B/∂(t_A, τ) equals P_int(q_B) [A B] at t_{n+1} with θ-columns
  // multiplied by T(θ) (rotation_vector_offset). Q_A is the parent's rotation over the step
  // (Q_A R_A,n = R_A,n+1); `step_b` receives the child's.
  Q update(const Q& qa_n, const Q& qa_n1, const Mat3& QA, const Q& qb_n, const VecX& tau,
           Mat3* step_b = nullptr) const;
  using Joint::update;
  NodeVec update(CRef qa_n, CRef qa_n1, const Mat3& step_a, CRef qb_n, CRef tau, Mat3* step_b,
                 const StepIncrement* parent, StepIncrement* child) const override;
  FreedomBlock update_freedom_block(CRef qa_n1, CRef qb_n, CRef qb_n1, CRef tau) const override;

 private:
  struct FrameVectors {
    Vec3 x_a, x_b, rho_a, rho_b, r;
    Mat3 a, b;  // columns a_k, b_k
  };
  FrameVectors vectors(const Q& qa, const Q& qb) const;
  Q fixed_update(const Q& qa_n, const Q& qa_n1, const Mat3& QA, const Q& qb_n, CRef tau,
                 Mat3* step_b, const StepIncrement* parent = nullptr,
                 StepIncrement* child = nullptr) const;  // update() without copying τ
  Directions translation_directions(const Mat3& a) const;

  Kind kind_;
  FrameJointGeometry g_;
  Mat3 locked_;  // C_A C_Bᵀ: R_B = R_A C_A C_Bᵀ where the rotation is locked
  int m_ = 0, r_ = 0, rotvec_ = -1;
  bool point_rows_ = false;                      // x_B − x_A = 0
  bool slides_ = false;                          // plane rows r·a_i (translation freedoms)
  std::vector<int> plane_rows_;                  // i of r·a_i
  std::vector<std::pair<int, int>> frame_rows_;  // (i, j) of a_i·b_j
};

// Joint frames of a joint whose global frame E (columns) and point p are given at t = 0, for
// parent and child in their initial configurations (ground: φ = 0, d = I).
FrameJointGeometry geometry_from_global(const frame_node::Q& qa0, const frame_node::Q& qb0,
                                        const Vec3& p, const Mat3& E);

}  // namespace isoflex::joints
