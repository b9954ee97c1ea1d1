#include "isoflex/elements/revolute_angle.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace isoflex::elements {

namespace {
constexpr double kCloseIncrement = 1e-5;  // |Δπ| ≤ this × |π̄|: no Gonzalez correction
}  // namespace

RevoluteAngle::RevoluteAngle(const FramePair& frames, const VecX& q0)
    : n_(frames.size()), c_(frames.axis_product(0, 0)), s_(frames.axis_product(1, 0)) {
  if (q0.size() != n_) throw std::invalid_argument("RevoluteAngle: q0 of another size");
  const Vec2 pi = invariants(q0);
  if (!(pi.norm() > 0.0))
    throw std::invalid_argument("RevoluteAngle: the angle is undefined at the start");
  reference_ = std::atan2(pi(1), pi(0));
}

Mat<2, Eigen::Dynamic> RevoluteAngle::invariant_gradient(const VecX& q) const {
  Mat<2, Eigen::Dynamic> G(2, n_);
  G.row(0) = c_.gradient(q).transpose();
  G.row(1) = s_.gradient(q).transpose();
  return G;
}

double RevoluteAngle::angle(const Vec2& pi) const {
  const double raw = std::atan2(pi(1), pi(0));
  return reference_ + std::remainder(raw - reference_, 2.0 * std::numbers::pi);
}

double RevoluteAngle::angle(const VecX& q) const {
  return angle(invariants(q));
}

RevoluteAngle::Vec2 RevoluteAngle::angle_gradient(const Vec2& pi) {
  return Vec2(-pi(1), pi(0)) / pi.squaredNorm();
}

RevoluteAngle::Mat2 RevoluteAngle::angle_hessian(const Vec2& pi) {
  const double c = pi(0), s = pi(1), r4 = pi.squaredNorm() * pi.squaredNorm();
  Mat2 H;
  H << 2.0 * c * s, s * s - c * c, s * s - c * c, -2.0 * c * s;
  return H / r4;
}

// ∇θ = ∇πᵀ θ_π, ∇²θ = ∇πᵀ θ_ππ ∇π + θ_c H_c + θ_s H_s.
VecX RevoluteAngle::gradient(const VecX& q, MatX* H) const {
  const Vec2 pi = invariants(q), g = angle_gradient(pi);
  const auto G = invariant_gradient(q);
  if (H) *H = G.transpose() * angle_hessian(pi) * G + g(0) * c_.hessian() + g(1) * s_.hessian();
  return G.transpose() * g;
}

// Dθ = ∇π(q_{n+½})ᵀ D_πθ (header). ∂Dθ/∂qₙ₊₁ = ½ (D_c H_c + D_s H_s)
// + ∇π(q_{n+½})ᵀ (∂D_πθ/∂πₙ₊₁) ∇π(qₙ₊₁), with ∂D_πθ/∂πₙ₊₁ = ½ θ_ππ(π̄) + Δπ βᵀ′ + β I,
// β′ = [θ_π(πₙ₊₁) − θ_π(π̄) − ½ θ_ππ(π̄) Δπ − 2β Δπ] / |Δπ|².
RevoluteAngle::Discrete RevoluteAngle::discrete(const VecX& qn, const VecX& qn1,
                                                bool derivative) const {
  const VecX qm = 0.5 * (qn + qn1);
  const Vec2 p0 = invariants(qn), p1 = invariants(qn1), pm = 0.5 * (p0 + p1), dp = p1 - p0;
  Discrete out;
  out.theta_n = angle(p0);
  out.dtheta = std::atan2(p0(0) * p1(1) - p0(1) * p1(0), p0.dot(p1));
  const Vec2 g = angle_gradient(pm);
  const double dp2 = dp.squaredNorm();
  const bool close = dp2 <= kCloseIncrement * kCloseIncrement * pm.squaredNorm();
  const double beta = close ? 0.0 : (out.dtheta - g.dot(dp)) / dp2;
  const Vec2 D = g + beta * dp;
  const auto Gm = invariant_gradient(qm);
  out.D = Gm.transpose() * D;
  if (derivative) {
    const auto G1 = invariant_gradient(qn1);
    const Mat2 Hm = angle_hessian(pm);
    Mat2 dD = 0.5 * Hm;
    if (!close) {
      const Vec2 dbeta = (angle_gradient(p1) - g - 0.5 * Hm * dp - 2.0 * beta * dp) / dp2;
      dD += dp * dbeta.transpose() + beta * Mat2::Identity();
    }
    out.gradient_n1 = G1.transpose() * angle_gradient(p1);
    out.dD_dqn1 = 0.5 * (D(0) * c_.hessian() + D(1) * s_.hessian()) + Gm.transpose() * dD * G1;
  }
  return out;
}

}  // namespace isoflex::elements
