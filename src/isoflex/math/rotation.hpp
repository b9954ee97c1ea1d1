#pragma once
// Exponential map on SO(3) and its derivative.
#include "isoflex/math/types.hpp"

namespace isoflex {
// Rodrigues formula, DNSM-III (35): exp(θ̂).
Mat3 rodrigues(const Vec3& theta);

// The same with exp(θ̂) − I = (sin a/a) θ̂ + ((1 − cos a)/a²) θ̂² (a = |θ|) from the same factors, to
// the precision of its own entries (~|θ|), not of I: (exp(θ̂) − I) v is a rotated vector's
// increment without subtracting rounded vectors (the velocities of a step, NodeType::root_update).
Mat3 rodrigues(const Vec3& theta, Mat3& minus_identity);
// The same where exp(θ̂) − I is wanted only if `minus_identity` is given (the rotation is the
// same bit for bit either way).
inline Mat3 rodrigues(const Vec3& theta, Mat3* minus_identity) {
  return minus_identity ? rodrigues(theta, *minus_identity) : rodrigues(theta);
}

// The increment of a product of two rotations from theirs: (I + A)(I + B) − I = A + B + AB, as
// accurate as A and B (no identity subtracted; the joints' step rotations, joints/joint.hpp).
inline Mat3 compose_increments(const Mat3& A, const Mat3& B) {
  return A + B + A * B;
}

// Left tangent operator T(θ): δ(exp(θ̂) v) = (T(θ) δθ) × (exp(θ̂) v).
// T = I + (1 − cos|θ|)/|θ|² θ̂ + (|θ| − sin|θ|)/|θ|³ θ̂².
Mat3 rodrigues_tangent(const Vec3& theta);
}  // namespace isoflex
