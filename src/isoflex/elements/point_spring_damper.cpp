#include "isoflex/elements/point_spring_damper.hpp"

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace isoflex::elements {

PointSpringDamper::PointSpringDamper(std::vector<int> nodes, int coordinates, MaterialPointMap a,
                                     MaterialPointMap b, SpringDamperLaw law, const VecX& q0)
    : nodes_(std::move(nodes)), n_(coordinates), law_(law) {
  if (a.P.cols() != n_ || b.P.cols() != n_ || q0.size() != n_)
    throw std::invalid_argument("PointSpringDamper: the point maps have " +
                                std::to_string(a.P.cols()) + " and " + std::to_string(b.P.cols()) +
                                " columns, the configuration " + std::to_string(q0.size()) +
                                " entries, expected " + std::to_string(n_));
  if (!(law.stiffness >= 0.0) || !(law.damping >= 0.0) || !(law.free_length >= 0.0) ||
      !std::isfinite(law.stiffness) || !std::isfinite(law.damping) ||
      !std::isfinite(law.free_length))
    throw std::invalid_argument(
        "PointSpringDamper: stiffness, damping and free length must be "
        "finite and ≥ 0");
  D_ = a.P - b.P;
  ca_ = a.c;
  cb_ = b.c;
  e_ = a.c - b.c;
  if ((law.free_length > 0.0 || law.damping > 0.0) && !(difference(q0).norm() > 0.0))
    throw std::invalid_argument(
        "PointSpringDamper: the two points coincide at the start, so the line of the force is "
        "undefined (give them a distance, or free length 0 and no damping)");
}

double PointSpringDamper::length(const VecX& q) const {
  return difference(q).norm();
}

double PointSpringDamper::potential(const VecX& q) const {
  const double s = length(q) - law_.free_length;
  return 0.5 * law_.stiffness * s * s;
}

// ∇V = k (1 − L/ζ) Dᵀ d.
VecX PointSpringDamper::gradient(const VecX& q) const {
  const Vec3 d = difference(q);
  const double z = d.norm();
  const double g =
      law_.free_length > 0.0 ? law_.stiffness * (1.0 - law_.free_length / z) : law_.stiffness;
  return D_.transpose() * (g * d);
}

// DV = g Dᵀ d_{n+½}, g = 2 W̄′ = k (1 − 2L/s), s = ζₙ + ζₙ₊₁;
// ∂DV/∂qₙ₊₁ = ½ g DᵀD + (2kL/(s² ζₙ₊₁)) Dᵀ d_{n+½} dₙ₊₁ᵀ D.
VecX PointSpringDamper::discrete_gradient(const VecX& qn, const VecX& qn1, MatX* dv_dqn1) const {
  const Vec3 d0 = difference(qn), d1 = difference(qn1), dm = 0.5 * (d0 + d1);
  const double L = law_.free_length, k = law_.stiffness;
  const double s = d0.norm() + d1.norm();
  const double g = L > 0.0 ? k * (1.0 - 2.0 * L / s) : k;
  if (dv_dqn1) {
    *dv_dqn1 = (0.5 * g) * D_.transpose() * D_;
    if (L > 0.0) {
      const double h = 2.0 * k * L / (s * s * d1.norm());
      *dv_dqn1 += (h * (D_.transpose() * dm)) * (d1.transpose() * D_);
    }
  }
  return D_.transpose() * (g * dm);
}

double PointSpringDamper::rate(const VecX& q, const VecX& qdot) const {
  const Vec3 d = difference(q);
  const double z = d.norm();
  return z > 0.0 ? d.dot(D_ * qdot + w_) / z : 0.0;
}

void PointSpringDamper::move_anchor(int end, const Vec3& point, const Vec3& velocity) {
  (end == 0 ? ca_ : cb_) = point;
  e_ = ca_ - cb_;
  w_ = end == 0 ? velocity : Vec3(-velocity);
}

double PointSpringDamper::force(const VecX& q, const VecX& qdot) const {
  return law_.stiffness * (length(q) - law_.free_length) + law_.damping * rate(q, qdot);
}

// f = (c/ζ²) Dᵀ d (dᵀ u), u = D q̇: ∂f/∂q̇ = (c/ζ²) Dᵀ d dᵀ D and
// ∂f/∂q = (c/ζ²) [Dᵀ d uᵀ D + (dᵀu) DᵀD] − (2c (dᵀu)/ζ⁴) Dᵀ d dᵀ D.
VecX PointSpringDamper::viscous_force_in_pattern(const VecX& q, const VecX& qdot, double cq,
                                                 double cv, double* values) const {
  const double c = law_.damping;
  if (!(c > 0.0)) return VecX::Zero(n_);
  const Vec3 d = difference(q), u = D_ * qdot + w_;
  const double z2 = d.squaredNorm(), r = d.dot(u);
  const VecX Dd = D_.transpose() * d;
  if (values) {
    Eigen::Map<MatX> K(values, n_, n_);  // the dense pattern, column-major
    const VecX Du = D_.transpose() * u;  // ∂/∂q at fixed w
    K += (cv * c / z2) * Dd * Dd.transpose();
    K += (cq * c / z2) * (Dd * Du.transpose() + r * D_.transpose() * D_) -
         (cq * 2.0 * c * r / (z2 * z2)) * Dd * Dd.transpose();
  }
  return (c * r / z2) * Dd;
}

}  // namespace isoflex::elements
