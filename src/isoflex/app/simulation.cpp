#include "isoflex/app/simulation.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <thread>

#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/integrate/initial_equilibrium.hpp"

namespace isoflex::app {

std::vector<std::string> body_names(const model::Model& m) {
  std::vector<std::string> names;
  for (const auto& b : m.bodies) names.push_back(b.name);
  for (const auto& b : m.beams)
    for (int i = 0; i < b.node_count(); ++i) names.push_back(fmt::format("{}[{}]", b.name, i));
  return names;
}

// A cheap scan (O(n)) after every step, so that overflow (e.g. an absurdly thin shell) ends the
// run instead of being recorded as results.
std::string non_finite_results(const integrate::Snapshot& snap, const integrate::State& state) {
  std::vector<std::string> parts;
  if (!std::isfinite(snap.kinetic_energy)) parts.push_back("kinetic energy");
  if (!std::isfinite(snap.potential_energy)) parts.push_back("potential energy");
  const auto vector_part = [&](const VecX& x, const char* name) {
    Eigen::Index count = 0, first = -1;
    for (Eigen::Index i = 0; i < x.size(); ++i)
      if (!std::isfinite(x[i]) && count++ == 0) first = i;
    if (count > 0)
      parts.push_back(fmt::format("{} ({} of {} entries, the first at index {})", name, count,
                                  x.size(), first));
  };
  vector_part(state.q, "coordinates q");
  vector_part(state.v, "velocities v");
  std::string text;
  for (const std::string& p : parts) text += (text.empty() ? "" : ", ") + p;
  return text;
}

Simulation::Simulation(model::Model m, int threads) : model_(std::move(m)) {
  if (model_.solver.cosimulation)
    throw std::invalid_argument(
        "a co-simulation model (solver.cosimulation) runs with the isoflex tool only");
  sys_ = std::make_unique<system::System>(system::System::compile(model_));
  sys_->set_threads(
      threads > 0 ? threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency())));
  names_ = body_names(model_);
  // As `isoflex run` starts (app/commands.cpp), so that both take the same steps.
  state_.q = sys_->q0();
  state_.v = statics() ? VecX::Zero(sys_->n()) : sys_->v0();
  if (!statics() && model_.solver.initial_equilibrium > 0) {
    const integrate::InitialEquilibrium eq = integrate::initial_equilibrium(model_);
    state_.q = eq.q;
    state_.v.setZero();
    initial_load_steps_ = eq.load_steps;
  }
  if (!statics()) {
    integ_ = integrate::make_time_integrator(*sys_, model_.solver);
    integ_->set_joint_reactions(model_.output.history && model_.output.reactions &&
                                !(model_.joints.empty() && model_.kl_surface_joints.empty()));
  }
  current_ = integrate::snapshot(*sys_, state_, {}, names_);
}

int Simulation::unknowns() const {
  return integ_ ? integ_->unknowns()
                : integrate::StaticEquilibrium(*sys_, model_.solver).unknowns();
}

void Simulation::accept(const integrate::State& next, const integrate::StepStats& st,
                        const char* what, double path) {
  integrate::Snapshot snap = integrate::snapshot(*sys_, next, st, names_);
  snap.path = path;
  if (const std::string bad = non_finite_results(snap, next); !bad.empty())
    throw integrate::NewtonFailure(
        fmt::format("{} {} (t = {:.6g}): non-finite results: {}", what, next.step, next.t, bad));
  state_ = next;  // into the same buffers: numpy views of the state stay valid
  current_ = std::move(snap);
}

integrate::StepStats Simulation::step() {
  if (!integ_) throw std::logic_error("a static model has load steps (solve_static), not steps");
  integrate::State next = state_;
  const integrate::StepStats st = integ_->step(next);
  accept(next, st, "step", 0.0);
  return st;
}

integrate::StaticResult Simulation::solve_static(const std::function<void()>& each) {
  if (!statics()) throw std::logic_error("a dynamic model has time steps (step), not load steps");
  if (solved_) throw std::logic_error("the load stepping of this simulation has been done");
  solved_ = true;
  integrate::StaticEquilibrium equilibrium(*sys_, model_.solver);
  const int n = sys_->n(), m = sys_->m_selected();
  return equilibrium.solve([&](const integrate::LoadStepStats& st, const VecX& x) {
    integrate::State next = state_;
    next.q = x.head(n);
    next.lambda = x.segment(n, m);
    next.t = st.t;
    next.step = st.step;
    accept(next, {st.iterations, st.residual, st.cuts + 1}, "load step", st.path);
    if (each) each();
  });
}

}  // namespace isoflex::app
