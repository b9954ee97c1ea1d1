#include "isoflex/math/rotation.hpp"

#include <cmath>

#include "isoflex/math/skew.hpp"

namespace isoflex {

namespace {
// sin(a)/a and ½ (sin(a/2)/(a/2))² = (1 − cos a)/a², written to stay accurate for small a.
struct RodriguesFactors {
  double s, c;
};
RodriguesFactors rodrigues_factors(double a) {
  const double s = a < 1e-4 ? 1.0 - a * a / 6.0 : std::sin(a) / a;
  const double h = a / 2.0;
  const double sh = h < 1e-4 ? 1.0 - h * h / 6.0 : std::sin(h) / h;
  return {s, 0.5 * sh * sh};
}
}  // namespace

Mat3 rodrigues(const Vec3& theta) {
  const auto [s, c] = rodrigues_factors(theta.norm());
  const Mat3 t = skew(theta);
  return Mat3::Identity() + s * t + c * t * t;
}

Mat3 rodrigues(const Vec3& theta, Mat3& minus_identity) {
  const auto [s, c] = rodrigues_factors(theta.norm());
  const Mat3 t = skew(theta);
  minus_identity = s * t + c * t * t;
  return Mat3::Identity() + s * t + c * t * t;  // rodrigues(θ)'s expression: the same roundings
}

Mat3 rodrigues_tangent(const Vec3& theta) {
  const double a = theta.norm();
  const Mat3 t = skew(theta);
  double c1, c2;  // (1 − cos a)/a², (a − sin a)/a³
  if (a < 1e-3) {
    const double a2 = a * a;
    c1 = 0.5 - a2 / 24.0 + a2 * a2 / 720.0;
    c2 = 1.0 / 6.0 - a2 / 120.0 + a2 * a2 / 5040.0;
  } else {
    c1 = (1.0 - std::cos(a)) / (a * a);
    c2 = (a - std::sin(a)) / (a * a * a);
  }
  return Mat3::Identity() + c1 * t + c2 * t * t;
}

}  // namespace isoflex
