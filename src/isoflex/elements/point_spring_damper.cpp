#include "isoflex/elements/point_spring_damper.hpp"

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace isoflex::elements {

PointSpringDamper::PointSpringDamper(std::vector<int> nodes, int coordinates, MaterialPointMap a,
                                     MaterialPointMap b, SpringDamperLaw law, const VecX& q0)
    : nodes_(std::move(nodes)),
      n_(coordinates),
      law_(std::move(law)),
      spring_(law_.stiffness_law.empty() ? ForceLaw(law_.stiffness)
                                         : ForceLaw(law_.stiffness_law, "e")),
      damper_(law_.damping_law.empty() ? ForceLaw(law_.damping) : ForceLaw(law_.damping_law, "v")) {
  if (a.P.cols() != n_ || b.P.cols() != n_ || q0.size() != n_)
    throw std::invalid_argument("PointSpringDamper: the point maps have " +
                                std::to_string(a.P.cols()) + " and " + std::to_string(b.P.cols()) +
                                " columns, the configuration " + std::to_string(q0.size()) +
                                " entries, expected " + std::to_string(n_));
  if (!(law_.stiffness >= 0.0) || !(law_.damping >= 0.0) || !(law_.free_length >= 0.0) ||
      !std::isfinite(law_.stiffness) || !std::isfinite(law_.damping) ||
      !std::isfinite(law_.free_length))
    throw std::invalid_argument(
        "PointSpringDamper: stiffness, damping and free length must be "
        "finite and ≥ 0");
  D_ = a.P - b.P;
  ca_ = a.c;
  cb_ = b.c;
  e_ = a.c - b.c;
  if ((law_.free_length > 0.0 || viscous() || !spring_.linear()) && !(difference(q0).norm() > 0.0))
    throw std::invalid_argument(
        "PointSpringDamper: the two points coincide at the start, so the line of the force is "
        "undefined (give them a distance, or free length 0 and no damping)");
}

double PointSpringDamper::length(const VecX& q) const {
  return difference(q).norm();
}

double PointSpringDamper::potential(const VecX& q) const {
  return spring_.energy(length(q) - law_.free_length);
}

// ∇V = (N(e)/ζ) Dᵀ d; linear: k (1 − L/ζ) Dᵀ d.
VecX PointSpringDamper::gradient(const VecX& q) const {
  const Vec3 d = difference(q);
  const double z = d.norm(), L = law_.free_length, k = law_.stiffness;
  const double g = !spring_.linear() ? spring_.force(z - L) / z : L > 0.0 ? k * (1.0 - L / z) : k;
  return D_.transpose() * (g * d);
}

// DV = g Dᵀ d_{n+½}, g = 2 W̄′ = 2 N̄ / s, s = ζₙ + ζₙ₊₁ (linear: k (1 − 2L/s));
// ∂DV/∂qₙ₊₁ = ½ g DᵀD + h Dᵀ d_{n+½} dₙ₊₁ᵀ D, h = (2 ∂N̄/∂eₙ₊₁ / s − 2 N̄/s²) / ζₙ₊₁
// (linear: 2kL/(s² ζₙ₊₁)).
VecX PointSpringDamper::discrete_gradient(const VecX& qn, const VecX& qn1, MatX* dv_dqn1) const {
  const Vec3 d0 = difference(qn), d1 = difference(qn1), dm = 0.5 * (d0 + d1);
  const double L = law_.free_length, k = law_.stiffness;
  const double z0 = d0.norm(), z1 = d1.norm(), s = z0 + z1;
  double g = k, h = 0.0;
  if (!spring_.linear()) {
    double dN = 0.0;
    const double N = spring_.mean(z0 - L, z1 - L, dv_dqn1 ? &dN : nullptr);
    g = 2.0 * N / s;
    h = (2.0 * dN / s - 2.0 * N / (s * s)) / z1;
  } else if (L > 0.0) {
    g = k * (1.0 - 2.0 * L / s);
    h = 2.0 * k * L / (s * s * z1);
  }
  if (dv_dqn1) {
    *dv_dqn1 = (0.5 * g) * D_.transpose() * D_;
    if (h != 0.0) *dv_dqn1 += (h * (D_.transpose() * dm)) * (d1.transpose() * D_);
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
  return spring_.force(length(q) - law_.free_length) + damper_.force(rate(q, qdot));
}

// f = (c/ζ²) Dᵀ d (dᵀ u), u = D q̇: ∂f/∂q̇ = (c/ζ²) Dᵀ d dᵀ D and
// ∂f/∂q = (c/ζ²) [Dᵀ d uᵀ D + (dᵀu) DᵀD] − (2c (dᵀu)/ζ⁴) Dᵀ d dᵀ D.
// A nonlinear law: f = N_d(ζ̇) n, n = Dᵀd/ζ, ζ̇ = dᵀu/ζ: ∂f/∂q̇ = N_d′ n nᵀ,
// ∂f/∂q = N_d′ n (Dᵀu/ζ − ζ̇ n/ζ)ᵀ + (N_d/ζ) (DᵀD − n nᵀ).
VecX PointSpringDamper::viscous_force_in_pattern(const VecX& q, const VecX& qdot, double cq,
                                                 double cv, double* values) const {
  if (!viscous()) return VecX::Zero(n_);
  if (!damper_.linear()) {
    const Vec3 d = difference(q), u = D_ * qdot + w_;
    const double z = d.norm(), v = d.dot(u) / z;
    const VecX nv = D_.transpose() * (d / z);
    const double N = damper_.force(v);
    if (values) {
      const double dN = damper_.derivative(v);
      Eigen::Map<MatX> K(values, n_, n_);
      K += (cv * dN) * nv * nv.transpose();
      K += (cq * dN) * nv * (D_.transpose() * u / z - (v / z) * nv).transpose();
      K += (cq * N / z) * (D_.transpose() * D_ - nv * nv.transpose());
    }
    return N * nv;
  }
  const double c = law_.damping;
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
