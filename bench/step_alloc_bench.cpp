// Heap allocations of the energy–momentum step (issue #20: none in the Newton loop). The
// program interposes malloc, calloc and realloc (glibc: the executable's definitions win over
// libc's, and operator new as well as Eigen's dynamic storage go through them), counting every
// call that obtains memory, in
//   • whole steps of EnergyMomentumIntegrator: per step and, the figure of issue #20, per Newton
//     iteration — the slope b of the least-squares line allocations = a + b · iterations over
//     the steps (a: the step's own bookkeeping, start values, accept; it does not grow with
//     the iterations), beside the plain ratio allocations / iterations;
//   • the Newton iteration of the reparametrized block path alone: ReducedNewtonMatrix::evaluate
//     with the Newton matrix and ReducedNewtonMatrix::solve, repeated at a fixed state (the
//     first calls, which size the workspaces, excluded), and evaluate without the matrix.
//
//   step_alloc_bench MODEL [--steps N] [--max-per-iteration X]
// With --max-per-iteration the exit code is 1 if the slope or the block path's allocations per
// iteration exceed X (ctest: bench.zero_allocations_per_newton_iteration).
#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cmath>
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
    std::fprintf(stderr, "usage: step_alloc_bench MODEL [--steps N] [--max-per-iteration X]\n");
    return 2;
  }
  int steps = 200;
  double max_per_iteration = -1.0;  // no check
  for (int a = 2; a + 1 < argc; a += 2) {
    if (std::string(argv[a]) == "--steps") steps = std::atoi(argv[a + 1]);
    if (std::string(argv[a]) == "--max-per-iteration") max_per_iteration = std::atof(argv[a + 1]);
  }
  bool over = false;
  try {
    const model::Model m = io::read_model(argv[1]);
    const auto sys = system::System::compile(m);
    integrate::EnergyMomentumIntegrator integ(sys, m.solver);
    integrate::State s = integ.initial_state();
    integ.step(s);  // the first step sizes the workspaces
    long iterations = 0;
    long long whole = 0, fewest = -1, most = 0;
    // Least squares allocations = a + b · iterations over the steps.
    double sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0;
    for (int i = 0; i < steps; ++i) {
      const long long a0 = allocations();
      const int it = integ.step(s).iterations;
      const long long count = allocations() - a0;  // fmt below allocates: counted outside
      iterations += it;
      whole += count;
      fewest = fewest < 0 ? count : std::min(fewest, count);
      most = std::max(most, count);
      sx += it;
      sy += double(count);
      sxx += double(it) * it;
      sxy += double(it) * double(count);
    }
    const double spread = steps * sxx - sx * sx;
    const double slope = spread > 0.0 ? (steps * sxy - sx * sy) / spread : 0.0;
    fmt::print("model {}: {} steps, {} Newton iterations ({:.3f} per step)\n", argv[1], steps,
               iterations, double(iterations) / steps);
    fmt::print(
        "whole step:  {:>10} allocations, {:9.1f} per step ({} to {}), {:9.1f} per iteration "
        "(ratio)\n",
        whole, double(whole) / steps, fewest, most, double(whole) / iterations);
    fmt::print("per Newton iteration (slope over the steps): {:.2f}\n", slope);
    if (max_per_iteration >= 0.0 && !(std::abs(slope) <= max_per_iteration)) over = true;

    if (m.solver.formulation == model::Formulation::reparametrized &&
        integrate::ReducedNewtonMatrix::applicable(sys)) {
      const integrate::ReducedNewtonMatrix blocks(sys);
      solve::NormalEquations normal;
      system::SpMat J;
      const VecX u = s.last_unknowns;
      const double dt = m.solver.dt, t_mid = s.t + 0.5 * dt;
      VecX R = blocks.evaluate(s.q, s.v, u, dt, t_mid, normal, &J);
      VecX minus_R = -R;  // as EnergyMomentumIntegrator::correction, in a kept vector
      VecX du = blocks.solve(J, minus_R);
      const int calls = 100;
      const long long b0 = allocations();
      for (int i = 0; i < calls; ++i) {
        R = blocks.evaluate(s.q, s.v, u, dt, t_mid, normal, &J);
        minus_R = -R;
        du = blocks.solve(J, minus_R);
      }
      const long long iteration = allocations() - b0;
      const long long c0 = allocations();
      for (int i = 0; i < calls; ++i) R = blocks.evaluate(s.q, s.v, u, dt, t_mid, normal, nullptr);
      const long long residual = allocations() - c0;
      fmt::print(
          "block path:  {:9.1f} allocations per evaluate(J) + solve, {:9.1f} per residual "
          "alone\n",
          double(iteration) / calls, double(residual) / calls);
      if (max_per_iteration >= 0.0 && double(iteration) / calls > max_per_iteration) over = true;
    }
    if (over) {
      fmt::print("more than {} allocations per Newton iteration\n", max_per_iteration);
      return 1;
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "step_alloc_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
