#pragma once
// The element contract (docs/architecture.md): an element maps the stacked coordinates of its
// nodes to a potential V, its gradient, its discrete gradient DV(qₙ, qₙ₊₁) with ∂DV/∂qₙ₊₁, and a
// constant mass matrix. Elements are immutable after construction (but for the history of
// `accept` below); configurations are passed in.
//
// Matrices come in two shapes. Small elements (a rigid body, a beam, a director-shell quad) hand
// out dense matrices over their stacked coordinates. An element with many nodes (a NURBS patch:
// hundreds of control points, each coupled only to its neighbours) has its own sparsity pattern
// instead: `pattern()` is computed once and every matrix of the element is given as values in that
// pattern's storage order, which the system scatters into its fixed global pattern by a map
// computed once (system/global_matrix.hpp) — no triplets per Newton iteration. The defaults below
// make a dense element a sparse one with the full pattern (column-major = storage order).
#include <Eigen/SparseCore>
#include <vector>

#include "isoflex/math/types.hpp"

namespace isoflex::elements {

using SpMat = Eigen::SparseMatrix<double>;

class Element {
 public:
  virtual ~Element() = default;
  // Indices of the element's nodes in the system.
  virtual const std::vector<int>& nodes() const = 0;
  virtual double potential(const VecX& q) const = 0;
  virtual VecX gradient(const VecX& q) const = 0;
  // DV with DV·(qₙ₊₁ − qₙ) = V(qₙ₊₁) − V(qₙ); dv_dqn1 (if not null) receives ∂DV/∂qₙ₊₁.
  virtual VecX discrete_gradient(const VecX& qn, const VecX& qn1, MatX* dv_dqn1) const = 0;
  // dv += DV (dv of the stacked coordinates' size), ∂DV/∂qₙ₊₁ into dv_dqn1 as discrete_gradient;
  // an element that can overrides it without heap allocation (the fixed-pattern Newton
  // iteration calls it in every evaluation).
  virtual void add_discrete_gradient(const VecX& qn, const VecX& qn1, VecX& dv,
                                     MatX* dv_dqn1) const {
    dv += discrete_gradient(qn, qn1, dv_dqn1);
  }
  // Constant consistent mass matrix of the element, in stacked node coordinates.
  virtual MatX mass() const = 0;

  // --- Assembly into a fixed global pattern ----------------------------------------------------
  // The element's matrix pattern over its stacked coordinates (compressed, column-major): every
  // entry ∂DV/∂qₙ₊₁ may fill. Default: dense.
  virtual SpMat pattern() const;
  // discrete_gradient with ∂DV/∂qₙ₊₁ written into `values` (pattern().nonZeros() entries, the
  // pattern's storage order) when values is not null.
  virtual VecX discrete_gradient_in_pattern(const VecX& qn, const VecX& qn1, double* values) const;
  // The mixed integration point Newton iteration (docs/theory/schemes.md §6): DV(qₙ, qₙ₊₁) as
  // discrete_gradient_in_pattern, with the stresses of the tangent's geometric part (the terms
  // that multiply stresses by second derivatives of strains) taken from estimated strains Ê
  // instead of E(qₙ₊₁): Ê = E(q_lin) + B(q_lin)(qₙ₊₁ − q_lin), the strains linearized at the last
  // iterate q_lin, or Ê = E(qₙ) at a Newton start (q_lin null). stress_force (if not null)
  // receives the force of those stresses less DV's (what the multiplier estimate of the reduced
  // formulations uses). The root is the same; only the Newton path changes. Default: no
  // geometric part of that kind, discrete_gradient_in_pattern and a zero stress_force.
  virtual VecX mixed_discrete_gradient_in_pattern(const VecX& qn, const VecX& qn1,
                                                  const VecX* q_lin, double* values,
                                                  VecX* stress_force) const;
  // The gradient ∇V(q) with the tangent ∇²V(q) written into `values` (pattern order) when values
  // is not null: statics and the DAE integrators. Default: DV(q, q) and 2 ∂DV/∂qₙ₊₁(q, q), exact
  // for a discrete gradient symmetric in its arguments, DV(a, b) = DV(b, a) (the average-strain
  // gradients of beams and director shells, gravity: docs/theory/beam.md §4); an element whose
  // discrete gradient is not symmetric overrides it.
  virtual VecX gradient_in_pattern(const VecX& q, double* values) const;
  // The mass matrix without its zero entries (computed once by the system).
  virtual SpMat sparse_mass() const;

  // --- Viscous forces (Kelvin–Voigt, IGA-thesis §3.5) -------------------------------------------
  // Whether the element has forces f_v(q, q̇) that dissipate, linear in the velocity q̇ (its
  // coordinates' time derivatives). Default: none.
  virtual bool viscous() const { return false; }
  // f_v(q, q̇); when values is not null, cq ∂f_v/∂q + cv ∂f_v/∂q̇ is added to it (pattern order).
  // Default: zero.
  virtual VecX viscous_force_in_pattern(const VecX& q, const VecX& qdot, double cq, double cv,
                                        double* values) const;

  // --- Numerical dissipation (docs/theory/schemes.md §10) ----------------------------------------
  // Whether the element's stored energy is a quadratic form of strains E(q) that it can damp by
  // an algorithmic stress on their second difference. Default: no.
  virtual bool strain_dissipation() const { return false; }
  // f_d = B(q_{n+½})ᵀ χ C (ΔEₙ₊₁ − r ΔEₙ), ΔEₙ₊₁ = E(qₙ₊₁) − E(qₙ), ΔEₙ = E(qₙ) − E(qₙ₋₁), r the
  // ratio of the step lengths; when values is not null, ∂f_d/∂qₙ₊₁ is added to it (pattern
  // order). Default: zero.
  virtual VecX strain_dissipation_force_in_pattern(const VecX& q_prev, const VecX& qn,
                                                   const VecX& qn1, double chi, double ratio,
                                                   double* values) const;
  // The same f_d, with the tangent's geometric part (½ Σ S_d,k H_k) and stress_force as in
  // mixed_discrete_gradient_in_pattern: E(qₙ₊₁) replaced by the estimate Ê. Default: the exact
  // tangent and a zero stress_force.
  virtual VecX mixed_strain_dissipation_force_in_pattern(const VecX& q_prev, const VecX& qn,
                                                         const VecX& qn1, const VecX* q_lin,
                                                         double chi, double ratio, double* values,
                                                         VecX* stress_force) const;

  // --- History --------------------------------------------------------------------------------
  // A configuration q of a converged step (time step or load step), before the next step starts.
  // An element whose potential depends on more than its configuration keeps that one piece of
  // history from it — the revolute spring the branch of its angle (the turns), which the
  // configuration fixes only modulo 2π. Called by System::accept, never while a step iterates,
  // so the functions above are functions of their arguments during a step. Default: nothing.
  virtual void accept(const VecX& q) const { (void)q; }
};

}  // namespace isoflex::elements
