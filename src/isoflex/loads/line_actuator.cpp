#include "isoflex/loads/line_actuator.hpp"

#include <stdexcept>
#include <utility>

namespace isoflex::loads {

LineActuator::LineActuator(std::vector<int> nodes, Eigen::Matrix<double, 3, Eigen::Dynamic> D,
                           const Vec3& e, TimeFunction force, const VecX& x0)
    : nodes_(std::move(nodes)), D_(std::move(D)), e_(e), force_(std::move(force)) {
  if (D_.cols() != x0.size())
    throw std::invalid_argument("LineActuator: the point map's width differs from x");
  if (!((D_ * x0 + e_).norm() > 0.0))
    throw std::invalid_argument(
        "the two points of the actuator coincide at the start, so the line of its force is "
        "undefined");
}

VecX LineActuator::generalized_force(const VecX& x, double t) const {
  const Vec3 d = D_ * x + e_;
  return D_.transpose() * (-force_(t) / d.norm() * d);
}

void LineActuator::add_tangent(const VecX& x, double t, double scale, double* values) const {
  const Vec3 d = D_ * x + e_;
  const double z = d.norm();
  const VecX Dd = D_.transpose() * d;
  Eigen::Map<MatX> K(values, D_.cols(), D_.cols());  // the dense pattern, column-major
  K -= (scale * force_(t) / z) * (D_.transpose() * D_ - Dd * Dd.transpose() / (z * z));
}

}  // namespace isoflex::loads
