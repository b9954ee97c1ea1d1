#include "isoflex/solve/normal_equations.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <stdexcept>

namespace isoflex::solve {

VecX NormalEquations::solve(const SpMat& G, const VecX& rhs) {
  SpMat A = G * SpMat(G.transpose());
  A.makeCompressed();
  const auto* o = A.outerIndexPtr();
  const auto* i = A.innerIndexPtr();
  const bool same = outer_.size() == static_cast<std::size_t>(A.outerSize() + 1) &&
                    inner_.size() == static_cast<std::size_t>(A.nonZeros()) &&
                    std::equal(outer_.begin(), outer_.end(), o) &&
                    std::equal(inner_.begin(), inner_.end(), i);
  if (!same) {
    ldlt_.analyzePattern(A);
    outer_.assign(o, o + A.outerSize() + 1);
    inner_.assign(i, i + A.nonZeros());
    ++analyses_;
  }
  ldlt_.factorize(A);
  if (ldlt_.info() == Eigen::Success) {
    VecX x = ldlt_.solve(rhs);
    if (x.allFinite()) return x;
  }
  // G Gᵀ singular to working precision: its condition is that of G squared, and rows of very
  // different size make it worse (a joint 1e9 from its body: lever arms of 1e9 beside the unit
  // entries of other rows). A constraint row may be scaled freely, so the rank is decided on
  // Ĝ = D G with rows of unit length (D = diag(1/‖Gᵢ‖)), by pivoted QR of Ĝᵀ = Q R Πᵀ (the rank
  // test relative to the largest pivot), and G Gᵀ λ = rhs as Ĝ Ĝᵀ μ = D rhs, λ = D μ, with
  // Ĝ Ĝᵀ = Π Rᵀ R Πᵀ solved by two triangular solves, G Gᵀ never formed.
  ++fallbacks_;
  MatX Gt = MatX(G.transpose());
  const VecX d = Gt.colwise().norm().transpose().cwiseInverse();
  Gt *= d.asDiagonal();
  const Eigen::ColPivHouseholderQR<MatX> qr(Gt);
  if (!d.allFinite() || qr.rank() < G.rows())
    throw std::runtime_error("constraint Jacobian rank deficient");
  const auto R = qr.matrixR().topLeftCorner(G.rows(), G.rows()).triangularView<Eigen::Upper>();
  VecX z = qr.colsPermutation().transpose() * d.cwiseProduct(rhs);
  R.transpose().solveInPlace(z);
  R.solveInPlace(z);
  VecX x = d.cwiseProduct(qr.colsPermutation() * z);
  if (!x.allFinite()) throw std::runtime_error("constraint Jacobian rank deficient");
  return x;
}

}  // namespace isoflex::solve
