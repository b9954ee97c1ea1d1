#pragma once
// The time-integrator contract of a dynamic run: a state, one step at a time, against `System`
// only. Two families implement it — the energy–momentum schemes of DNSM-III
// (energy_momentum.hpp, three formulations) and the index-3 DAE schemes of IGA-thesis ch. 2
// (dae_integrator.hpp: generalized-α, BDF-1, BDF-2) — chosen by `solver.integrator`. Both run the
// one Newton loop (newton_loop.hpp) and the one subdivision of a failing step
// (step_subdivision.hpp).
#include <memory>
#include <string>

#include "isoflex/math/types.hpp"
#include "isoflex/model/model.hpp"

namespace isoflex::system {
class System;
}

namespace isoflex::integrate {

// Everything an integrator carries from one step to the next: a run restarted from a saved State
// continues bit for bit (`isoflex run --restart`, io/hdf5_results.hpp; tests/app/
// test_cli_restart.cpp). The integrators' mutable members are no memory of the run: workspace,
// counters, and the symbolic analyses of the Newton matrices (the fill-reducing orderings kept by
// solve::FixedPatternLU, FixedPatternLDLT and NormalEquations while the pattern is unchanged),
// which depend on the pattern alone — UMFPACK 5.7's umfpack_*_symbolic reads the values only for
// its statistics (umfpack_symbolic.h) — so a new integrator makes the same ones.
struct State {
  int step = 0;
  double t = 0.0;
  // The grid of equal steps that t lies on: t = grid_start + grid_steps · grid_dt, computed as such
  // (integrate/step_subdivision.hpp whole_step): the time of step n of a run is n Δt, not a sum
  // of n increments; a step of another length starts a new grid at the current t.
  double grid_start = 0.0, grid_dt = 0.0;
  int grid_steps = 0;
  VecX q, v;
  // Energy–momentum: the converged unknowns of the last step (empty at the start) and its
  // length; the Newton predictor extrapolates with them (q_{n+1} ≈ qₙ + Δt vₙ, u ≈ uₙ Δt/Δt_last,
  // λ ≈ λₙ).
  VecX last_unknowns;
  double last_dt = 0.0;
  // Energy–momentum: the Newton start the last step converged from
  // (EnergyMomentumIntegrator::Predictor), tried first in the next step.
  int last_start = 0;
  // DAE schemes (empty until their first step): q̈ₙ, the auxiliary acceleration aₙ of
  // generalized-α (IGA-thesis (2.23)), the multipliers λₙ of the selected rows, and qₙ₋₁, vₙ₋₁
  // for BDF-2. Energy–momentum: λ of the last step where it is recovered (reactions, drivers,
  // the reduced block path's next Newton start).
  VecX a, aux, lambda, q_prev, v_prev;
  // The work done against the viscous forces since t = 0 (System::viscous_force), ≥ 0: the
  // energy–momentum schemes add f_v(q_{n+½}, Δq/Δt)·Δq, exactly what their step removes from
  // the energy; the DAE schemes the trapezoidal rule of the power f_v·q̇.
  double dissipated = 0.0;
  // The work of the external forces (loads, actuators: System::external_force) since t = 0: the
  // energy–momentum schemes add f_ext(q_{n+½}, t_{n+½})·Δq, exactly what their step adds to the
  // energy; the DAE schemes the trapezoidal rule of the power f_ext·q̇.
  double external_work = 0.0;
  // The work of the prescribed motions (joint drivers, moving supports: the rheonomic rows
  // Φ(q) = d(t)) since t = 0: the energy–momentum schemes add −λ·(d(tₙ₊₁) − d(tₙ)) over the
  // selected rows, λ the step's multipliers, exactly what the constraint forces G̃ᵀλ add to the
  // energy (system/joint_drivers.hpp), in every step of a model with joint drivers (and where
  // the reactions are recovered); the DAE schemes the trapezoidal rule of the power −λ·ḋ.
  double driver_work = 0.0;
};

struct StepStats {
  int iterations = 0;     // Newton iterations, also those of attempts then retried in halves
  double residual = 0.0;  // ‖R‖∞ at the last evaluation
  int substeps = 1;       // > 1: the step was subdivided (model::Solver::max_subdivisions)
  // Energy–momentum: Newton starts abandoned before one converged (iterations include theirs),
  // and every start of an attempt that was then retried in halves.
  int failed_starts = 0;
};

class TimeIntegrator {
 public:
  virtual ~TimeIntegrator() = default;
  // What the run reports: the formulation or the scheme ("reparametrized", "generalized_alpha").
  virtual std::string name() const = 0;
  // Size of the linear system solved per Newton iteration.
  virtual int unknowns() const = 0;
  virtual State initial_state() const = 0;
  // Advances s by one step of solver.dt (subdivided on failure as solver.max_subdivisions
  // allows); throws NewtonFailure and leaves s unchanged when it cannot.
  virtual StepStats step(State& s) const = 0;
  // Whether every step records the multipliers of the selected rows in State::lambda (the joint
  // reactions): the DAE schemes have them anyway; the energy–momentum schemes recover them at
  // one more force evaluation and a least-squares solve per step (on by default when the model has
  // joints between frame nodes; off: output.reactions false).
  virtual void set_joint_reactions(bool) {}
};

// The integrator `settings.integrator` names, for sys (which must outlive it).
std::unique_ptr<TimeIntegrator> make_time_integrator(const system::System& sys,
                                                     const model::Solver& settings);

}  // namespace isoflex::integrate
