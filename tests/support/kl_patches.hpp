#pragma once
// Kirchhoff–Love patches, deformations and momentum sums shared by the tests of the patch's
// discrete gradient and viscous forces (tests/elements/test_kl_shell_*.cpp).
#include <random>

#include "isoflex/elements/kl_shell_patch.hpp"
#include "isoflex/geometry/builders.hpp"
#include "isoflex/geometry/refinement.hpp"
#include "support/finite_difference.hpp"
#include "support/geometry.hpp"

namespace isoflex::test {

inline elements::KLShellSection section(double t = 0.1) {
  elements::KLShellSection s;
  s.young = 1.0e3;
  s.poisson = 0.3;
  s.thickness = t;
  s.density = 1.0;
  return s;
}

// Rational cylinder sector (80°, radius 1, length 1.2) at degree (p, p), 3 × 2 elements, control
// points moved randomly by up to 0.03.
inline geometry::NurbsSurface curved_patch(std::mt19937& g, int p) {
  geometry::NurbsSurface s = geometry::cylinder_sector(1.0, 1.2, 80.0 * kPi / 180.0);
  s = geometry::k_refine(s, p - 2, p - 1, 2, 1);
  for (auto& q : s.points) q += random_vector(g, 3, 0.03);
  return s;
}

// x_A = Q X_A + c for every control point.
inline VecX affine(const VecX& X, const Mat3& Q, const Vec3& c = Vec3::Zero()) {
  VecX x(X.size());
  for (int i = 0; i < X.size() / 3; ++i) x.segment<3>(3 * i) = Q * X.segment<3>(3 * i) + c;
  return x;
}

// A large deformation of X: a finite rotation of a stretched and sheared copy (F = I + 0.2·random)
// plus random control-point moves of `jitter` (about 10–30 % of the patch size in all).
inline VecX deformed(std::mt19937& g, const VecX& X, double jitter = 0.05) {
  const Mat3 F = Mat3::Identity() + 0.2 * Eigen::Map<const Mat3>(random_vector(g, 9).data());
  return affine(affine(X, F), random_rotation(g), random_vector(g, 3, 0.5)) +
         random_vector(g, static_cast<int>(X.size()), jitter);
}

// Σ_A v_A and Σ_A x_A × v_A.
inline Vec3 sum(const VecX& v) {
  Vec3 s = Vec3::Zero();
  for (int i = 0; i < v.size() / 3; ++i) s += v.segment<3>(3 * i);
  return s;
}
inline Vec3 moment(const VecX& x, const VecX& v) {
  Vec3 s = Vec3::Zero();
  for (int i = 0; i < v.size() / 3; ++i) s += x.segment<3>(3 * i).cross(v.segment<3>(3 * i));
  return s;
}
// Σ_A |v_A| and Σ_A |x_A||v_A|: the scales the two sums cancel from.
inline double abs_sum(const VecX& v) {
  double s = 0.0;
  for (int i = 0; i < v.size() / 3; ++i) s += v.segment<3>(3 * i).norm();
  return s;
}
inline double abs_moment(const VecX& x, const VecX& v) {
  double s = 0.0;
  for (int i = 0; i < v.size() / 3; ++i)
    s += x.segment<3>(3 * i).norm() * v.segment<3>(3 * i).norm();
  return s;
}

inline MatX dense(const elements::SpMat& K) {
  return MatX(K);
}

}  // namespace isoflex::test
