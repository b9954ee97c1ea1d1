#pragma once
// Co-simulation of the Kirchhoff–Love shells with the rest of a model (IGA-thesis §6.3.2,
// Fig. 6.8: serial exchange after [Goy11]). The model is split in two: the shell part (surfaces,
// kl_shells and their supports to the ground, loads, interfaces, springs among shell points and
// the ground) and the multibody part (bodies, beams, director shells, joints, their loads). The
// springs between the two (IGA-thesis (6.8)–(6.9), the pointwise interaction) appear in each part
// with the other part's end as a moving point of the ground, an anchor
// (System::move_spring_anchor). Each part has its own system and integrator (the model's, with
// its dt); every macro step H:
//   1. the shell part steps from t_k to t_k + H, the anchors (the multibody points) held at
//      their values at t_k (hold: constant) or extrapolated with their velocities (linear),
//      evaluated at each micro step's midpoint;
//   2. the multibody part steps from t_k to t_k + H, the anchors (the shell points) interpolated
//      between their values at t_k and t_k + H (linear) or held at t_k + H (constant).
// The monolithic run (one system, the default) conserves energy and momenta to round-off; the
// exchange does not, and its error falls with H (bench/cosimulation.md). Other couplings across
// the split (joints at shell points, joints at control points, supports to a body) are refused:
// they would need the exchange of constraint forces.
#include <memory>
#include <string>
#include <vector>

#include "isoflex/integrate/snapshot.hpp"
#include "isoflex/integrate/time_integrator.hpp"
#include "isoflex/model/model.hpp"
#include "isoflex/system/system.hpp"

namespace isoflex::integrate {

class CoSimulation {
 public:
  // m.solver.cosimulation must be set. Throws system::CompileError (located in the model file)
  // for a coupling across the split that is not a spring, or for a split with an empty side.
  explicit CoSimulation(const model::Model& m);
  ~CoSimulation();

  double t() const { return t_; }
  double macro_step() const { return H_; }
  int micro_steps() const { return micro_; }  // per macro step, H / dt
  int macro_steps_taken() const { return k_; }
  int crossing_springs() const;
  const State& mbs_state() const { return mbs_state_; }
  const State& shell_state() const { return shell_state_; }
  const system::System& mbs() const { return *mbs_; }
  const system::System& shell() const { return *shell_; }
  // The unknowns of one Newton iteration of each part.
  int mbs_unknowns() const;
  int shell_unknowns() const;

  // Advances both parts by one macro step; throws NewtonFailure (the step, time and part named).
  StepStats advance();

  // The coupled state: energies, momenta and probes summed over the parts, the crossing springs'
  // energy and values from their true end points (not from the anchors), the bodies, beams and
  // reactions of the multibody part, the patches of the shell part.
  Snapshot snapshot(const StepStats& st) const;

 private:
  struct Crossing;
  void anchor_shell_side(double t);
  void anchor_mbs_side(double t);

  double H_, dt_, t_ = 0.0;
  int micro_ = 1, k_ = 0;
  model::CoSimulationHold hold_;
  std::vector<std::string> mbs_bodies_;
  std::unique_ptr<system::System> mbs_, shell_;
  std::unique_ptr<TimeIntegrator> mbs_integ_, shell_integ_;
  State mbs_state_, shell_state_;
  std::vector<Crossing> crossing_;
};

}  // namespace isoflex::integrate
