#pragma once
// Exponential map on SO(3) and its derivative.
#include "isoflex/math/types.hpp"

namespace isoflex {
// Rodrigues formula, DNSM-III (35): exp(θ̂).
Mat3 rodrigues(const Vec3& theta);

// (exp(θ̂) − I) v, without forming exp(θ̂) v and subtracting v: its round-off is ε|θ||v|, not ε|v|
// (the velocities of a step, NodeType::root_increment).
Vec3 rotation_increment(const Vec3& theta, const Vec3& v);

// Left tangent operator T(θ): δ(exp(θ̂) v) = (T(θ) δθ) × (exp(θ̂) v).
// T = I + (1 − cos|θ|)/|θ|² θ̂ + (|θ| − sin|θ|)/|θ|³ θ̂².
Mat3 rodrigues_tangent(const Vec3& theta);
}  // namespace isoflex
