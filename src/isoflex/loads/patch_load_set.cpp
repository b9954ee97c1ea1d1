#include "isoflex/loads/patch_load_set.hpp"

#include <algorithm>
#include <cassert>
#include <utility>

namespace isoflex::loads {

PatchLoadSet::PatchLoadSet(std::vector<int> nodes, PatchLoads loads, SpMat pattern)
    : nodes_(std::move(nodes)), loads_(std::move(loads)), pattern_(std::move(pattern)) {
  pattern_.makeCompressed();
}

VecX PatchLoadSet::generalized_force(const VecX& x, double t) const {
  VecX f = VecX::Zero(x.size());
  for (const auto& L : loads_) {
    const double lambda = L->factor(t);
    if (lambda != 0.0) f += lambda * L->force(x);
  }
  return f;
}

bool PatchLoadSet::follower() const {
  return std::any_of(loads_.begin(), loads_.end(), [](const auto& L) { return L->follower(); });
}

Load::SpMat PatchLoadSet::tangent_pattern(int size) const {
  assert(size == pattern_.rows());
  (void)size;
  return pattern_;
}

void PatchLoadSet::add_tangent(const VecX& x, double t, double scale, double* values) const {
  SpMat K = pattern_;
  std::fill_n(K.valuePtr(), K.nonZeros(), 0.0);
  bool any = false;
  for (const auto& L : loads_) {
    const double lambda = L->factor(t);
    if (lambda == 0.0 || !L->follower()) continue;
    L->add_tangent(x, scale * lambda, K);
    any = true;
  }
  if (!any) return;
  assert(K.nonZeros() == pattern_.nonZeros());  // a load's tangent stays in the element pattern
  for (Eigen::Index k = 0; k < K.nonZeros(); ++k) values[k] += K.valuePtr()[k];
}

}  // namespace isoflex::loads
