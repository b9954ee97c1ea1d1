#pragma once
// Two frames, each fixed in a frame node (a rigid body, a beam node) or in space, and the scalar
// invariants of their relative position that are quadratic in the coordinates (docs/theory/
// coupling.md §7–§8): the force elements of bushings and joint springs are functions of them.
//
// A frame node has q = (φ, d₁, d₂, d₃); a frame attached to it at body coordinates X with axes
// C (columns, body coordinates) has the point x = φ + X_I d_I and the axes e_k = C_Ik d_I, both
// LINEAR in q (DNSM-III (2)); a frame of the ground is constant. So every product of two of these
// vectors, and every sum of such products, is a quadratic function π(q) = ½ qᵀ H q + gᵀ q + π₀
// with a constant Hessian H, and its gradient at the midpoint is exact for its increment:
// ∇π(q_{n+½})·(qₙ₊₁ − qₙ) = π(qₙ₊₁) − π(qₙ) (DNSM-III (23)). A product of two vectors that both
// turn and move with the nodes is invariant under rigid motions of the pair.
#include <array>
#include <vector>

#include "isoflex/math/types.hpp"

namespace isoflex::elements {

// A frame fixed in a frame node (X, C in its body coordinates) or, with `ground`, in space (X, C
// global).
struct AttachedFrame {
  Vec3 X = Vec3::Zero();
  Mat3 C = Mat3::Identity();
  bool ground = false;
};

// v(q) = P q + c over the stacked coordinates of the pair's nodes.
struct AffineVector {
  Eigen::Matrix<double, 3, Eigen::Dynamic> P;
  Vec3 c = Vec3::Zero();
  Vec3 operator()(const VecX& q) const { return P * q + c; }
};

// π(q) = Σ_t w_t u_t(q)·v_t(q): value, gradient Σ w (P_uᵀ v + P_vᵀ u) and the constant Hessian
// Σ w (P_uᵀ P_v + P_vᵀ P_u).
class QuadraticInvariant {
 public:
  explicit QuadraticInvariant(int size = 0) : H_(MatX::Zero(size, size)) {}
  QuadraticInvariant& add(double w, const AffineVector& u, const AffineVector& v);
  double value(const VecX& q) const;
  VecX gradient(const VecX& q) const;
  const MatX& hessian() const { return H_; }

 private:
  struct Term {
    double w;
    AffineVector u, v;
  };
  std::vector<Term> terms_;
  MatX H_;
};

// The frames a (on the parent side) and b: their points and axes as affine maps of the stacked
// coordinates of the frame nodes that are not the ground, a's node first (12 or 24 coordinates).
class FramePair {
 public:
  FramePair(const AttachedFrame& a, const AttachedFrame& b);
  int size() const { return size_; }
  const AffineVector& point(int side) const { return point_[side]; }  // 0: a, 1: b
  const AffineVector& axis(int side, int k) const { return axis_[side][k]; }
  // a_i·b_j.
  QuadraticInvariant axis_product(int i, int j) const;
  // u_k = a_k·(x_b − x_a): the displacement of b's point from a's in a's frame.
  QuadraticInvariant displacement(int k) const;
  // θ_k = ½ (a_j·b_i − a_i·b_j), (i, j, k) cyclic: the axial vector of the skew part of the
  // relative rotation R = [a_i·b_j] in a's frame, sin φ n for a rotation by φ about n (θ for
  // small rotations).
  QuadraticInvariant rotation(int k) const;

 private:
  int size_ = 0;
  std::array<AffineVector, 2> point_;
  std::array<std::array<AffineVector, 3>, 2> axis_;
};

}  // namespace isoflex::elements
