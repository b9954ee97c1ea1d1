#include "isoflex/loads/follower_body_load.hpp"

#include "isoflex/loads/body_load.hpp"
#include "isoflex/math/skew.hpp"

namespace isoflex::loads {

FollowerBodyLoad::FollowerBodyLoad(int node, const Vec3& X,
                                   std::optional<std::array<TimeFunction, 3>> force,
                                   std::optional<std::array<TimeFunction, 3>> moment)
    : nodes_{node}, X_(X), force_(std::move(force)), moment_(std::move(moment)) {}

namespace {
// Σ_J a_J d_J: components a in the frame of the directors of q (not normalized: at q_{n+½}).
Vec3 on_directors(const Vec<12>& q, const Vec3& a) {
  return a(0) * q.segment<3>(3) + a(1) * q.segment<3>(6) + a(2) * q.segment<3>(9);
}
}  // namespace

Vec3 FollowerBodyLoad::local_force(double t) const {
  return evaluate(force_, t);
}
Vec3 FollowerBodyLoad::local_moment(double t) const {
  return evaluate(moment_, t);
}

// BodyLoad's generalized force (docs/theory/rigid-body.md §7) with the turned F and M.
Vec<12> FollowerBodyLoad::generalized_force(const Vec<12>& q, double t) const {
  return frame_node_force(q, X_, on_directors(q, local_force(t)), on_directors(q, local_moment(t)));
}

// Rows (φ, d_I), columns d_J: F_J I, X_I F_J I − ½ M_J d̂_I + δ_IJ ½ M̂ (header); the φ columns
// are zero.
Mat<12, 12> FollowerBodyLoad::generalized_force_derivative(const Vec<12>& q, double t) const {
  const Vec3 Fl = local_force(t), Ml = local_moment(t);
  const Mat3 half_M = 0.5 * skew(on_directors(q, Ml));
  Mat<12, 12> K = Mat<12, 12>::Zero();
  for (int J = 0; J < 3; ++J) {
    K.block<3, 3>(0, 3 + 3 * J).diagonal().setConstant(Fl(J));
    for (int I = 0; I < 3; ++I) {
      Mat3 B = -0.5 * Ml(J) * skew(q.segment<3>(3 + 3 * I));
      B.diagonal().array() += X_(I) * Fl(J);
      if (I == J) B += half_M;
      K.block<3, 3>(3 + 3 * I, 3 + 3 * J) = B;
    }
  }
  return K;
}

VecX FollowerBodyLoad::generalized_force(const VecX& x, double t) const {
  return generalized_force(Vec<12>(x), t);
}

void FollowerBodyLoad::add_tangent(const VecX& x, double t, double scale, double* values) const {
  Eigen::Map<Mat<12, 12>>(values) += scale * generalized_force_derivative(Vec<12>(x), t);
}

}  // namespace isoflex::loads
