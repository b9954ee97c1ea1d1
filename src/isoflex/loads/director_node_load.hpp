#pragma once
// A prescribed force F(t) and moment M(t) on a director node (a shell node, DNSM-III (40)). The
// force acts on φ; the moment on the director as f_d = M × d, whose virtual work
// (M × d)·(δθ × d) = M·δθ for M ⊥ d (docs/theory/shell.md): a shell node carries no drilling
// moment, so the part of M along d does no work. In a time step both are evaluated at t_{n+½} and
// q_{n+½}, as for frame nodes (loads/body_load.hpp).
#include <array>
#include <optional>
#include <vector>

#include "isoflex/loads/load.hpp"
#include "isoflex/loads/time_function.hpp"
#include "isoflex/math/types.hpp"

namespace isoflex::loads {

class DirectorNodeLoad : public Load {
 public:
  DirectorNodeLoad(int node, std::optional<std::array<TimeFunction, 3>> force,
                   std::optional<std::array<TimeFunction, 3>> moment);

  int node() const { return nodes_.front(); }
  // The Load contract on the node's 6 coordinates; the tangent (moment only) is dense.
  const std::vector<int>& nodes() const override { return nodes_; }
  VecX generalized_force(const VecX& x, double t) const override;
  bool follower() const override { return has_moment(); }
  void add_tangent(const VecX& x, double t, double scale, double* values) const override;
  // Generalized force (6 entries, node coordinates (φ, d)) at configuration q and time t.
  Vec<6> generalized_force(const Vec<6>& q, double t) const;
  // ∂f/∂q (6 × 6), constant in q.
  Mat<6, 6> generalized_force_derivative(double t) const;
  // Whether generalized_force depends on q (only through the moment): the derivative may be
  // non-zero.
  bool has_moment() const { return moment_.has_value(); }

 private:
  std::vector<int> nodes_;
  std::optional<std::array<TimeFunction, 3>> force_, moment_;
};

}  // namespace isoflex::loads
