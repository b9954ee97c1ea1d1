#pragma once
// The loads of one Kirchhoff–Love patch (kl_patch_loads.hpp) as one Load over the patch's control
// points, System point nodes: f_ext(x, t) = Σ λ_l(t) f_l(x), summed in the order of the model
// file. The follower tangent Σ λ_l ∂f_l/∂x lives in the patch element's pattern (every pair of
// control points sharing a knot span).
#include <vector>

#include "isoflex/loads/kl_patch_loads.hpp"
#include "isoflex/loads/load.hpp"

namespace isoflex::loads {

class PatchLoadSet : public Load {
 public:
  // nodes: the control points' nodes in the patch's order; pattern: the patch element's (needed
  // only if a load is a follower).
  PatchLoadSet(std::vector<int> nodes, PatchLoads loads, SpMat pattern);

  const std::vector<int>& nodes() const override { return nodes_; }
  VecX generalized_force(const VecX& x, double t) const override;
  bool follower() const override;
  SpMat tangent_pattern(int size) const override;
  void add_tangent(const VecX& x, double t, double scale, double* values) const override;
  const PatchLoads& loads() const { return loads_; }

 private:
  std::vector<int> nodes_;
  PatchLoads loads_;
  SpMat pattern_;
};

}  // namespace isoflex::loads
