#pragma once
// A step of length dt by `attempt(dt)` (which leaves the state unchanged when it throws
// NewtonFailure), retried as two halves on failure while fewer than max_subdivisions halvings
// deep: the time steps of every integrator. Each part of a subdivided energy–momentum step is
// itself such a step, so the conservation properties hold whatever the subdivision; only the
// time nodes in between are not written.
#include "isoflex/integrate/energy_momentum.hpp"

namespace isoflex::integrate {

// The iterations and abandoned starts of a failed attempt count in the step's (StepStats).
template <class Attempt>
StepStats subdivided(Attempt&& attempt, double dt, int max_subdivisions, int depth = 0) {
  int lost_iterations = 0, lost_starts = 0;
  try {
    return attempt(dt);
  } catch (const NewtonFailure& e) {
    if (depth >= max_subdivisions) throw;
    lost_iterations = e.spent_iterations();
    lost_starts = e.spent_starts();
  }
  const StepStats a = subdivided(attempt, 0.5 * dt, max_subdivisions, depth + 1);
  const StepStats b = subdivided(attempt, 0.5 * dt, max_subdivisions, depth + 1);
  return {lost_iterations + a.iterations + b.iterations, b.residual, a.substeps + b.substeps,
          lost_starts + a.failed_starts + b.failed_starts};
}

// One whole step of s by `attempt(dt)`, subdivided on failure: s.step advances by one, s.t is
// then the next point of its grid of steps dt (State::grid_start: the time of step n of a run is
// n Δt, not a sum of n increments, which drifted to 9.999000000000267 after 3333 steps of 0.003),
// and a failure (after a converged part, too) leaves s as it was.
template <class Attempt>
StepStats whole_step(State& s, Attempt&& attempt, double dt, int max_subdivisions) {
  const State start = s;
  try {
    const StepStats st = subdivided(attempt, dt, max_subdivisions);
    s.step = start.step + 1;
    if (start.grid_dt != dt) {
      s.grid_start = start.t;
      s.grid_dt = dt;
      s.grid_steps = 0;
    }
    ++s.grid_steps;
    s.t = s.grid_start + static_cast<double>(s.grid_steps) * dt;
    return st;
  } catch (const NewtonFailure&) {
    s = start;
    throw;
  }
}

}  // namespace isoflex::integrate
