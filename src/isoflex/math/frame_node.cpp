#include "isoflex/math/frame_node.hpp"

#include "isoflex/math/rotation.hpp"
#include "isoflex/math/skew.hpp"

namespace isoflex::frame_node {

Mat3 directors(const Q& q) {
  Mat3 R;
  for (int i = 0; i < 3; ++i) R.col(i) = director(q, i);
  return R;
}

Q make(const Vec3& phi, const Mat3& R) {
  Q q;
  q << phi, R.col(0), R.col(1), R.col(2);
  return q;
}

Vec<6> constraints(const Q& q) {
  const Vec3 d1 = director(q, 0), d2 = director(q, 1), d3 = director(q, 2);
  Vec<6> c;
  c << 0.5 * (d1.dot(d1) - 1.0), 0.5 * (d2.dot(d2) - 1.0), 0.5 * (d3.dot(d3) - 1.0), d1.dot(d2),
      d1.dot(d3), d2.dot(d3);
  return c;
}

Mat<6, 12> jacobian(const Q& q) {
  const Vec3 d1 = director(q, 0), d2 = director(q, 1), d3 = director(q, 2);
  Mat<6, 12> G = Mat<6, 12>::Zero();
  G.block<1, 3>(0, 3) = d1.transpose();
  G.block<1, 3>(1, 6) = d2.transpose();
  G.block<1, 3>(2, 9) = d3.transpose();
  G.block<1, 3>(3, 3) = d2.transpose();
  G.block<1, 3>(3, 6) = d1.transpose();
  G.block<1, 3>(4, 3) = d3.transpose();
  G.block<1, 3>(4, 9) = d1.transpose();
  G.block<1, 3>(5, 6) = d3.transpose();
  G.block<1, 3>(5, 9) = d2.transpose();
  return G;
}

void add_constraint_hessian(const Vec<6>& l, Mat<12, 12>& H) {
  const Mat3 I = Mat3::Identity();
  for (int i = 0; i < 3; ++i) H.block<3, 3>(3 + 3 * i, 3 + 3 * i) += l(i) * I;
  const int pairs[3][2] = {{0, 1}, {0, 2}, {1, 2}};
  for (int k = 0; k < 3; ++k) {
    const int a = 3 + 3 * pairs[k][0], b = 3 + 3 * pairs[k][1];
    H.block<3, 3>(a, b) += l(3 + k) * I;
    H.block<3, 3>(b, a) += l(3 + k) * I;
  }
}

Mat<12, 6> null_space(const Q& q) {
  Mat<12, 6> P = Mat<12, 6>::Zero();
  P.block<3, 3>(0, 0).setIdentity();
  for (int i = 0; i < 3; ++i) P.block<3, 3>(3 + 3 * i, 3) = -skew(director(q, i));
  return P;
}

Q update(const Q& qn, const Vec<6>& u) {
  return update(qn, u, rodrigues(u.tail<3>()));
}

Q update(const Q& qn, const Vec<6>& u, const Mat3& R) {
  Q q;
  q.head<3>() = qn.head<3>() + u.head<3>();
  for (int i = 0; i < 3; ++i) q.segment<3>(3 + 3 * i) = R * director(qn, i);
  return q;
}

Mat<12, 6> update_derivative(const Q& qn, const Vec<6>& u) {
  Mat<12, 6> D = null_space(update(qn, u));
  D.rightCols<3>() = D.rightCols<3>() * rodrigues_tangent(u.tail<3>());
  return D;
}

}  // namespace isoflex::frame_node
