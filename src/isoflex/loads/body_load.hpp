#pragma once
// A prescribed force F(t) at a body-fixed point X and a moment M(t) on a frame node
// (docs/theory/rigid-body.md). In director coordinates the force acts as F on φ and X_I F on d_I;
// the moment as ½ M × d_I on each d_I (virtual work ½ Σ (M × d_I)·(δθ × d_I) = M·δθ).
// In a time step both are evaluated at t_{n+½} and q_{n+½}, the midpoint of the scheme.
#include <array>
#include <optional>
#include <vector>

#include "isoflex/loads/load.hpp"
#include "isoflex/loads/time_function.hpp"
#include "isoflex/math/types.hpp"

namespace isoflex::loads {

// The generalized force of a force F at the body-fixed point X (director coordinates X_I) and a
// moment M on a frame node q = (φ, d₁, d₂, d₃): F on φ, X_I F + ½ M × d_I on d_I (docs/theory/
// rigid-body.md §7). Shared by BodyLoad (F, M global) and FollowerBodyLoad (F, M on the directors).
Vec<12> frame_node_force(const Vec<12>& q, const Vec3& X, const Vec3& F, const Vec3& M);

class BodyLoad : public Load {
 public:
  BodyLoad(int node, const Vec3& X, std::optional<std::array<TimeFunction, 3>> force,
           std::optional<std::array<TimeFunction, 3>> moment);

  int node() const { return nodes_.front(); }
  // The Load contract on the node's 12 coordinates; the tangent (moment only) is dense.
  const std::vector<int>& nodes() const override { return nodes_; }
  VecX generalized_force(const VecX& x, double t) const override;
  void add_generalized_force(const VecX& x, double t, VecX& g) const override;
  bool follower() const override { return has_moment(); }
  void add_tangent(const VecX& x, double t, double scale, double* values) const override;
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
  std::vector<int> nodes_;
  Vec3 X_;
  std::optional<std::array<TimeFunction, 3>> force_, moment_;
};

}  // namespace isoflex::loads
