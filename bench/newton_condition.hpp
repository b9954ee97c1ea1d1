#pragma once
// The 2-norm condition number of the Newton matrix of the first step of a run, as the integrator
// assembles it (reduced formulations in their explicit form), at the Newton start and at the
// converged solution. Shared by the benchmarks that regenerate DNSM-III Table 4.
#include <algorithm>

#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/solve/linear_solver.hpp"
#include "isoflex/system/system.hpp"

namespace isoflex::bench {

struct NewtonCondition {
  int rows = 0, cols = 0;
  double at_start = 0.0, converged = 0.0;
  // Diagnostic (the solver does no such scaling): the converged matrix with its Δt-dependence
  // divided out; constrained: dynamics rows × Δt/2, λ columns × 2/Δt², i.e. [M + O(Δt²), Gᵀ; G, 0].
  double converged_scaled = 0.0;
  int iterations = 0;
  double final_residual = 0.0;
};

// `settings` gives the formulation, Δt and the Newton tolerances; the first step from the initial
// state is solved by plain Newton (dense LU) with the integrator's convergence test.
inline NewtonCondition newton_condition(const system::System& sys, const model::Solver& settings) {
  using model::Formulation;
  const integrate::EnergyMomentumIntegrator integ(sys, settings,
                                                  integrate::ReducedSolve::explicit_null_space);
  const integrate::State s = integ.initial_state();
  const double dt = settings.dt;
  VecX x = integ.start_unknowns(s);
  MatX J;
  VecX R = integ.residual(s, x, &J);
  NewtonCondition c;
  c.rows = static_cast<int>(J.rows());
  c.cols = static_cast<int>(J.cols());
  c.at_start = solve::condition_number(J);
  const double ref = std::max(1.0, (2.0 / dt) * (sys.mass() * s.q).lpNorm<Eigen::Infinity>() +
                                       (sys.mass() * s.v).lpNorm<Eigen::Infinity>());
  for (int it = 0; it < settings.max_iterations; ++it) {
    if (R.lpNorm<Eigen::Infinity>() <= settings.residual_tolerance * ref) break;
    const VecX dx = J.partialPivLu().solve(-R);
    x += dx;
    R = integ.residual(s, x, &J);
    c.iterations = it + 1;
    if (dx.lpNorm<Eigen::Infinity>() <=
        settings.increment_tolerance * std::max(1.0, x.lpNorm<Eigen::Infinity>()))
      break;
  }
  c.final_residual = R.lpNorm<Eigen::Infinity>();
  c.converged = solve::condition_number(J);
  MatX Js = J;
  if (settings.formulation == Formulation::constrained) {
    const int n = sys.n();
    Js.topRows(n) *= 0.5 * dt;
    Js.rightCols(Js.cols() - n) *= 2.0 / (dt * dt);
  }
  c.converged_scaled = solve::condition_number(Js);
  return c;
}

}  // namespace isoflex::bench
