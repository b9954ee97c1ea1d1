#include "isoflex/system/joint_drivers.hpp"

#include <utility>

namespace isoflex::system {

JointDriver::JointDriver(std::vector<int> nodes, const elements::FramePair& pair,
                         Coordinate coordinate, const VecX& q0, const std::string& expression)
    : nodes_(std::move(nodes)),
      coordinate_(coordinate),
      slide_(pair.displacement(2)),
      f_(expression) {
  if (coordinate_ == Coordinate::angle) angle_.emplace(pair, q0);
}

double JointDriver::value(CRef q_c) const {
  const VecX q = q_c;
  return angle_ ? angle_->angle(q) : slide_.value(q);
}

VecX JointDriver::constraints(CRef q_c) const {
  return VecX::Constant(1, value(q_c));
}

MatX JointDriver::jacobian(CRef q_c) const {
  const VecX q = q_c;
  return (angle_ ? angle_->gradient(q, nullptr) : slide_.gradient(q)).transpose();
}

void JointDriver::add_constraint_hessian(CRef q_c, CRef lambda, MatX& H) const {
  if (!angle_) {
    H += lambda(0) * slide_.hessian();
    return;
  }
  MatX Ha;
  angle_->gradient(VecX(q_c), &Ha);
  H += lambda(0) * Ha;
}

// DNSM-III (9)–(10) with G̃ for 𝖦: G̃ (q_b − q_a) = Φ(q_b) − Φ(q_a) exactly.
MatX JointDriver::discrete_jacobian(CRef q_a, CRef q_b) const {
  if (!angle_) return jacobian(0.5 * (q_a + q_b));
  return angle_->discrete(VecX(q_a), VecX(q_b), false).D.transpose();
}

VecX JointDriver::prescribed(double t) const {
  return VecX::Constant(1, f_(t));
}

void JointDriver::accept(CRef q_c) const {
  if (angle_) angle_->accept(VecX(q_c));
}

}  // namespace isoflex::system
