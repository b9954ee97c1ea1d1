#include "isoflex/solve/normal_equations.hpp"

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
  if (ldlt_.info() != Eigen::Success)
    throw std::runtime_error("constraint Jacobian rank deficient");
  return ldlt_.solve(rhs);
}

}  // namespace isoflex::solve
