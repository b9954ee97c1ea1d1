#include "isoflex/loads/director_node_load.hpp"

#include "isoflex/math/skew.hpp"

namespace isoflex::loads {

DirectorNodeLoad::DirectorNodeLoad(int node, std::optional<std::array<TimeFunction, 3>> force,
                                   std::optional<std::array<TimeFunction, 3>> moment)
    : nodes_{node}, force_(std::move(force)), moment_(std::move(moment)) {}

Vec<6> DirectorNodeLoad::generalized_force(const Vec<6>& q, double t) const {
  Vec<6> f;
  f << evaluate(force_, t), evaluate(moment_, t).cross(q.tail<3>());
  return f;
}

Mat<6, 6> DirectorNodeLoad::generalized_force_derivative(double t) const {
  Mat<6, 6> K = Mat<6, 6>::Zero();
  K.bottomRightCorner<3, 3>() = skew(evaluate(moment_, t));
  return K;
}

VecX DirectorNodeLoad::generalized_force(const VecX& x, double t) const {
  return generalized_force(Vec<6>(x), t);
}

void DirectorNodeLoad::add_tangent(const VecX&, double t, double scale, double* values) const {
  Eigen::Map<Mat<6, 6>>(values) += scale * generalized_force_derivative(t);
}

}  // namespace isoflex::loads
