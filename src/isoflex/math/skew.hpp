#pragma once
#include "isoflex/math/types.hpp"

namespace isoflex {
// skew(a) b = a × b (DNSM-III writes â).
inline Mat3 skew(const Vec3& a) {
  Mat3 s;
  s << 0.0, -a.z(), a.y(), a.z(), 0.0, -a.x(), -a.y(), a.x(), 0.0;
  return s;
}
}  // namespace isoflex
