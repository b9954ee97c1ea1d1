#pragma once
// The state a dynamic run starts from when `solver.initial_equilibrium` is N > 0: at rest, in the
// static equilibrium under the loads at t = 0. A structure hanging under gravity, a beam deflected
// by a tip load and then released (IGA-thesis §6.4.3.1) start there instead of at the unloaded
// reference.
//
// The equilibrium is found by the one static solver (static_equilibrium.hpp) on a copy of the
// model whose every load time function f(t) is replaced by s·f(0), s ∈ (0, 1] the load parameter,
// in N nominal load steps (each halved up to solver.max_subdivisions times, at least 8, when its
// Newton fails). The copy is compiled as a dynamic analysis, so its constraint rows (joints, the
// Kirchhoff–Love supports) and its coordinates are those of the run. Gravity on bodies, beams and
// shells is a constant of the model and acts in full from the first load step; a
// Kirchhoff–Love self_weight load is a time function and is stepped like the others.
#include "isoflex/math/types.hpp"
#include "isoflex/model/model.hpp"

namespace isoflex::integrate {

struct InitialEquilibrium {
  VecX q;              // the configuration, in the coordinates of System::compile(m)
  int load_steps = 0;  // accepted load steps
  int iterations = 0;  // Newton iterations over all of them
};

// Throws NewtonFailure (newton_loop.hpp) when a load step fails for good, naming it.
InitialEquilibrium initial_equilibrium(const model::Model& m);

}  // namespace isoflex::integrate
