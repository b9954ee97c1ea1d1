#pragma once
// An actuator between two material points (model `springs`, key `actuator`; docs/theory/
// coupling.md §6): a force F(t) along the line of the points, prescribed as a time function,
// tension > 0 (it pulls the points together, as a spring in tension does). The points are linear
// in the stacked coordinates x of their nodes, so their difference is d = D x + e, ζ = |d|, and
// the generalized force is f = −F(t) Dᵀ d / ζ: a pair of opposite forces on one line, without
// resultant or moment. It depends on x (a follower load): its tangent is
// ∂f/∂x = −(F/ζ) (DᵀD − Dᵀd dᵀD / ζ²).
//
// The energy–momentum schemes take it, like every load, at (q_{n+½}, t_{n+½}); the work it does,
// f·Δq per step, is what history.csv's external_work adds up.
#include <string>
#include <vector>

#include "isoflex/loads/load.hpp"
#include "isoflex/loads/time_function.hpp"

namespace isoflex::loads {

class LineActuator final : public Load {
 public:
  // Throws std::invalid_argument for a map of another width than x or points that coincide in
  // x0 (the line of the force undefined).
  LineActuator(std::vector<int> nodes, Eigen::Matrix<double, 3, Eigen::Dynamic> D, const Vec3& e,
               TimeFunction force, const VecX& x0);

  const std::vector<int>& nodes() const override { return nodes_; }
  VecX generalized_force(const VecX& x, double t) const override;
  bool follower() const override { return true; }
  void add_tangent(const VecX& x, double t, double scale, double* values) const override;

  // F(t), tension > 0.
  double force(double t) const { return force_(t); }
  const std::string& expression() const { return force_.expression(); }

 private:
  std::vector<int> nodes_;
  Eigen::Matrix<double, 3, Eigen::Dynamic> D_;
  Vec3 e_;
  TimeFunction force_;
};

}  // namespace isoflex::loads
