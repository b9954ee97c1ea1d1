#pragma once
// The load contract (docs/architecture.md, "loads"): a prescribed external force on the stacked
// coordinates x of a set of System nodes, of any node kind — a force and moment on a rigid body or
// beam node (BodyLoad; FollowerBodyLoad in its director frame), on a director node
// (DirectorNodeLoad), the loads of a Kirchhoff–Love patch on its control points (PatchLoadSet).
// System assembles them all by this one interface, for the static residual ∇V − f_ext and, at
// (q_{n+½}, t_{n+½}), for the energy–momentum step (DNSM-III (9): the external forces enter the
// discrete balance at the midpoint).
//
// A load whose force depends on x (a follower: a moment that turns with the directors, a pressure
// on the current normal) has a tangent, given like an element's matrices as values in the
// storage order of its own pattern (elements/element.hpp), which the system scatters into its
// fixed global pattern. Dead loads have none.
#include <Eigen/SparseCore>
#include <vector>

#include "isoflex/math/types.hpp"

namespace isoflex::loads {

class Load {
 public:
  using SpMat = Eigen::SparseMatrix<double>;
  virtual ~Load() = default;

  // The system's nodes whose stacked coordinates x (in this order) the force acts on.
  virtual const std::vector<int>& nodes() const = 0;
  // f_ext(x, t), the generalized force on x.
  virtual VecX generalized_force(const VecX& x, double t) const = 0;
  // g += f_ext(x, t) (g of x's size): a load that can overrides it without heap allocation (the
  // fixed-pattern Newton iteration calls it in every evaluation).
  virtual void add_generalized_force(const VecX& x, double t, VecX& g) const {
    g += generalized_force(x, t);
  }
  // Whether f_ext depends on x; only then are tangent_pattern and add_tangent used.
  virtual bool follower() const = 0;
  // The pattern of ∂f_ext/∂x over x (compressed, column-major); default: dense.
  virtual SpMat tangent_pattern(int size) const;
  // values (tangent_pattern's storage order) += scale · ∂f_ext/∂x (x, t).
  virtual void add_tangent(const VecX& x, double t, double scale, double* values) const = 0;
};

}  // namespace isoflex::loads
