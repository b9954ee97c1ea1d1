#pragma once
// The constraint contract (docs/architecture.md): rows Φ(q) = 0 over the stacked coordinates of
// any set of nodes, with their Jacobian and Hessians. System evaluates every row of a model through
// it. Rows at most quadratic in q (every joint) have constant Hessians and their Jacobian at the
// midpoint is an exact discrete derivative (DNSM-III (9)–(10)); a row that is not (the angle row
// of a kinked Kirchhoff–Love interface, IGA-thesis (5.37)) gives its own discrete derivative
// G̃(q_a, q_b), G̃ (q_b − q_a) = Φ(q_b) − Φ(q_a), for the energy–momentum schemes. `Joint`
// (joint.hpp) is the binary special case that also describes its explicit elimination (parent
// and freedom blocks, update map), so that the spanning forest can remove its rows; a joint
// instance's rows are a Constraint through `JointRows` (joint_rows.hpp). Any other Constraint
// has no elimination: its rows stay in every formulation as loop-closing ("cut") rows, selected
// for independence with the loop rows of the joints (IGA-thesis Alg. 5.1). Rheonomic rows depend
// on t through a prescribed right-hand side only, Φ(q_c) = d(t) (a prescribed displacement,
// IGA-thesis (3.37)–(3.40)): the Jacobian and the Hessians stay those of Φ(q_c), so the null
// spaces of the reduced formulations are the same, and the rows hold exactly at every time node.
#include <vector>

#include "isoflex/math/types.hpp"

namespace isoflex::joints {

class Constraint {
 public:
  using CRef = Eigen::Ref<const VecX>;
  virtual ~Constraint() = default;
  // The system's nodes whose stacked coordinates q_c (in this order) the rows depend on.
  virtual const std::vector<int>& nodes() const = 0;
  virtual int constraint_count() const = 0;
  virtual VecX constraints(CRef q_c) const = 0;
  virtual MatX jacobian(CRef q_c) const = 0;  // constraint_count() × q_c.size()
  // H += Σ λ_i ∂²Φ_i/∂q_c² at q_c (independent of q_c for rows at most quadratic).
  virtual void add_constraint_hessian(CRef q_c, CRef lambda, MatX& H) const = 0;
  // A discrete derivative: G̃ (q_b − q_a) = Φ(q_b) − Φ(q_a), G̃ → G(q) as q_a, q_b → q, and
  // G̃ annihilating the rigid motions at the midpoint where G does (so that constraint forces
  // G̃ᵀλ keep the momentum maps). The default G(½(q_a + q_b)) is exact for rows at most quadratic.
  virtual MatX discrete_jacobian(CRef q_a, CRef q_b) const { return jacobian(0.5 * (q_a + q_b)); }
  // > 0: perturbed Lagrange rows, Φ(q) − compliance·λ = 0 (IGA-thesis (5.24b)): a penalty
  // 1/compliance written with multipliers; such rows need not be independent (static analyses).
  virtual double compliance() const { return 0.0; }
  // True: rows whose independent subset changes with the configuration (the AF-BS strip forces,
  // IGA-thesis Conjecture 5.1): all are selected, and a static analysis keeps, in every load
  // step, as many as are independent at the reference, chosen by full-pivot LU at the step's
  // start (Alg. 5.1 as (5.35)); the others' multipliers are held at 0.
  virtual bool reselected() const { return false; }
  // d(t) (constraint_count() entries), asked only when rheonomic().
  virtual bool rheonomic() const { return false; }
  virtual VecX prescribed(double /*t*/) const { return VecX::Zero(constraint_count()); }
  // A converged configuration (System::accept, after every time or load step): rows with history
  // keep it from here (the turns of a revolute joint's driven angle, system/joint_drivers.hpp).
  virtual void accept(CRef /*q_c*/) const {}
};

}  // namespace isoflex::joints
