#pragma once
// The element contract (docs/architecture.md): an element maps the stacked coordinates of its
// nodes to a potential V, its discrete gradient DV(qₙ, qₙ₊₁) with ∂DV/∂qₙ₊₁, and a constant mass
// matrix. Elements are immutable after construction; configurations are passed in.
#include <vector>

#include "isoflex/math/types.hpp"

namespace isoflex::elements {

class Element {
 public:
  virtual ~Element() = default;
  // Indices of the element's nodes in the system (each a frame node for now).
  virtual const std::vector<int>& nodes() const = 0;
  virtual double potential(const VecX& q) const = 0;
  virtual VecX gradient(const VecX& q) const = 0;
  // DV with DV·(qₙ₊₁ − qₙ) = V(qₙ₊₁) − V(qₙ); dv_dqn1 (if not null) receives ∂DV/∂qₙ₊₁.
  virtual VecX discrete_gradient(const VecX& qn, const VecX& qn1, MatX* dv_dqn1) const = 0;
  // Constant consistent mass matrix of the element, in stacked node coordinates.
  virtual MatX mass() const = 0;
};

}  // namespace isoflex::elements
