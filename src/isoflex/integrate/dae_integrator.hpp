#pragma once
// Index-3 DAE time integration of every System (IGA-thesis ch. 2, docs/theory/integrators.md):
//
//   M q̈ + ∇V(q) − f_ext(q, t) + G(q)ᵀ λ = 0,   Φ(q, t) = 0                       (2.22)
//
// on the embedded coordinates q with every selected row — the nodes' internal rows, the joints'
// and the n-ary constraints — imposed at the time nodes by multipliers, as in the constrained
// energy–momentum formulation. A frame node's directors are therefore orthonormal at every tₙ to
// the Newton tolerance, but its embedded velocity is not kept tangent (G v = 0 is not imposed:
// index 3), and neither energy nor the momentum maps are conserved exactly.
//
// Every scheme is written as linear relations between the step's unknown qₙ₊₁ and its velocity
// and acceleration, v = v* + γ'(q − q*), q̈ = a* + β'(q − q*):
//   generalized-α (Arnold & Brüls, Alg. 2.1, (2.23)–(2.26)), parameters from ρ∞ (Chung–Hulbert):
//     α_m = (2ρ∞ − 1)/(ρ∞ + 1), α_f = ρ∞/(ρ∞ + 1), γ = ½ − α_m + α_f, β = ¼(γ + ½)²;
//   BDF-1 (2.20): v = (q − qₙ)/h, q̈ = (v − vₙ)/h;
//   BDF-2 (2.21): v = (3/2 q − 2qₙ + ½qₙ₋₁)/h, q̈ likewise from the velocities (its first step is
//     taken with BDF-1; a step whose length differs from the last one, as the halves of a
//     subdivided step, uses the variable-grid coefficients).
// Newton on (q, λ) with the iteration matrix S_t (2.27), [β'M + γ'C_t + K_t, Gᵀ; G, 0],
// K_t = ∇²V − ∂f_ext/∂q + Σλᵢ∇²Φᵢ (no velocity-dependent forces yet: C_t = 0). With
// `solver.scaling` (IGA-thesis §2.2.4, (2.56)–(2.58)) the force rows are multiplied by h², the
// constraint rows by s = ‖M‖∞ + h²‖K_t‖∞ (at the start of the step) and λ = s λ̂ / h², so that the
// condition number of S_t no longer grows like h⁻²…h⁻⁴. The start is consistent: q̈₀ and λ₀
// from [M Gᵀ; G 0] [q̈₀; λ₀] = [f_ext − ∇V; d̈(0) − (vᵀ∇²Φᵢ v)ᵢ].
#include "isoflex/integrate/newton_loop.hpp"
#include "isoflex/integrate/time_integrator.hpp"
#include "isoflex/solve/linear_solver.hpp"
#include "isoflex/system/system.hpp"

namespace isoflex::integrate {

class DaeIntegrator final : public TimeIntegrator {
 public:
  // Throws std::invalid_argument when settings.integrator is not a DAE scheme.
  DaeIntegrator(const system::System& sys, const model::Solver& settings);

  std::string name() const override { return model::to_string(settings_.integrator); }
  int unknowns() const override { return sys_.n() + sys_.m_selected(); }
  // q₀, v₀ with the consistent q̈₀ and λ₀.
  State initial_state() const override;
  StepStats step(State& s) const override;

  struct AlphaParameters {
    double alpha_m, alpha_f, beta, gamma;
  };
  static AlphaParameters alpha_parameters(double rho_infinity);

  // The iteration matrix S_t (2.27) of the step from s at its Newton start (scaled as set), for
  // condition numbers.
  system::SpMat iteration_matrix(const State& s) const;

 private:
  // The step's linear relations v = v* + γ'(q − q*), q̈ = a* + β'(q − q*); for generalized-α
  // also the auxiliary acceleration before the correction.
  struct Prediction {
    VecX q, v, a, aux;
    double beta_p = 0.0, gamma_p = 0.0;
  };
  Prediction predict(const State& s, double h) const;
  // Fills s.a, s.aux, s.lambda at s.q, s.v, s.t.
  void consistent_start(State& s) const;
  StepStats attempt(State& s, double h) const;
  // c and σ of the scaled equations (1 and 1 without scaling), from the step's start.
  void scaling_factors(const Prediction& p, double t, double h, double& c, double& sigma) const;
  // R = [c (M q̈ + ∇V − f_ext) + σ Gᵀλ̂; σ Φ_sel] at (q, λ̂), time t; S (if not null) receives
  // its derivative. c = h² and σ the constraint scale with scaling, else 1 and 1.
  VecX residual(const Prediction& p, const VecX& q, const VecX& lambda_hat, double t, double c,
                double sigma, system::SpMat* S, double* load_norm) const;

  const system::System& sys_;
  model::Solver settings_;
  AlphaParameters alpha_{};
  mutable solve::FixedPatternLU lu_;  // keeps its ordering while S_t keeps its pattern
};

}  // namespace isoflex::integrate
