// Heap allocations of the energy–momentum step (issue #20: none in the Newton loop). The
// program interposes malloc, calloc and realloc (glibc: the executable's definitions win over
// libc's, and operator new as well as Eigen's dynamic storage go through them), counting every
// call that obtains memory, in
//   • whole steps of EnergyMomentumIntegrator (per step and per Newton iteration: the step's
//     own bookkeeping included), and
//   • the Newton iteration of the reparametrized block path alone: ReducedNewtonMatrix::evaluate
//     with the Newton matrix and ReducedNewtonMatrix::solve, repeated at a fixed state (the
//     first calls, which size the workspaces, excluded), and evaluate without the matrix.
//
//   step_alloc_bench MODEL [--steps N]
#include <fmt/format.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/integrate/reduced_newton_matrix.hpp"
#include "isoflex/io/model_reader.hpp"
#include "isoflex/solve/normal_equations.hpp"

extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
}

namespace {
// Relaxed atomics: the library may start threads (KL patches); the count is all that matters.
std::atomic<long long> g_allocations{0};
long long allocations() {
  return g_allocations.load(std::memory_order_relaxed);
}
}  // namespace

extern "C" {
void* malloc(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(size);
}
void* calloc(std::size_t n, std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_calloc(n, size);
}
void* realloc(void* p, std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_realloc(p, size);
}
}

namespace {
using namespace isoflex;
}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: step_alloc_bench MODEL [--steps N]\n");
    return 2;
  }
  int steps = 200;
  for (int a = 2; a + 1 < argc; a += 2)
    if (std::string(argv[a]) == "--steps") steps = std::atoi(argv[a + 1]);
  try {
    const model::Model m = io::read_model(argv[1]);
    const auto sys = system::System::compile(m);
    integrate::EnergyMomentumIntegrator integ(sys, m.solver);
    integrate::State s = integ.initial_state();
    integ.step(s);  // the first step sizes the workspaces
    const long long a0 = allocations();
    long iterations = 0;
    for (int i = 0; i < steps; ++i) iterations += integ.step(s).iterations;
    const long long whole = allocations() - a0;
    fmt::print("model {}: {} steps, {} Newton iterations ({:.3f} per step)\n", argv[1], steps,
               iterations, double(iterations) / steps);
    fmt::print("whole step:  {:>10} allocations, {:9.1f} per step, {:9.1f} per iteration\n", whole,
               double(whole) / steps, double(whole) / iterations);

    if (m.solver.formulation == model::Formulation::reparametrized &&
        integrate::ReducedNewtonMatrix::applicable(sys)) {
      const integrate::ReducedNewtonMatrix blocks(sys);
      solve::NormalEquations normal;
      system::SpMat J;
      const VecX u = s.last_unknowns;
      const double dt = m.solver.dt, t_mid = s.t + 0.5 * dt;
      VecX R = blocks.evaluate(s.q, s.v, u, dt, t_mid, normal, &J);
      VecX du = blocks.solve(J, -R);
      const int calls = 100;
      const long long b0 = allocations();
      for (int i = 0; i < calls; ++i) {
        R = blocks.evaluate(s.q, s.v, u, dt, t_mid, normal, &J);
        du = blocks.solve(J, -R);
      }
      const long long iteration = allocations() - b0;
      const long long c0 = allocations();
      for (int i = 0; i < calls; ++i) R = blocks.evaluate(s.q, s.v, u, dt, t_mid, normal, nullptr);
      const long long residual = allocations() - c0;
      fmt::print(
          "block path:  {:9.1f} allocations per evaluate(J) + solve, {:9.1f} per residual "
          "alone\n",
          double(iteration) / calls, double(residual) / calls);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "step_alloc_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
