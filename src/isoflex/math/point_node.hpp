#pragma once
// Point node q = φ ∈ R³ (an IGA control point or a particle): no internal constraints, null space
// P = I, update φ + u (docs/architecture.md, node kinds).
#include "isoflex/math/types.hpp"

namespace isoflex::point_node {
inline constexpr int kCoords = 3;
inline constexpr int kTwist = 3;
inline constexpr int kConstraints = 0;
using Q = Vec<3>;

inline Mat3 null_space(const Q&) {
  return Mat3::Identity();
}
inline Q update(const Q& qn, const Vec3& u) {
  return qn + u;
}
inline Mat3 update_derivative(const Q&, const Vec3&) {
  return Mat3::Identity();
}
}  // namespace isoflex::point_node
