#pragma once
// The Newton iteration shared by the time step (EnergyMomentumIntegrator) and the load step
// (StaticEquilibrium), with the convergence tests of docs/theory/schemes.md §6: ‖R‖∞ ≤
// residual_tolerance · scale, or a correction at round-off level (‖Δ‖ ≤ increment_tolerance ·
// qscale in configuration units; its error is its square). Throws NewtonFailure with `where`
// ("step 12 (t = 0.12)") and how far the residual got.
#include <fmt/format.h>

#include <cmath>
#include <exception>
#include <string>

#include "isoflex/integrate/energy_momentum.hpp"

namespace isoflex::integrate {

// residual(x, with_matrix) → R (keeping the Newton matrix when asked); correction(R) → Δx;
// scale(x) → the residual scale; increment(Δx) → the size of Δx in configuration units.
// A step of length dt by `attempt(dt)` (which leaves the state unchanged when it throws
// NewtonFailure), retried as two halves on failure while fewer than max_subdivisions halvings
// deep: the time steps of EnergyMomentumIntegrator and the load increments of StaticEquilibrium.
template <class Attempt>
StepStats subdivided(Attempt&& attempt, double dt, int max_subdivisions, int depth = 0) {
  try {
    return attempt(dt);
  } catch (const NewtonFailure&) {
    if (depth >= max_subdivisions) throw;
  }
  const StepStats a = subdivided(attempt, 0.5 * dt, max_subdivisions, depth + 1);
  const StepStats b = subdivided(attempt, 0.5 * dt, max_subdivisions, depth + 1);
  return {a.iterations + b.iterations, b.residual, a.substeps + b.substeps};
}

// One whole step of s by `attempt(dt)`, subdivided on failure: s.step advances by one, and a
// failure (after a converged part, too) leaves s as it was.
template <class Attempt>
StepStats whole_step(State& s, Attempt&& attempt, double dt, int max_subdivisions) {
  const State start = s;
  try {
    const StepStats st = subdivided(attempt, dt, max_subdivisions);
    s.step = start.step + 1;
    return st;
  } catch (const NewtonFailure&) {
    s = start;
    throw;
  }
}

template <class Residual, class Correction, class Scale, class Increment>
StepStats newton_loop(VecX& x, const model::Solver& settings, double qscale,
                      const std::string& where, Residual&& residual, Correction&& correction,
                      Scale&& scale, Increment&& increment) {
  StepStats st;
  double ref = 1.0;
  double first = 0.0, first_ref = 1.0;  // at the start value: the model's scale, not a diverged one
  for (int it = 0; it <= settings.max_iterations; ++it) {
    const VecX R = residual(x, true);
    st.residual = R.lpNorm<Eigen::Infinity>();
    st.iterations = it;
    if (!std::isfinite(st.residual)) break;
    ref = scale(x);
    if (it == 0) {
      first = st.residual;
      first_ref = ref;
    }
    if (st.residual <= settings.residual_tolerance * ref) return st;
    if (it == settings.max_iterations) break;
    VecX dx;
    try {
      dx = correction(R);
    } catch (const std::exception& e) {
      throw NewtonFailure(fmt::format("{}: {} at Newton iteration {}, residual {:.3e}", where,
                                      e.what(), it + 1, st.residual));
    }
    x += dx;
    if (increment(dx) <= settings.increment_tolerance * qscale) {
      st.iterations = it + 1;
      const VecX R_final = residual(x, false);
      st.residual = R_final.lpNorm<Eigen::Infinity>();
      if (std::isfinite(st.residual)) return st;
      break;
    }
  }
  // A residual that grew by orders of magnitude (or overflowed) diverged; its scale would be the
  // diverged iterate's, so the start value's is reported.
  if (!std::isfinite(st.residual) || st.residual > 1e6 * std::max(first, 1e-300))
    throw NewtonFailure(fmt::format(
        "{}: Newton diverged: the residual grew from {:.3e} to {:.3e} in {} iterations "
        "(tolerance {:.1e} x scale {:.3e} at the start)",
        where, first, st.residual, st.iterations, settings.residual_tolerance, first_ref));
  throw NewtonFailure(fmt::format(
      "{}: Newton did not converge in {} iterations; residual {:.3e} (tolerance {:.1e} x scale "
      "{:.3e})",
      where, st.iterations, st.residual, settings.residual_tolerance, ref));
}

}  // namespace isoflex::integrate
