#include "isoflex/math/director_node.hpp"

#include <cmath>

#include "isoflex/math/rotation.hpp"
#include "isoflex/math/skew.hpp"

namespace isoflex::director_node {

Mat<3, 2> tangent_basis(const Vec3& d) {
  const Vec3 n = d.normalized();
  Vec3 a = std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  const Vec3 d1 = (a - a.dot(n) * n).normalized();
  Mat<3, 2> B;
  B.col(0) = d1;
  B.col(1) = n.cross(d1);
  return B;
}

double constraint(const Q& q) {
  return 0.5 * (q.tail<3>().squaredNorm() - 1.0);
}

Mat<1, 6> jacobian(const Q& q) {
  Mat<1, 6> G = Mat<1, 6>::Zero();
  G.rightCols<3>() = q.tail<3>().transpose();
  return G;
}

Mat<6, 5> null_space(const Mat<3, 2>& basis) {
  Mat<6, 5> P = Mat<6, 5>::Zero();
  P.topLeftCorner<3, 3>().setIdentity();
  P.bottomRightCorner<3, 2>() = basis;
  return P;
}

Mat<6, 5> discrete_null_space(const Q& qn, const Mat<3, 2>& basis_n, const Q& qn1) {
  const Vec3 dn = qn.tail<3>();
  const Vec3 dm = 0.5 * (dn + qn1.tail<3>());
  Mat<3, 2> t;
  for (int k = 0; k < 2; ++k) t.col(k) = basis_n.col(k) - basis_n.col(k).dot(dm) / dn.dot(dm) * dn;
  return null_space(t);
}

namespace {
// exp_d(v) = cos|v| d + sin|v|/|v| v (54), with its Jacobian w.r.t. v.
Vec3 sphere_exp(const Vec3& d, const Vec3& v, Mat3* J) {
  const double a = v.norm();
  const double s = a < 1e-4 ? 1.0 - a * a / 6.0 : std::sin(a) / a;
  if (J) {
    const double c =
        a < 1e-3 ? -1.0 / 3.0 + a * a / 30.0 : (a * std::cos(a) - std::sin(a)) / (a * a * a);
    *J = -s * d * v.transpose() + s * Mat3::Identity() + c * v * v.transpose();
  }
  return std::cos(a) * d + s * v;
}
}  // namespace

Q update(const Q& qn, const Mat<3, 2>& basis_n, const Vec<5>& u) {
  Q q;
  q.head<3>() = qn.head<3>() + u.head<3>();
  q.tail<3>() = sphere_exp(qn.tail<3>(), basis_n * u.tail<2>(), nullptr);
  return q;
}

Mat<6, 5> update_derivative(const Q& qn, const Mat<3, 2>& basis_n, const Vec<5>& u) {
  Mat3 J;
  sphere_exp(qn.tail<3>(), basis_n * u.tail<2>(), &J);
  Mat<6, 5> D = Mat<6, 5>::Zero();
  D.topLeftCorner<3, 3>().setIdentity();
  D.bottomRightCorner<3, 2>() = J * basis_n;
  return D;
}

Mat<6, 6> twist_null_space(const Q& q) {
  Mat<6, 6> P = Mat<6, 6>::Zero();
  P.topLeftCorner<3, 3>().setIdentity();
  P.bottomRightCorner<3, 3>() = -skew(Vec3(q.tail<3>()));
  return P;
}

namespace {
// [d₂ −d₁]: the ω of the unit θ̇₁, θ̇₂ (45).
Mat<3, 2> rotation_axes(const Vec3& d) {
  const Mat<3, 2> b = tangent_basis(d);
  Mat<3, 2> w;
  w << b.col(1), -b.col(0);
  return w;
}
}  // namespace

Mat<6, 5> root_block(const Q& q) {
  Mat<6, 5> B = Mat<6, 5>::Zero();
  B.topLeftCorner<3, 3>().setIdentity();
  B.bottomRightCorner<3, 2>() = rotation_axes(q.tail<3>());
  return B;
}

Q root_update(const Q& qn, const Vec<5>& u, Mat3* step, Q* increment, Mat3* step_increment) {
  const Vec3 theta = rotation_axes(qn.tail<3>()) * u.tail<2>();
  Mat3 A;
  const Mat3 R = rodrigues(theta, increment || step_increment ? &A : nullptr);
  if (step) *step = R;
  if (increment) *increment << u.head<3>(), A * qn.tail<3>();
  if (step_increment) *step_increment = A;
  Q q;
  q << qn.head<3>() + u.head<3>(), R * qn.tail<3>();
  return q;
}

void transport_increments(const Q& qn, const Q& q1, Eigen::Ref<VecX> u) {
  const Vec3 theta = rotation_axes(qn.tail<3>()) * u.tail<2>();
  u.tail<2>() = rotation_axes(q1.tail<3>()).transpose() * theta;
}

Mat<6, 5> root_update_block(const Q& qn, const Vec<5>& u) {
  const Mat<3, 2> w = rotation_axes(qn.tail<3>());
  Mat<6, 5> B = Mat<6, 5>::Zero();
  B.topLeftCorner<3, 3>().setIdentity();
  B.bottomRightCorner<3, 2>() = rodrigues_tangent(w * u.tail<2>()) * w;
  return B;
}

}  // namespace isoflex::director_node
