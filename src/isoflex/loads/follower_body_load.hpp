#pragma once
// A follower force and moment on a frame node (a rigid body or a beam node; model `loads` with
// `frame: body`): their components are prescribed in the node's director frame,
// F = F_J(t) d_J(q), M = M_J(t) d_J(q), the force at the body-fixed point X (docs/theory/
// rigid-body.md §7, "Follower loads"). The generalized force is that of BodyLoad with F and M
// turned by the directors: F on φ, X_I F + ½ M × d_I on d_I (virtual work F·δx + M·δθ on the
// manifold). It is not the gradient of a potential: its tangent
//   ∂f_φ/∂d_J   = F_J I,
//   ∂f_{d_I}/∂d_J = X_I F_J I − ½ M_J d̂_I + δ_IJ ½ M̂
// (from ½ M × d_I = ½ Σ_J M_J d_J × d_I) is not symmetric, and none of it depends on φ.
//
// In a time step it is evaluated, as every load, at t_{n+½} and q_{n+½} (DNSM-III (9)), where the
// directors are not orthonormal: F and M are then the prescribed components on the mean
// directors, a consistent second-order approximation of the load at the midpoint. The work it
// does per step, f·Δq, is what history.csv's external_work adds up; energy is not conserved and
// the momenta change as the load dictates.
#include <array>
#include <optional>
#include <vector>

#include "isoflex/loads/load.hpp"
#include "isoflex/loads/time_function.hpp"
#include "isoflex/math/types.hpp"

namespace isoflex::loads {

class FollowerBodyLoad final : public Load {
 public:
  // force and moment: the components along d₁, d₂, d₃; at least one of them is expected.
  FollowerBodyLoad(int node, const Vec3& X, std::optional<std::array<TimeFunction, 3>> force,
                   std::optional<std::array<TimeFunction, 3>> moment);

  int node() const { return nodes_.front(); }
  // The Load contract on the node's 12 coordinates; the tangent is dense.
  const std::vector<int>& nodes() const override { return nodes_; }
  VecX generalized_force(const VecX& x, double t) const override;
  bool follower() const override { return true; }
  void add_tangent(const VecX& x, double t, double scale, double* values) const override;

  // Generalized force (a 12-vector in the node coordinates) at configuration q and time t.
  Vec<12> generalized_force(const Vec<12>& q, double t) const;
  // ∂f/∂q (12 × 12) at q and t.
  Mat<12, 12> generalized_force_derivative(const Vec<12>& q, double t) const;
  // The prescribed components (F_J(t)), (M_J(t)) in the director frame; zero when not given.
  Vec3 local_force(double t) const;
  Vec3 local_moment(double t) const;

 private:
  std::vector<int> nodes_;
  Vec3 X_;
  std::optional<std::array<TimeFunction, 3>> force_, moment_;
};

}  // namespace isoflex::loads
