#pragma once
// A model set up to run step by step, what `isoflex run` does between reading the model and
// writing the results, for programs that use isoflex as a library (the Python module, python/).
// The run's outputs are not written here (app/run_outputs.hpp does that, fed with snapshot()).
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "isoflex/integrate/snapshot.hpp"
#include "isoflex/integrate/static_equilibrium.hpp"
#include "isoflex/integrate/time_integrator.hpp"
#include "isoflex/model/model.hpp"
#include "isoflex/system/system.hpp"

namespace isoflex::app {

class Simulation {
 public:
  // Compiles `m` (system::CompileError on a model that cannot be), finds the initial equilibrium
  // if the model asks for it (NewtonFailure when it cannot), and sets the state to t = 0.
  // threads: of the Kirchhoff–Love shell assembly, 0 = every hardware thread. A co-simulation
  // model is refused (std::invalid_argument): it runs with the `isoflex` tool only.
  explicit Simulation(model::Model m, int threads = 0);

  const model::Model& model() const { return model_; }
  const system::System& system() const { return *sys_; }
  const integrate::State& state() const { return state_; }
  bool statics() const { return model_.solver.analysis == model::Analysis::statics; }
  // Size of the linear system of a Newton iteration.
  int unknowns() const;
  // The initial equilibrium's load steps (0: the model has none).
  int initial_equilibrium_load_steps() const { return initial_load_steps_; }

  // The current state as the outputs see it, with the last step's Newton figures.
  const integrate::Snapshot& snapshot() const { return current_; }

  // One time step of solver.dt. Throws NewtonFailure (the state stays that of the last step),
  // also for non-finite results; std::logic_error for a static model.
  integrate::StepStats step();

  // The load stepping of a static model from its initial state; `each` after every accepted
  // load step (the state is already that of the step). Throws NewtonFailure when a load step fails
  // for good (the state stays that of the last accepted one); std::logic_error for a dynamic
  // model or a second call.
  integrate::StaticResult solve_static(const std::function<void()>& each = {});

 private:
  model::Model model_;
  std::unique_ptr<system::System> sys_;
  std::vector<std::string> names_;
  // Makes `next` the state if its results are finite (NewtonFailure naming the `what` otherwise).
  void accept(const integrate::State& next, const integrate::StepStats& st, const char* what,
              double path);

  integrate::State state_;
  integrate::Snapshot current_;  // of state_
  int initial_load_steps_ = 0;
  bool solved_ = false;
  std::unique_ptr<integrate::TimeIntegrator> integ_;
};

// The names of Snapshot::bodies: the bodies, then each beam's nodes as NAME[i].
std::vector<std::string> body_names(const model::Model& m);

// What of a state is not finite ("" if all is): the energies of `snap`, then the coordinates q
// and velocities v with how many entries and the first.
std::string non_finite_results(const integrate::Snapshot& snap, const integrate::State& state);

}  // namespace isoflex::app
