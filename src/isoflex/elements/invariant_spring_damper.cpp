#include "isoflex/elements/invariant_spring_damper.hpp"

#include <stdexcept>
#include <string>
#include <utility>

namespace isoflex::elements {

InvariantSpringDamper::InvariantSpringDamper(std::vector<int> nodes,
                                             std::vector<QuadraticInvariant> strains, const MatX& K,
                                             const MatX& C, const VecX& q0, const VecX& offsets)
    : nodes_(std::move(nodes)),
      n_(static_cast<int>(q0.size())),
      pi_(std::move(strains)),
      K_(K),
      C_(C),
      viscous_(C.size() > 0 && C.cwiseAbs().maxCoeff() > 0.0) {
  const auto m = static_cast<Eigen::Index>(pi_.size());
  if (K.rows() != m || K.cols() != m || C.rows() != m || C.cols() != m ||
      (offsets.size() != 0 && offsets.size() != m))
    throw std::invalid_argument("InvariantSpringDamper: matrices and offsets must match the " +
                                std::to_string(m) + " strains");
  for (const auto& p : pi_)
    if (p.hessian().rows() != n_)
      throw std::invalid_argument("InvariantSpringDamper: a strain of another size than q0");
  pi0_ = VecX::Zero(m);
  for (Eigen::Index i = 0; i < m; ++i) pi0_(i) = pi_[i].value(q0);
  if (offsets.size() == m) pi0_ += offsets;
}

VecX InvariantSpringDamper::strains(const VecX& q) const {
  VecX e(pi_.size());
  for (std::size_t i = 0; i < pi_.size(); ++i) e(i) = pi_[i].value(q);
  return e - pi0_;
}

MatX InvariantSpringDamper::strain_gradient(const VecX& q) const {
  MatX G(pi_.size(), n_);
  for (std::size_t i = 0; i < pi_.size(); ++i) G.row(i) = pi_[i].gradient(q).transpose();
  return G;
}

double InvariantSpringDamper::potential(const VecX& q) const {
  const VecX e = strains(q);
  return 0.5 * e.dot(K_ * e);
}

VecX InvariantSpringDamper::gradient(const VecX& q) const {
  return strain_gradient(q).transpose() * (K_ * strains(q));
}

// DV = Gₘᵀ K ē, Gₘ = ∇e(q_{n+½}); ∂DV/∂qₙ₊₁ = ½ Σᵢ Hᵢ (K ē)ᵢ + ½ Gₘᵀ K ∇e(qₙ₊₁).
VecX InvariantSpringDamper::discrete_gradient(const VecX& qn, const VecX& qn1,
                                              MatX* dv_dqn1) const {
  const VecX qm = 0.5 * (qn + qn1);
  const MatX Gm = strain_gradient(qm);
  const VecX s = K_ * (0.5 * (strains(qn) + strains(qn1)));
  if (dv_dqn1) {
    *dv_dqn1 = 0.5 * Gm.transpose() * K_ * strain_gradient(qn1);
    for (std::size_t i = 0; i < pi_.size(); ++i) *dv_dqn1 += (0.5 * s(i)) * pi_[i].hessian();
  }
  return Gm.transpose() * s;
}

// f = Gᵀ C ė, ė = G q̇: ∂f/∂q̇ = Gᵀ C G, ∂f/∂q = Σᵢ Hᵢ (C ė)ᵢ + Gᵀ C R, R's rows (Hᵢ q̇)ᵀ.
VecX InvariantSpringDamper::viscous_force_in_pattern(const VecX& q, const VecX& qdot, double cq,
                                                     double cv, double* values) const {
  if (!viscous_) return VecX::Zero(n_);
  const MatX G = strain_gradient(q);
  const VecX s = C_ * (G * qdot);
  if (values) {
    Eigen::Map<MatX> A(values, n_, n_);  // the dense pattern, column-major
    MatX R(pi_.size(), n_);
    for (std::size_t i = 0; i < pi_.size(); ++i) {
      R.row(i) = (pi_[i].hessian() * qdot).transpose();
      A += (cq * s(i)) * pi_[i].hessian();
    }
    A += G.transpose() * C_ * (cv * G + cq * R);
  }
  return G.transpose() * s;
}

}  // namespace isoflex::elements
