// Beam benchmark: a free-flying geometrically exact beam of N elements (fixed length 2, so N
// refines the mesh), started with a rigid translation and rotation plus a bending velocity field;
// no loads, joints or gravity (see bench/beam.md).
//
//   beam_bench [--n 10,100,1000,10000] [--steps S]
//              [--formulations constrained,nullspace,reparametrized] [--dt 0.005] [--repeat R]
//              [--reduced automatic|explicit|bordered|blocks] [--max-seconds S]
//
// Per N and formulation: wall time per step (steady_clock around integ.step only; compile, the
// initial state and the energy bookkeeping excluded) and the process CPU time per step
// (CLOCK_PROCESS_CPUTIME_ID around the same calls: on a shared machine it is much less disturbed
// by other jobs than the wall time), average Newton iterations per step, CPU time per Newton
// iteration, the sizes (nodes, n, m, unknowns), the path of the reduced solve, and the relative
// drifts of energy, linear and angular momentum over the run. Without --steps the number of steps
// is max(5, 20000/N). With --repeat R each run is done R times and the fastest (CPU time) is
// reported, with the spread (slowest − fastest)/fastest of the CPU time per step.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <exception>
#include <numbers>
#include <string>
#include <vector>

#include "bench_cli.hpp"
#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/math/frame_node.hpp"
#include "isoflex/model/model.hpp"
#include "isoflex/system/system.hpp"

namespace {

using namespace isoflex;
using Clock = std::chrono::steady_clock;
using model::Formulation;

struct Options {
  std::vector<int> ns{10, 100, 1000, 10000};
  int steps = 0;  // 0: max(5, 20000/N)
  std::vector<Formulation> formulations{Formulation::constrained, Formulation::nullspace,
                                        Formulation::reparametrized};
  double dt = 5e-3;
  int repeat = 1;
  integrate::ReducedSolve reduced = integrate::ReducedSolve::automatic;
  double max_seconds = 0.0;  // 0 = no limit; otherwise stop a run after this much stepping time
};

[[noreturn]] void usage(const std::string& msg) {
  std::fprintf(
      stderr,
      "beam_bench: %s\n"
      "usage: beam_bench [--n 10,100,1000,10000] [--steps S]\n"
      "                  [--formulations constrained,nullspace,reparametrized]\n"
      "                  [--dt 0.005] [--repeat R] [--reduced automatic|explicit|bordered|blocks]\n"
      "                  [--max-seconds S]\n",
      msg.c_str());
  std::exit(2);
}

Options parse(int argc, char** argv) {
  Options o;
  bench::Args args(argc, argv, usage);
  while (args.next()) {
    if (args.is("--n")) {
      o.ns = args.counts("N");
    } else if (args.is("--steps")) {
      o.steps = args.count("step count");
    } else if (args.is("--formulations")) {
      o.formulations = bench::parse_formulations(args.value(), usage);
    } else if (args.is("--dt")) {
      o.dt = args.number("time step");
      if (!(o.dt > 0)) usage("--dt must be positive");
    } else if (args.is("--repeat")) {
      o.repeat = args.count("repeat count");
    } else if (args.is("--max-seconds")) {
      o.max_seconds = args.number("time limit");
    } else if (args.is("--reduced")) {
      const std::string v = args.value();
      if (v == "automatic")
        o.reduced = integrate::ReducedSolve::automatic;
      else if (v == "explicit")
        o.reduced = integrate::ReducedSolve::explicit_null_space;
      else if (v == "bordered")
        o.reduced = integrate::ReducedSolve::bordered;
      else if (v == "blocks")
        o.reduced = integrate::ReducedSolve::blocks;
      else
        usage(fmt::format("unknown --reduced '{}'", v));
    } else {
      args.unknown();
    }
  }
  return o;
}

constexpr double kLength = 2.0;

// The beam of examples/free_flying_beam (section, length 2 along x, centred at the origin,
// d₁ = y) with N elements.
model::Model beam(int N, Formulation f, double dt) {
  model::Model m;
  m.name = fmt::format("beam{}", N);
  model::Beam b;
  b.name = "beam";
  b.points = {Vec3(-0.5 * kLength, 0, 0), Vec3(0.5 * kLength, 0, 0)};
  b.elements = {N};
  b.d1 = Vec3::UnitY();
  b.section = {1.0e4, 1.0e4, 1.0e4, 50.0, 80.0, 40.0, 1.0, 0.01, 0.005};
  m.beams.push_back(b);
  m.solver.formulation = f;
  m.solver.dt = dt;
  return m;
}

// Admissible initial velocities (frame node i: φ̇ = vᵢ, ḋ_I = ωᵢ × d_I): the rigid motion
// v₀ + ω₀ × φ, ω₀, plus the bending field w(x) = A cos(πx/L) e_z with the matching rotation rate
// −w′(x) about y (the cross-sections stay normal to the centreline's velocity field).
VecX initial_velocity(const system::System& sys) {
  const Vec3 v0(0.0, 0.1, 0.2), w0(5.0, 0.0, 1.0);  // spin about the axis, tumbling about z
  const double A = 1.0, k = std::numbers::pi / kLength;
  VecX v = VecX::Zero(sys.n());
  for (int i = 0; i < sys.node_count(); ++i) {
    const frame_node::Q q = sys.q0().segment<12>(12 * i);
    const Vec3 phi = frame_node::phi(q);
    const Vec3 vel = v0 + w0.cross(phi) + A * std::cos(k * phi.x()) * Vec3::UnitZ();
    const Vec3 omega = w0 + A * k * std::sin(k * phi.x()) * Vec3::UnitY();
    v.segment<3>(12 * i) = vel;
    for (int I = 0; I < 3; ++I)
      v.segment<3>(12 * i + 3 + 3 * I) = omega.cross(frame_node::director(q, I));
  }
  return v;
}

double seconds(Clock::duration d) {
  return std::chrono::duration<double>(d).count();
}

// CPU time of the process (the program is single-threaded).
double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

struct RunResult {
  int N = 0;
  Formulation f{};
  int nodes = 0, n = 0, m = 0, k = 0, unknowns = 0;
  int steps_requested = 0, steps_done = 0;
  double per_step_s = 0.0, cpu_per_step_s = 0.0, avg_iterations = 0.0, spread = 0.0;
  double dE = 0.0, dp = 0.0, dL = 0.0, max_violation = 0.0;
  std::string solve;
  std::string status = "ok";
};

void run_once(const system::System& sys, const integrate::EnergyMomentumIntegrator& integ,
              const Options& o, RunResult& r) {
  integrate::State s = integ.initial_state();
  s.v = initial_velocity(sys);
  const auto a = integ.snapshot(s, {}, {});
  Clock::duration stepping{};
  double cpu = 0.0;
  long iterations = 0;
  double scale = std::max(std::abs(a.total_energy), a.kinetic_energy);
  double dE = 0.0;
  for (int i = 0; i < r.steps_requested; ++i) {
    integrate::StepStats st;
    const auto t0 = Clock::now();
    const double c0 = cpu_seconds();
    try {
      st = integ.step(s);
    } catch (const std::exception& e) {
      stepping += Clock::now() - t0;
      cpu += cpu_seconds() - c0;
      r.status = fmt::format("Newton failure: {}", e.what());
      break;
    }
    cpu += cpu_seconds() - c0;
    stepping += Clock::now() - t0;
    ++r.steps_done;
    iterations += st.iterations;
    // Bookkeeping, outside the timed region.
    const auto b = integ.snapshot(s, st, {});
    scale = std::max({scale, b.kinetic_energy, std::abs(b.potential_energy)});
    dE = std::max(dE, std::abs(b.total_energy - a.total_energy));
    r.dp =
        std::max(r.dp, (b.linear_momentum - a.linear_momentum).norm() / a.linear_momentum.norm());
    r.dL = std::max(r.dL,
                    (b.angular_momentum - a.angular_momentum).norm() / a.angular_momentum.norm());
    r.max_violation = std::max(r.max_violation, b.constraint_violation);
    if (o.max_seconds > 0 && seconds(stepping) > o.max_seconds && i + 1 < r.steps_requested) {
      r.status = fmt::format("stopped by --max-seconds after {} steps", r.steps_done);
      break;
    }
  }
  r.dE = dE / scale;
  if (r.steps_done > 0) {
    r.per_step_s = seconds(stepping) / r.steps_done;
    r.cpu_per_step_s = cpu / r.steps_done;
    r.avg_iterations = double(iterations) / r.steps_done;
  }
}

RunResult run(int N, Formulation f, const Options& o) {
  RunResult r;
  r.N = N;
  r.f = f;
  r.steps_requested = o.steps > 0 ? o.steps : std::max(5, 20000 / N);
  const model::Model m = beam(N, f, o.dt);
  const system::System sys = system::System::compile(m);
  const integrate::EnergyMomentumIntegrator integ(sys, m.solver, o.reduced);
  r.solve = f == Formulation::constrained ? "full"
            : integ.tree_recursion()      ? "tree"
            : integ.block_assembly()      ? "blocks"
            : integ.bordered()            ? "bordered"
                                          : "explicit";
  r.nodes = sys.node_count();
  r.n = sys.n();
  r.m = sys.m_selected();
  r.k = sys.k();
  r.unknowns = integ.unknowns();
  RunResult best;
  double slowest = 0.0;
  for (int rep = 0; rep < o.repeat; ++rep) {
    RunResult x = r;
    run_once(sys, integ, o, x);
    slowest = std::max(slowest, x.cpu_per_step_s);
    if (rep == 0 || x.cpu_per_step_s < best.cpu_per_step_s) best = x;
  }
  best.spread =
      best.cpu_per_step_s > 0 ? (slowest - best.cpu_per_step_s) / best.cpu_per_step_s : 0.0;
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  fmt::print(
      "free-flying beam, length {:g}, N elements, dt = {:g}, steps {}, fastest (CPU time) of {} "
      "run(s)\n\n",
      kLength, o.dt, o.steps > 0 ? std::to_string(o.steps) : std::string("max(5, 20000/N)"),
      o.repeat);
  fmt::print(
      "{:>6} {:<15} {:<8} {:>6} {:>7} {:>7} {:>8} {:>5} {:>10} {:>10} {:>6} {:>9} {:>6} {:>9} "
      "{:>9} {:>9} {:>9} {}\n",
      "N", "formulation", "solve", "nodes", "n", "m", "unknowns", "steps", "ms/step", "cpu_ms/st",
      "avg_it", "cpu_ms/it", "spread", "dE_rel", "dp_rel", "dL_rel", "max|Phi|", "status");
  std::vector<RunResult> runs;
  for (int N : o.ns) {
    for (Formulation f : o.formulations) {
      const RunResult r = run(N, f, o);
      fmt::print(
          "{:>6} {:<15} {:<8} {:>6} {:>7} {:>7} {:>8} {:>5} {:>10.3f} {:>10.3f} {:>6.2f} {:>9.3f} "
          "{:>5.0f}% {:>9.2e} {:>9.2e} {:>9.2e} {:>9.2e} {}\n",
          r.N, model::to_string(r.f), r.solve, r.nodes, r.n, r.m, r.unknowns, r.steps_done,
          1e3 * r.per_step_s, 1e3 * r.cpu_per_step_s, r.avg_iterations,
          r.avg_iterations > 0 ? 1e3 * r.cpu_per_step_s / r.avg_iterations : 0.0, 100.0 * r.spread,
          r.dE, r.dp, r.dL, r.max_violation, r.status);
      std::fflush(stdout);
      runs.push_back(r);
    }
  }
  // Growth of the CPU time per step and per Newton iteration between consecutive N: linear cost
  // means a ratio equal to the ratio of the N.
  fmt::print("\ngrowth of the CPU time between consecutive N (linear: equal to the ratio of N)\n");
  for (Formulation f : o.formulations) {
    const RunResult* prev = nullptr;
    for (const auto& r : runs) {
      if (r.f != f || r.steps_done == 0) continue;
      if (prev)
        fmt::print(
            "  {:<15} N {:>5} -> {:>5} (x{:g}): per step x{:.2f}, per iteration x{:.2f}\n",
            model::to_string(f), prev->N, r.N, double(r.N) / prev->N,
            r.cpu_per_step_s / prev->cpu_per_step_s,
            (r.cpu_per_step_s / r.avg_iterations) / (prev->cpu_per_step_s / prev->avg_iterations));
      prev = &r;
    }
  }
  return 0;
}
