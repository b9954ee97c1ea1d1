#include "isoflex/system/strip_force_rows.hpp"

#include <algorithm>
#include <utility>

namespace isoflex::system {

using elements::KLKinematics;

StripForceRows::StripForceRows(std::shared_ptr<const elements::KLShellPatch> strip,
                               std::vector<int> nodes, double scale, double compliance)
    : strip_(std::move(strip)), nodes_(std::move(nodes)), scale_(scale), compliance_(compliance) {}

VecX StripForceRows::constraints(CRef q) const {
  return scale_ * strip_->internal_force(q, KLKinematics::nonlinear, nullptr);
}

MatX StripForceRows::jacobian(CRef q) const {
  elements::SpMat K;
  strip_->internal_force(q, KLKinematics::nonlinear, &K);
  return scale_ * MatX(K);
}

void StripForceRows::add_constraint_hessian(CRef q, CRef lambda, MatX& H) const {
  const double size = lambda.norm();
  if (size == 0.0) return;
  // D_λK ≈ (K(q + ε λ̂) − K(q − ε λ̂)) |λ| / 2ε; ε ~ 1e-5 of the configuration's size balances
  // truncation (ε²) against round-off (1/ε) at about 1e-10 relative.
  const double eps = 1e-5 * std::max(q.cwiseAbs().maxCoeff(), 1e-300);
  const VecX dir = lambda / size;
  elements::SpMat Kp, Km;
  strip_->internal_force(q + eps * dir, KLKinematics::nonlinear, &Kp);
  strip_->internal_force(q - eps * dir, KLKinematics::nonlinear, &Km);
  H += (scale_ * size / (2.0 * eps)) * MatX(Kp - Km);
}

}  // namespace isoflex::system
