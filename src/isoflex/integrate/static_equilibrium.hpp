#pragma once
// Static equilibrium with load stepping: the constrained formulation (DNSM-III (9)) with the mass
// terms dropped. The time t of the load functions is read as a load parameter: step() solves
//   R(q, λ) = [ ∇V(q) − f_ext(q, t) + G(q)ᵀ λ ;  Φ_sel(q) ] = 0,     unknowns (q, λ), n + m,
// at t = tₙ + Δt, starting from the equilibrium at tₙ (q₀ at t = 0; v stays 0). Newton tangent
//   J = [ ∇²V − ∂f_ext/∂q + Σ λᵢ Hᵢ ,  Gᵀ ;  G , 0 ]
// with the constant constraint Hessians Hᵢ. Reuses the element kernels through
// System::discrete_force at equal arguments: DV(q, q) = ∇V(q) (docs/theory/beam.md §4) and, since
// DV(a, b) = DV(b, a) for the average-strain and the linear gravity discrete gradients,
// ∂DV/∂qₙ₊₁(q, q) = ½ ∇²V; the loads enter as −f_ext(q_{n+½}) with the same factor ½ on
// ∂f_ext/∂q. So J's upper-left block is 2 K + Σ λᵢ Hᵢ with K from discrete_force(q, q).
// Convergence test and failure as in EnergyMomentumIntegrator::step (docs/theory/schemes.md §6);
// the residual scale is max(1, ‖Gᵀλ‖∞), the size of the forces that balance. `formulation` and the
// mass data are ignored.
#include "isoflex/integrate/energy_momentum.hpp"

namespace isoflex::integrate {

class StaticEquilibrium {
 public:
  StaticEquilibrium(const system::System& sys, const model::Solver& settings);

  int unknowns() const { return sys_.n() + sys_.m_selected(); }
  // q₀, v = 0, t = 0: the unloaded reference configuration (an equilibrium when the loads vanish
  // at t = 0 and there is no gravity).
  State initial_state() const;
  // Equilibrium at the load parameter s.t + Δt, Newton started from s.q and the last multipliers
  // (kept in s.last_unknowns); an increment that fails is taken in halves, at most
  // solver.max_subdivisions deep. Throws NewtonFailure (s unchanged) when that does not converge.
  StepStats step(State& s) const;
  // R(x) and J(x) at the load parameter t for x = (q, λ) (tests).
  VecX residual(double t, const VecX& x, MatX* J) const;

 private:
  VecX evaluate(double t, const VecX& x, system::SpMat* J) const;
  StepStats attempt(State& s, double dt) const;  // one increment; s unchanged if it throws

  const system::System& sys_;
  model::Solver settings_;
};

}  // namespace isoflex::integrate
