#include "isoflex/loads/body_load.hpp"

#include "isoflex/math/skew.hpp"

namespace isoflex::loads {

BodyLoad::BodyLoad(int node, const Vec3& X, std::optional<std::array<TimeFunction, 3>> force,
                   std::optional<std::array<TimeFunction, 3>> moment)
    : nodes_{node}, X_(X), force_(std::move(force)), moment_(std::move(moment)) {}

Vec3 BodyLoad::force(double t) const {
  return evaluate(force_, t);
}
Vec3 BodyLoad::moment(double t) const {
  return evaluate(moment_, t);
}

Vec<12> frame_node_force(const Vec<12>& q, const Vec3& X, const Vec3& F, const Vec3& M) {
  Vec<12> f;
  f.head<3>() = F;
  for (int I = 0; I < 3; ++I)
    f.segment<3>(3 + 3 * I) = X(I) * F + 0.5 * M.cross(q.segment<3>(3 + 3 * I));
  return f;
}

Vec<12> BodyLoad::generalized_force(const Vec<12>& q, double t) const {
  return frame_node_force(q, X_, force(t), moment(t));
}

Mat<12, 12> BodyLoad::generalized_force_derivative(double t) const {
  Mat<12, 12> K = Mat<12, 12>::Zero();
  const Mat3 S = 0.5 * skew(moment(t));
  for (int I = 0; I < 3; ++I) K.block<3, 3>(3 + 3 * I, 3 + 3 * I) = S;
  return K;
}

VecX BodyLoad::generalized_force(const VecX& x, double t) const {
  return generalized_force(Vec<12>(x), t);
}

void BodyLoad::add_generalized_force(const VecX& x, double t, VecX& g) const {
  g += generalized_force(Vec<12>(x), t);
}

void BodyLoad::add_tangent(const VecX&, double t, double scale, double* values) const {
  Eigen::Map<Mat<12, 12>>(values) += scale * generalized_force_derivative(t);
}

}  // namespace isoflex::loads
