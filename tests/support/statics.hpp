#pragma once
// The static analysis of a model in process (integrate/static_equilibrium.hpp): the model
// compiled as a System, the load stepping run, every accepted load step kept.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "isoflex/integrate/static_equilibrium.hpp"
#include "isoflex/model/model.hpp"
#include "isoflex/system/system.hpp"

namespace isoflex::test {

struct StaticStep {
  double t = 0.0;
  VecX q;  // the configuration (without multipliers)
  int iterations = 0, cuts = 0;
};

struct StaticRun {
  std::vector<StaticStep> steps;
  std::string failure;  // NewtonFailure's message, empty if the run reached t_end
  int unknowns = 0;
};

// Runs the load stepping of m (solver.analysis is taken as static) on sys.
inline StaticRun solve_static(const system::System& sys, const model::Model& m) {
  StaticRun run;
  integrate::StaticEquilibrium eq(sys, m.solver);
  run.unknowns = eq.unknowns();
  try {
    eq.solve([&](const integrate::LoadStepStats& st, const VecX& x) {
      run.steps.push_back({st.t, x.head(sys.n()), st.iterations, st.cuts});
    });
  } catch (const integrate::NewtonFailure& e) {
    run.failure = e.what();
  }
  return run;
}

// The model compiled for a static analysis.
inline system::System static_system(model::Model m) {
  m.solver.analysis = model::Analysis::statics;
  return system::System::compile(m);
}

// The position of the probe named `name` in q.
inline Vec3 probe_at(const system::System& sys, const VecX& q, const std::string& name) {
  for (const auto& p : sys.probes())
    if (p.name == name) return sys.probe_point(q, p);
  ADD_FAILURE() << "no probe " << name;
  return Vec3::Zero();
}

}  // namespace isoflex::test
