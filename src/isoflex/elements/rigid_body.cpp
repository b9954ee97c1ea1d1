#include "isoflex/elements/rigid_body.hpp"

namespace isoflex::elements {

RigidBody::RigidBody(int node, double mass, const Vec3& J, const Vec3& gravity)
    : nodes_{node}, m_(mass), E_(euler_tensor(J)), g_(gravity) {}

Vec3 RigidBody::euler_tensor(const Vec3& J) {
  return Vec3::Constant(0.5 * J.sum()) - J;
}

double RigidBody::potential(const VecX& q) const {
  return -m_ * g_.dot(q.head<3>());
}

VecX RigidBody::gradient(const VecX&) const {
  VecX g = VecX::Zero(12);
  g.head<3>() = -m_ * g_;
  return g;
}

VecX RigidBody::discrete_gradient(const VecX& qn, const VecX&, MatX* dv_dqn1) const {
  if (dv_dqn1) dv_dqn1->setZero(12, 12);
  return gradient(qn);
}

void RigidBody::add_discrete_gradient(const VecX&, const VecX&, VecX& dv, MatX* dv_dqn1) const {
  if (dv_dqn1) dv_dqn1->setZero(12, 12);
  dv.head<3>() += -m_ * g_;  // gradient(): gravity only, constant
}

MatX RigidBody::mass() const {
  VecX d(12);
  d << Vec3::Constant(m_), Vec3::Constant(E_(0)), Vec3::Constant(E_(1)), Vec3::Constant(E_(2));
  return d.asDiagonal();
}

}  // namespace isoflex::elements
