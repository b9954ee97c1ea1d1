#include "isoflex/elements/frame_pair.hpp"

namespace isoflex::elements {

QuadraticInvariant& QuadraticInvariant::add(double w, const AffineVector& u,
                                            const AffineVector& v) {
  terms_.push_back({w, u, v});
  const MatX PuPv = u.P.transpose() * v.P;
  H_ += w * (PuPv + PuPv.transpose());
  return *this;
}

double QuadraticInvariant::value(const VecX& q) const {
  double pi = 0.0;
  for (const Term& t : terms_) pi += t.w * t.u(q).dot(t.v(q));
  return pi;
}

VecX QuadraticInvariant::gradient(const VecX& q) const {
  VecX g = VecX::Zero(H_.rows());
  for (const Term& t : terms_) g += t.w * (t.u.P.transpose() * t.v(q) + t.v.P.transpose() * t.u(q));
  return g;
}

FramePair::FramePair(const AttachedFrame& a, const AttachedFrame& b)
    : size_(12 * ((a.ground ? 0 : 1) + (b.ground ? 0 : 1))) {
  int offset = 0;
  for (int side = 0; side < 2; ++side) {
    const AttachedFrame& f = side == 0 ? a : b;
    AffineVector& x = point_[side];
    x.P = Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, size_);
    for (auto& e : axis_[side]) e.P = x.P;
    if (f.ground) {
      x.c = f.X;
      for (int k = 0; k < 3; ++k) axis_[side][k].c = f.C.col(k);
      continue;
    }
    // x = φ + X_I d_I, e_k = C_Ik d_I.
    x.P.middleCols<3>(offset) = Mat3::Identity();
    for (int I = 0; I < 3; ++I) {
      x.P.middleCols<3>(offset + 3 + 3 * I) = f.X(I) * Mat3::Identity();
      for (int k = 0; k < 3; ++k)
        axis_[side][k].P.middleCols<3>(offset + 3 + 3 * I) = f.C(I, k) * Mat3::Identity();
    }
    offset += 12;
  }
}

QuadraticInvariant FramePair::axis_product(int i, int j) const {
  return QuadraticInvariant(size_).add(1.0, axis_[0][i], axis_[1][j]);
}

QuadraticInvariant FramePair::displacement(int k) const {
  return QuadraticInvariant(size_)
      .add(1.0, axis_[0][k], point_[1])
      .add(-1.0, axis_[0][k], point_[0]);
}

QuadraticInvariant FramePair::rotation(int k) const {
  const int i = (k + 1) % 3, j = (k + 2) % 3;
  return QuadraticInvariant(size_)
      .add(0.5, axis_[0][j], axis_[1][i])
      .add(-0.5, axis_[0][i], axis_[1][j]);
}

}  // namespace isoflex::elements
