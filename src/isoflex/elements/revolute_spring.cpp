#include "isoflex/elements/revolute_spring.hpp"

#include <cmath>
#include <stdexcept>
#include <utility>

namespace isoflex::elements {

RevoluteSpring::RevoluteSpring(std::vector<int> nodes, const FramePair& frames, double stiffness,
                               double damping, double free_angle, const VecX& q0)
    : nodes_(std::move(nodes)),
      n_(frames.size()),
      angle_(frames, q0),
      stiffness_(stiffness),
      damping_(damping),
      free_angle_(free_angle) {
  if (!(stiffness >= 0.0) || !(damping >= 0.0) || !std::isfinite(stiffness) ||
      !std::isfinite(damping) || !std::isfinite(free_angle))
    throw std::invalid_argument("RevoluteSpring: stiffness and damping must be finite and ≥ 0");
}

double RevoluteSpring::angle(const VecX& q) const {
  return angle_.angle(q);
}

double RevoluteSpring::potential(const VecX& q) const {
  const double d = angle(q) - free_angle_;
  return 0.5 * stiffness_ * d * d;
}

VecX RevoluteSpring::gradient(const VecX& q) const {
  return (stiffness_ * (angle(q) - free_angle_)) * angle_.gradient(q, nullptr);
}

// DV = k (θ̄ − θ₀) Dθ (header). ∂DV/∂qₙ₊₁ = Dθ ⊗ ½ k ∇θ(qₙ₊₁) + k (θ̄ − θ₀) ∂Dθ/∂qₙ₊₁.
VecX RevoluteSpring::discrete_gradient(const VecX& qn, const VecX& qn1, MatX* dv_dqn1) const {
  const RevoluteAngle::Discrete d = angle_.discrete(qn, qn1, dv_dqn1 != nullptr);
  const double f = stiffness_ * (d.theta_n + 0.5 * d.dtheta - free_angle_);
  if (dv_dqn1) {
    *dv_dqn1 = (0.5 * stiffness_) * d.D * d.gradient_n1.transpose();
    *dv_dqn1 += f * d.dD_dqn1;
  }
  return f * d.D;
}

// f = c θ̇ ∇θ, θ̇ = ∇θ·q̇: ∂f/∂q̇ = c ∇θ ∇θᵀ, ∂f/∂q = c [∇θ (∇²θ q̇)ᵀ + θ̇ ∇²θ].
VecX RevoluteSpring::viscous_force_in_pattern(const VecX& q, const VecX& qdot, double cq, double cv,
                                              double* values) const {
  if (!viscous()) return VecX::Zero(n_);
  MatX H;
  const VecX g = angle_.gradient(q, values ? &H : nullptr);
  const double rate = g.dot(qdot);
  if (values) {
    Eigen::Map<MatX> K(values, n_, n_);  // the dense pattern, column-major
    K += (cv * damping_) * g * g.transpose();
    K += (cq * damping_) * (g * (H * qdot).transpose() + rate * H);
  }
  return (damping_ * rate) * g;
}

double RevoluteSpring::rate(const VecX& q, const VecX& qdot) const {
  return angle_.gradient(q, nullptr).dot(qdot);
}

double RevoluteSpring::moment(const VecX& q, const VecX& qdot) const {
  return stiffness_ * (angle(q) - free_angle_) + damping_ * rate(q, qdot);
}

}  // namespace isoflex::elements
