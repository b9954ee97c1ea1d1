#include "isoflex/elements/revolute_spring.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <utility>

namespace isoflex::elements {

namespace {
constexpr double kCloseIncrement = 1e-5;  // |Δπ| ≤ this × |π̄|: no Gonzalez correction
}  // namespace

RevoluteSpring::RevoluteSpring(std::vector<int> nodes, const FramePair& frames, double stiffness,
                               double damping, double free_angle, const VecX& q0)
    : nodes_(std::move(nodes)),
      n_(frames.size()),
      c_(frames.axis_product(0, 0)),
      s_(frames.axis_product(1, 0)),
      stiffness_(stiffness),
      damping_(damping),
      free_angle_(free_angle) {
  if (!(stiffness >= 0.0) || !(damping >= 0.0) || !std::isfinite(stiffness) ||
      !std::isfinite(damping) || !std::isfinite(free_angle))
    throw std::invalid_argument("RevoluteSpring: stiffness and damping must be finite and ≥ 0");
  if (q0.size() != n_) throw std::invalid_argument("RevoluteSpring: q0 of another size");
  const Vec2 pi = invariants(q0);
  if (!(pi.norm() > 0.0))
    throw std::invalid_argument("RevoluteSpring: the angle is undefined at the start");
  reference_ = std::atan2(pi(1), pi(0));
}

Mat<2, Eigen::Dynamic> RevoluteSpring::invariant_gradient(const VecX& q) const {
  Mat<2, Eigen::Dynamic> G(2, n_);
  G.row(0) = c_.gradient(q).transpose();
  G.row(1) = s_.gradient(q).transpose();
  return G;
}

double RevoluteSpring::angle(const Vec2& pi) const {
  const double raw = std::atan2(pi(1), pi(0));
  return reference_ + std::remainder(raw - reference_, 2.0 * std::numbers::pi);
}

double RevoluteSpring::angle(const VecX& q) const {
  return angle(invariants(q));
}

RevoluteSpring::Vec2 RevoluteSpring::angle_gradient(const Vec2& pi) {
  return Vec2(-pi(1), pi(0)) / pi.squaredNorm();
}

RevoluteSpring::Mat2 RevoluteSpring::angle_hessian(const Vec2& pi) {
  const double c = pi(0), s = pi(1), r4 = pi.squaredNorm() * pi.squaredNorm();
  Mat2 H;
  H << 2.0 * c * s, s * s - c * c, s * s - c * c, -2.0 * c * s;
  return H / r4;
}

// ∇θ = ∇πᵀ θ_π, ∇²θ = ∇πᵀ θ_ππ ∇π + θ_c H_c + θ_s H_s.
VecX RevoluteSpring::angle_gradient(const VecX& q, MatX* H) const {
  const Vec2 pi = invariants(q), g = angle_gradient(pi);
  const auto G = invariant_gradient(q);
  if (H) *H = G.transpose() * angle_hessian(pi) * G + g(0) * c_.hessian() + g(1) * s_.hessian();
  return G.transpose() * g;
}

double RevoluteSpring::potential(const VecX& q) const {
  const double d = angle(q) - free_angle_;
  return 0.5 * stiffness_ * d * d;
}

VecX RevoluteSpring::gradient(const VecX& q) const {
  return (stiffness_ * (angle(q) - free_angle_)) * angle_gradient(q, nullptr);
}

// DV = k (θ̄ − θ₀) ∇π(q_{n+½})ᵀ D_πθ (header). ∂DV/∂qₙ₊₁ = Dθ ⊗ ½ k ∇θ(qₙ₊₁)
// + k (θ̄ − θ₀) [½ (D_c H_c + D_s H_s) + ∇π(q_{n+½})ᵀ (∂D_πθ/∂πₙ₊₁) ∇π(qₙ₊₁)], with
// ∂D_πθ/∂πₙ₊₁ = ½ θ_ππ(π̄) + Δπ βᵀ′ + β I, β′ = [θ_π(πₙ₊₁) − θ_π(π̄) − ½ θ_ππ(π̄) Δπ − 2β Δπ] / |Δπ|².
VecX RevoluteSpring::discrete_gradient(const VecX& qn, const VecX& qn1, MatX* dv_dqn1) const {
  const VecX qm = 0.5 * (qn + qn1);
  const Vec2 p0 = invariants(qn), p1 = invariants(qn1), pm = 0.5 * (p0 + p1), dp = p1 - p0;
  const double th0 = angle(p0);
  const double dth = std::atan2(p0(0) * p1(1) - p0(1) * p1(0), p0.dot(p1));
  const Vec2 g = angle_gradient(pm);
  const double dp2 = dp.squaredNorm();
  const bool close = dp2 <= kCloseIncrement * kCloseIncrement * pm.squaredNorm();
  const double beta = close ? 0.0 : (dth - g.dot(dp)) / dp2;
  const Vec2 D = g + beta * dp;
  const auto Gm = invariant_gradient(qm);
  const VecX Dtheta = Gm.transpose() * D;
  const double f = stiffness_ * (th0 + 0.5 * dth - free_angle_);
  if (dv_dqn1) {
    const auto G1 = invariant_gradient(qn1);
    const Mat2 Hm = angle_hessian(pm);
    Mat2 dD = 0.5 * Hm;
    if (!close) {
      const Vec2 dbeta = (angle_gradient(p1) - g - 0.5 * Hm * dp - 2.0 * beta * dp) / dp2;
      dD += dp * dbeta.transpose() + beta * Mat2::Identity();
    }
    *dv_dqn1 = (0.5 * stiffness_) * Dtheta * (G1.transpose() * angle_gradient(p1)).transpose();
    *dv_dqn1 += f * (0.5 * (D(0) * c_.hessian() + D(1) * s_.hessian()) + Gm.transpose() * dD * G1);
  }
  return f * Dtheta;
}

// f = c θ̇ ∇θ, θ̇ = ∇θ·q̇: ∂f/∂q̇ = c ∇θ ∇θᵀ, ∂f/∂q = c [∇θ (∇²θ q̇)ᵀ + θ̇ ∇²θ].
VecX RevoluteSpring::viscous_force_in_pattern(const VecX& q, const VecX& qdot, double cq, double cv,
                                              double* values) const {
  if (!viscous()) return VecX::Zero(n_);
  MatX H;
  const VecX g = angle_gradient(q, values ? &H : nullptr);
  const double rate = g.dot(qdot);
  if (values) {
    Eigen::Map<MatX> K(values, n_, n_);  // the dense pattern, column-major
    K += (cv * damping_) * g * g.transpose();
    K += (cq * damping_) * (g * (H * qdot).transpose() + rate * H);
  }
  return (damping_ * rate) * g;
}

double RevoluteSpring::rate(const VecX& q, const VecX& qdot) const {
  return angle_gradient(q, nullptr).dot(qdot);
}

double RevoluteSpring::moment(const VecX& q, const VecX& qdot) const {
  return stiffness_ * (angle(q) - free_angle_) + damping_ * rate(q, qdot);
}

}  // namespace isoflex::elements
