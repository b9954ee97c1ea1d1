#pragma once
// Exponential map on SO(3) and its derivative.
#include "isoflex/math/types.hpp"

namespace isoflex {
// Rodrigues formula, DNSM-III (35): exp(θ̂).
Mat3 rodrigues(const Vec3& theta);

// Left tangent operator T(θ): δ(exp(θ̂) v) = (T(θ) δθ) × (exp(θ̂) v).
// T = I + (1 − cos|θ|)/|θ|² θ̂ + (|θ| − sin|θ|)/|θ|³ θ̂².
Mat3 rodrigues_tangent(const Vec3& theta);
}  // namespace isoflex
