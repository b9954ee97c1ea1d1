#pragma once
// A model run with the energy–momentum integrator, every snapshot kept (tests of the examples).
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/integrate/initial_equilibrium.hpp"
#include "isoflex/integrate/time_integrator.hpp"
#include "isoflex/system/system.hpp"

namespace isoflex::test {

struct Trajectory {
  std::vector<integrate::Snapshot> snapshots;  // the initial state, then every step
  int unknowns = 0;                            // per Newton iteration

  // The position of probe `name` at every snapshot.
  std::vector<Vec3> probe(const std::string& name) const {
    std::vector<Vec3> path;
    for (const auto& s : snapshots)
      for (const auto& p : s.probes)
        if (p.name == name) path.push_back(p.position);
    return path;
  }
  // The index of the first snapshot at t ≥ t0.
  std::size_t first_at(double t0) const {
    std::size_t i = 0;
    while (i + 1 < snapshots.size() && snapshots[i].t < t0 - 1e-9) ++i;
    return i;
  }
};

// The largest relative drift of total energy, linear and angular momentum from the snapshot at
// t0 (the first at t ≥ t0) on: what a free system keeps after its loads end.
struct Drift {
  double energy = 0.0, p = 0.0, L = 0.0;
};
inline Drift drift_after(const Trajectory& r, double t0) {
  const auto& s = r.snapshots;
  const std::size_t i0 = r.first_at(t0);
  Drift d;
  for (std::size_t i = i0; i < s.size(); ++i) {
    d.energy =
        std::max(d.energy, std::abs(s[i].total_energy - s[i0].total_energy) / s[i0].total_energy);
    d.p = std::max(
        d.p, (s[i].linear_momentum - s[i0].linear_momentum).norm() / s[i0].linear_momentum.norm());
    d.L = std::max(d.L, (s[i].angular_momentum - s[i0].angular_momentum).norm() /
                            s[i0].angular_momentum.norm());
  }
  return d;
}

// Convergence in the step: for results at Δt, Δt/2, Δt/4, … the ratios of the differences of
// successive results, |x₀ − x₁| / |x₁ − x₂|, … (4 for a second-order scheme).
inline std::vector<double> successive_ratios(const std::vector<Vec3>& at) {
  std::vector<double> r;
  for (std::size_t i = 0; i + 2 < at.size(); ++i)
    r.push_back((at[i] - at[i + 1]).norm() / (at[i + 1] - at[i + 2]).norm());
  return r;
}

// As `isoflex run`: with solver.initial_equilibrium the run starts at rest in the static
// equilibrium under the loads at t = 0 (the DAE schemes then make their consistent start there).
inline void start_in_equilibrium(const model::Model& m, integrate::State& state) {
  if (m.solver.initial_equilibrium <= 0) return;
  state.q = integrate::initial_equilibrium(m).q;
  state.v.setZero();
  state.a.resize(0);
}

// Runs m (t_end / dt steps) with the integrator its solver names (make_time_integrator).
inline Trajectory simulate(const model::Model& m) {
  const auto sys = system::System::compile(m);
  const auto integ = integrate::make_time_integrator(sys, m.solver);
  auto state = integ->initial_state();
  start_in_equilibrium(m, state);
  Trajectory r;
  r.unknowns = integ->unknowns();
  const int steps = static_cast<int>(std::lround(m.solver.t_end / m.solver.dt));
  for (int i = 0; i <= steps; ++i) {
    const auto st = i == 0 ? integrate::StepStats{} : integ->step(state);
    r.snapshots.push_back(integrate::snapshot(sys, state, st, {}));
  }
  return r;
}

// Runs m (t_end / dt steps) in formulation f.
inline Trajectory simulate(model::Model m, model::Formulation f) {
  m.solver.formulation = f;
  const auto sys = system::System::compile(m);
  const integrate::EnergyMomentumIntegrator integ(sys, m.solver);
  auto state = integ.initial_state();
  start_in_equilibrium(m, state);
  Trajectory r;
  r.unknowns = integ.unknowns();
  const int steps = static_cast<int>(std::lround(m.solver.t_end / m.solver.dt));
  for (int i = 0; i <= steps; ++i) {
    const auto st = i == 0 ? integrate::StepStats{} : integ.step(state);
    r.snapshots.push_back(integ.snapshot(state, st, {}));
  }
  return r;
}

}  // namespace isoflex::test
