#pragma once
// Frame node q = (φ, d₁, d₂, d₃) ∈ R¹² on R³ × SO(3) (DNSM-III (16)), used by rigid bodies and
// beam nodes. Twist t = (φ̇, ω) ∈ R⁶ (29).
#include "isoflex/math/types.hpp"

namespace isoflex::frame_node {
inline constexpr int kCoords = 12;
inline constexpr int kTwist = 6;
inline constexpr int kConstraints = 6;
using Q = Vec<12>;

inline Vec3 phi(const Q& q) {
  return q.segment<3>(0);
}
inline Vec3 director(const Q& q, int i) {
  return q.segment<3>(3 + 3 * i);
}
// Columns are d₁, d₂, d₃ (the rotation matrix when q lies on the manifold).
Mat3 directors(const Q& q);
Q make(const Vec3& phi, const Mat3& R);

// Internal constraints (DNSM-III (20), with the first row read as ½(d₁·d₁ − 1)).
Vec<6> constraints(const Q& q);
// Jacobian (22). Constraints are quadratic, so G(q_{n+½}) is their discrete derivative (23).
Mat<6, 12> jacobian(const Q& q);
// H += Σᵢ λᵢ ∂²Φᵢ/∂q² (constant: the constraints are quadratic).
void add_constraint_hessian(const Vec<6>& lambda, Mat<12, 12>& H);
// Internal null space (31): q̇ = P t. G(q) P(q) = 0 for every q ∈ R¹², so P(q_{n+½}) is a
// discrete null space (32).
Mat<12, 6> null_space(const Q& q);
// Nodal reparametrization (37): φ + u_φ, exp(θ̂) d_I.
Q update(const Q& qn, const Vec<6>& u);
// The same with R = rodrigues(θ) given (a caller that needs the rotation too computes it once).
Q update(const Q& qn, const Vec<6>& u, const Mat3& R);
// ∂update/∂u = P(q_{n+1}) diag(I, T(θ)).
Mat<12, 6> update_derivative(const Q& qn, const Vec<6>& u);
}  // namespace isoflex::frame_node
