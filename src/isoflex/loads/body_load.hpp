#pragma once
// A prescribed force F(t) at a body-fixed point X and a moment M(t) on a frame node
// (docs/theory/rigid-body.md). In director coordinates the force acts as F on φ and X_I F on d_I;
// the moment as ½ M × d_I on each d_I (virtual work ½ Σ (M × d_I)·(δθ × d_I) = M·δθ).
// In a time step both are evaluated at t_{n+½} and q_{n+½}, the midpoint of the scheme.
#include <array>
#include <optional>

#include "isoflex/loads/time_function.hpp"
#include "isoflex/math/types.hpp"

namespace isoflex::loads {

class BodyLoad {
 public:
  BodyLoad(int node, const Vec3& X, std::optional<std::array<TimeFunction, 3>> force,
           std::optional<std::array<TimeFunction, 3>> moment);

  int node() const { return node_; }
  // Generalized force (a 12-vector in the node coordinates) at configuration q and time t.
  Vec<12> generalized_force(const Vec<12>& q, double t) const;
  // ∂f/∂q (12 × 12), constant in q.
  Mat<12, 12> generalized_force_derivative(double t) const;
  // Whether generalized_force depends on q (only through the moment): the derivative may be
  // non-zero.
  bool has_moment() const { return moment_.has_value(); }
  Vec3 force(double t) const;
  Vec3 moment(double t) const;

 private:
  int node_;
  Vec3 X_;
  std::optional<std::array<TimeFunction, 3>> force_, moment_;
};

}  // namespace isoflex::loads
