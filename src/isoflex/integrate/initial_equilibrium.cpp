#include "isoflex/integrate/initial_equilibrium.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <string>

#include "isoflex/integrate/static_equilibrium.hpp"
#include "isoflex/loads/time_function.hpp"
#include "isoflex/system/system.hpp"

namespace isoflex::integrate {

namespace {

// f(t) → s·f(0), written with 17 digits so that s = 1 gives f(0) exactly.
void at_start(std::string& f) {
  f = fmt::format("t*({:.17g})", loads::TimeFunction(f)(0.0));
}
void at_start(std::array<std::string, 3>& f) {
  for (std::string& c : f) at_start(c);
}
template <class T>
void at_start(std::optional<T>& f) {
  if (f) at_start(*f);
}

model::Model preload_model(const model::Model& m) {
  model::Model p = m;
  for (auto& l : p.loads) {
    at_start(l.force);
    at_start(l.moment);
  }
  for (auto& l : p.distributed_loads) at_start(l.force_per_length);
  for (auto& l : p.shell_loads) {
    at_start(l.force);
    at_start(l.moment);
    at_start(l.pressure);
    at_start(l.area_force);
  }
  for (auto& l : p.kl_loads) {
    at_start(l.force);
    at_start(l.pressure);
    at_start(l.factor);
    at_start(l.moment);
  }
  for (auto& s : p.kl_supports) at_start(s.displacement);
  model::Solver& s = p.solver;
  s.analysis = model::Analysis::dynamic;  // the rows of the run (compile), solved statically
  s.t_end = 1.0;
  s.dt = 1.0 / m.solver.initial_equilibrium;
  s.max_subdivisions = std::max(8, m.solver.max_subdivisions);
  s.linear = false;
  return p;
}

}  // namespace

InitialEquilibrium initial_equilibrium(const model::Model& m) {
  const model::Model p = preload_model(m);
  const system::System sys = system::System::compile(p);
  StaticEquilibrium equilibrium(sys, p.solver);
  InitialEquilibrium out;
  try {
    const StaticResult r = equilibrium.solve([&](const LoadStepStats& st, const VecX&) {
      ++out.load_steps;
      out.iterations += st.iterations;
    });
    out.q = r.x.head(sys.n());
  } catch (const NewtonFailure& e) {
    throw NewtonFailure(
        fmt::format("initial equilibrium (solver.initial_equilibrium): {}", e.what()));
  }
  return out;
}

}  // namespace isoflex::integrate
