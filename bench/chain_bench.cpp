// Chain benchmark: N slender rigid bodies linked by spherical joints, hanging from the ground,
// swinging from an initially horizontal configuration under gravity (see bench/chain.md).
//
//   chain_bench [--n 10,100] [--steps 1000] [--formulations constrained,nullspace,reparametrized]
//               [--cond] [--dt 0.01] [--csv FILE] [--max-seconds S]
//               [--reduced automatic|explicit|bordered|tree] [--repeat R]
//
// Per N and formulation: wall time per step (steady_clock, total over the stepping loop / steps,
// System::compile and the energy bookkeeping excluded), average Newton iterations per step, the
// sizes n, m_selected, k and the size of the Newton system, and the relative energy drift
// max|E − E₀|/|E₀|. With --cond: the 2-norm condition number of the Newton matrix of the first
// step at the Newton start and at the converged solution, for Δt ∈ {1e-2, 1e-3, 1e-4}.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <optional>
#include <string>
#include <vector>

#include "bench_cli.hpp"
#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/model/model.hpp"
#include "isoflex/solve/linear_solver.hpp"
#include "isoflex/system/system.hpp"
#include "newton_condition.hpp"

namespace {

using namespace isoflex;
using Clock = std::chrono::steady_clock;
using model::Formulation;

struct Options {
  std::vector<int> ns{10, 100};
  int steps = 1000;
  std::vector<Formulation> formulations{Formulation::constrained, Formulation::nullspace,
                                        Formulation::reparametrized};
  bool cond = false;
  double dt = 1e-2;
  std::string csv;
  double max_seconds = 0.0;  // 0 = no limit; otherwise stop a run after this much stepping time
  // How the null-space and reparametrized Newton systems are solved (integrate::ReducedSolve).
  integrate::ReducedSolve reduced = integrate::ReducedSolve::automatic;
  int repeat = 1;  // run each configuration this many times, report the fastest
};

[[noreturn]] void usage(const std::string& msg) {
  std::fprintf(stderr,
               "chain_bench: %s\n"
               "usage: chain_bench [--n 10,100] [--steps 1000]\n"
               "                   [--formulations constrained,nullspace,reparametrized]\n"
               "                   [--cond] [--dt 0.01] [--csv FILE] [--max-seconds S]\n"
               "                   [--reduced automatic|explicit|bordered|tree] [--repeat R]\n",
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
    } else if (args.is("--cond")) {
      o.cond = true;
    } else if (args.is("--dt")) {
      o.dt = args.number("time step");
      if (!(o.dt > 0)) usage("--dt must be positive");
    } else if (args.is("--csv")) {
      o.csv = args.value();
    } else if (args.is("--max-seconds")) {
      o.max_seconds = args.number("time limit");
    } else if (args.is("--repeat")) {
      o.repeat = args.count("repeat count");
    } else if (args.is("--reduced")) {
      const std::string v = args.value();
      if (v == "automatic")
        o.reduced = integrate::ReducedSolve::automatic;
      else if (v == "explicit")
        o.reduced = integrate::ReducedSolve::explicit_null_space;
      else if (v == "bordered")
        o.reduced = integrate::ReducedSolve::bordered;
      else if (v == "tree")
        o.reduced = integrate::ReducedSolve::tree;
      else
        usage(fmt::format("unknown --reduced '{}'", v));
    } else {
      args.unknown();
    }
  }
  return o;
}

// The chain: body i spans x ∈ [i, i + 1] (d₁ = x), spherical joints at x = 0 (to the ground),
// 1, …, N − 1. The first body turns about z at 0.5 rad/s; System::compile projects the given
// velocities onto the admissible ones.
model::Model chain(int N, Formulation f, double dt) {
  model::Model m;
  m.name = fmt::format("chain{}", N);
  m.gravity = Vec3(0, 0, -9.81);
  for (int i = 0; i < N; ++i) {
    model::Body b;
    b.name = fmt::format("b{}", i);
    b.mass = 1.0;
    b.inertia = Vec3(0.01, 1.0 / 12.0, 1.0 / 12.0);
    b.position = Vec3(i + 0.5, 0, 0);
    b.orientation = Mat3::Identity();
    b.shape.kind = model::ShapeKind::box;
    b.shape.size = Vec3(1.0, 0.1, 0.1);
    if (i == 0) {
      b.angular_velocity = Vec3(0, 0, 0.5);
      b.velocity = b.angular_velocity.cross(b.position);
    }
    m.bodies.push_back(b);
    model::Joint j;
    j.name = fmt::format("s{}", i);
    j.type = model::JointType::spherical;
    j.body_a = i == 0 ? std::string("ground") : fmt::format("b{}", i - 1);
    j.body_b = b.name;
    j.point = Vec3(i, 0, 0);
    m.joints.push_back(j);
  }
  m.solver.formulation = f;
  m.solver.dt = dt;
  return m;
}

double seconds(Clock::duration d) {
  return std::chrono::duration<double>(d).count();
}

struct RunResult {
  int N = 0;
  Formulation f{};
  int n = 0, m_selected = 0, k = 0, dof = 0, unknowns = 0;
  int steps_requested = 0, steps_done = 0;
  double compile_s = 0.0, total_s = 0.0, per_step_s = 0.0;
  double avg_iterations = 0.0;
  int max_iterations = 0;
  double E0 = 0.0, drift_abs = 0.0, drift_rel = 0.0, max_violation = 0.0;
  double max_kinetic = 0.0;  // max T over the run: the energy scale of the motion
  int repeats = 1;
  double spread = 0.0;  // (slowest − fastest)/fastest time per step over the repeats
  std::string solve;    // "full" (constrained), "explicit" or "bordered" (reduced formulations)
  std::string status = "ok";
};

void run_once(const integrate::EnergyMomentumIntegrator& integ, int N, Formulation f,
              const Options& o, RunResult& r);

RunResult run(int N, Formulation f, const Options& o) {
  RunResult r;
  r.N = N;
  r.f = f;
  r.steps_requested = o.steps;
  const model::Model m = chain(N, f, o.dt);
  const auto c0 = Clock::now();
  const system::System sys = system::System::compile(m);
  r.compile_s = seconds(Clock::now() - c0);
  // The tree recursion exists for the reparametrized formulation only.
  const auto how = o.reduced == integrate::ReducedSolve::tree && f != Formulation::reparametrized
                       ? integrate::ReducedSolve::automatic
                       : o.reduced;
  const integrate::EnergyMomentumIntegrator integ(sys, m.solver, how);
  r.solve = f == Formulation::constrained ? "full"
            : integ.tree_recursion()      ? "tree"
            : integ.bordered()            ? "bordered"
                                          : "explicit";
  r.n = sys.n();
  r.m_selected = sys.m_selected();
  r.k = sys.k();
  r.dof = sys.dof();
  r.unknowns = integ.unknowns();

  // The run is deterministic; with --repeat R it is done R times and the fastest is reported
  // (the machine is shared), with the spread (max − min)/min of the time per step.
  RunResult best;
  double slowest = 0.0;
  for (int rep = 0; rep < o.repeat; ++rep) {
    RunResult x = r;
    run_once(integ, N, f, o, x);
    slowest = std::max(slowest, x.per_step_s);
    if (rep == 0 || x.per_step_s < best.per_step_s) best = x;
  }
  best.repeats = o.repeat;
  best.spread = best.per_step_s > 0 ? (slowest - best.per_step_s) / best.per_step_s : 0.0;
  return best;
}

void run_once(const integrate::EnergyMomentumIntegrator& integ, int N, Formulation f,
              const Options& o, RunResult& r) {
  integrate::State s = integ.initial_state();
  const integrate::Snapshot snap0 = integ.snapshot(s, {}, {});
  r.E0 = snap0.total_energy;
  Clock::duration stepping{};
  long iterations = 0;
  for (int i = 0; i < o.steps; ++i) {
    integrate::StepStats st;
    const auto t0 = Clock::now();
    try {
      st = integ.step(s);
    } catch (const std::exception& e) {
      stepping += Clock::now() - t0;
      r.status = fmt::format("Newton failure: {}", e.what());
      break;
    }
    const auto dt_step = Clock::now() - t0;
    stepping += dt_step;
    ++r.steps_done;
    iterations += st.iterations;
    r.max_iterations = std::max(r.max_iterations, st.iterations);
    if (seconds(dt_step) > 1.0)
      std::fprintf(stderr, "  [N=%d %s] step %d: %.2f s, %d iterations\n", N, model::to_string(f),
                   i + 1, seconds(dt_step), st.iterations);
    // Energy bookkeeping, outside the timed region.
    const integrate::Snapshot snap = integ.snapshot(s, st, {});
    r.drift_abs = std::max(r.drift_abs, std::abs(snap.total_energy - r.E0));
    r.max_kinetic = std::max(r.max_kinetic, snap.kinetic_energy);
    r.max_violation = std::max(r.max_violation, snap.constraint_violation);
    if (o.max_seconds > 0 && seconds(stepping) > o.max_seconds && i + 1 < o.steps) {
      r.status = fmt::format("stopped by --max-seconds after {} steps", r.steps_done);
      break;
    }
  }
  r.total_s = seconds(stepping);
  if (r.steps_done > 0) {
    r.per_step_s = r.total_s / r.steps_done;
    r.avg_iterations = double(iterations) / r.steps_done;
  }
  r.drift_rel = r.drift_abs / std::abs(r.E0);
}

struct CondResult {
  int N = 0;
  Formulation f{};
  double dt = 0.0;
  int size_rows = 0, size_cols = 0;
  double cond_start = 0.0, cond_converged = 0.0;
  double cond_scaled = 0.0;  // diagnostic: converged J with Δt-scaled rows/columns (see below)
  int newton_iterations = 0;
  double final_residual = 0.0;
  double seconds = 0.0;
};

// Condition numbers of the Newton matrix of the first step, at the Newton start and at the
// converged solution (bench/newton_condition.hpp).
CondResult condition(const system::System& sys, int N, Formulation f, double dt) {
  const auto t0 = Clock::now();
  model::Solver settings;
  settings.formulation = f;
  settings.dt = dt;
  const bench::NewtonCondition nc = bench::newton_condition(sys, settings);
  CondResult c;
  c.N = N;
  c.f = f;
  c.dt = dt;
  c.size_rows = nc.rows;
  c.size_cols = nc.cols;
  c.cond_start = nc.at_start;
  c.cond_converged = nc.converged;
  c.cond_scaled = nc.converged_scaled;
  c.newton_iterations = nc.iterations;
  c.final_residual = nc.final_residual;
  c.seconds = seconds(Clock::now() - t0);
  return c;
}

std::string csv_cond_path(const std::string& path) {
  const std::size_t dot = path.rfind('.');
  const std::size_t slash = path.rfind('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash))
    return path + "_cond.csv";
  return path.substr(0, dot) + "_cond" + path.substr(dot);
}

const RunResult* find(const std::vector<RunResult>& runs, int N, Formulation f) {
  for (const auto& r : runs)
    if (r.N == N && r.f == f && r.steps_done > 0) return &r;
  return nullptr;
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);

  std::vector<RunResult> runs;
  fmt::print("chain of N bodies on spherical joints, dt = {:g}, {} steps, fastest of {} run(s)\n\n",
             o.dt, o.steps, o.repeat);
  fmt::print(
      "{:>6} {:<15} {:<8} {:>6} {:>6} {:>6} {:>8} {:>6} {:>11} {:>7} {:>9} {:>6} {:>6} {:>9} {:>9} "
      "{:>9} {:>9} {}\n",
      "N", "formulation", "solve", "n", "m_sel", "k", "unknowns", "steps", "ms/step", "avg_it",
      "ms/iter", "spread", "max_it", "dE_rel", "dE_abs", "dE/maxT", "max|Phi|", "status");
  for (int N : o.ns) {
    for (Formulation f : o.formulations) {
      const RunResult r = run(N, f, o);
      fmt::print(
          "{:>6} {:<15} {:<8} {:>6} {:>6} {:>6} {:>8} {:>6} {:>11.3f} {:>7.3f} {:>9.3f} {:>5.0f}% "
          "{:>6} "
          "{:>9.2e} {:>9.2e} {:>9.2e} {:>9.2e} {}\n",
          r.N, model::to_string(r.f), r.solve, r.n, r.m_selected, r.k, r.unknowns, r.steps_done,
          1e3 * r.per_step_s, r.avg_iterations,
          r.avg_iterations > 0 ? 1e3 * r.per_step_s / r.avg_iterations : 0.0, 100.0 * r.spread,
          r.max_iterations, r.drift_rel, r.drift_abs,
          r.max_kinetic > 0 ? r.drift_abs / r.max_kinetic : 0.0, r.max_violation, r.status);
      std::fflush(stdout);
      runs.push_back(r);
    }
  }
  if (!runs.empty())
    fmt::print("(E0 = {:.6g}; compile times [s]:{})\n", runs.front().E0, [&] {
      std::string s;
      for (const auto& r : runs)
        s += fmt::format(" {}/{}={:.3f}", r.N, model::to_string(r.f), r.compile_s);
      return s;
    }());

  // Ratios.
  fmt::print("\nratios\n");
  for (int N : o.ns) {
    const RunResult* c = find(runs, N, Formulation::constrained);
    const RunResult* p = find(runs, N, Formulation::reparametrized);
    const RunResult* z = find(runs, N, Formulation::nullspace);
    if (c && p)
      fmt::print(
          "  N = {:>5}: time/step constrained / reparametrized = {:.3f}  (goal >= 2 at N = "
          "100)\n",
          N, c->per_step_s / p->per_step_s);
    if (c && z)
      fmt::print("  N = {:>5}: time/step constrained / nullspace      = {:.3f}\n", N,
                 c->per_step_s / z->per_step_s);
  }
  for (Formulation f : o.formulations) {
    const RunResult* a = find(runs, 100, f);
    const RunResult* b = find(runs, 1000, f);
    if (a && b)
      fmt::print("  {:<15}: time/step N=1000 / N=100 = {:.2f}  (goal <= 12)\n", model::to_string(f),
                 b->per_step_s / a->per_step_s);
  }

  std::vector<CondResult> conds;
  if (o.cond) {
    fmt::print("\ncondition number of the Newton matrix, first step (2-norm, dense SVD)\n");
    fmt::print("{:>6} {:<15} {:>8} {:>11} {:>12} {:>12} {:>12} {:>5} {:>10} {:>8}\n", "N",
               "formulation", "dt", "size", "cond_start", "cond_conv", "scaled_conv", "it",
               "|R|_inf", "time_s");
    for (int N : o.ns) {
      if (N > 100) {
        fmt::print("{:>6} (skipped: --cond only for N <= 100)\n", N);
        continue;
      }
      const system::System sys = system::System::compile(chain(N, Formulation::constrained, o.dt));
      for (Formulation f : o.formulations) {
        for (double dt : {1e-2, 1e-3, 1e-4}) {
          const CondResult c = condition(sys, N, f, dt);
          fmt::print(
              "{:>6} {:<15} {:>8.0e} {:>11} {:>12.4e} {:>12.4e} {:>12.4e} {:>5} {:>10.2e} "
              "{:>8.2f}\n",
              c.N, model::to_string(c.f), c.dt, fmt::format("{}x{}", c.size_rows, c.size_cols),
              c.cond_start, c.cond_converged, c.cond_scaled, c.newton_iterations, c.final_residual,
              c.seconds);
          std::fflush(stdout);
          conds.push_back(c);
        }
      }
    }
  }

  if (!o.csv.empty()) {
    std::FILE* out = std::fopen(o.csv.c_str(), "w");
    if (!out) {
      std::fprintf(stderr, "chain_bench: cannot write %s\n", o.csv.c_str());
      return 1;
    }
    fmt::print(
        out,
        "N,formulation,solve,dt,n,m_selected,k,dof,unknowns,steps_requested,steps_done,compile_s,"
        "total_s,s_per_step,repeats,spread,avg_iterations,max_iterations,E0,energy_drift_abs,"
        "energy_drift_rel,max_kinetic_energy,max_constraint_violation,status\n");
    for (const auto& r : runs)
      fmt::print(out,
                 "{},{},{},{:g},{},{},{},{},{},{},{},"            // sizes and steps
                 "{:.6g},{:.6g},{:.6g},{},{:.3g},{:.6g},{},"      // times and iterations
                 "{:.17g},{:.6g},{:.6g},{:.6g},{:.6g},\"{}\"\n",  // energy, constraints, status
                 r.N, model::to_string(r.f), r.solve, o.dt, r.n, r.m_selected, r.k, r.dof,
                 r.unknowns, r.steps_requested, r.steps_done, r.compile_s, r.total_s, r.per_step_s,
                 r.repeats, r.spread, r.avg_iterations, r.max_iterations, r.E0, r.drift_abs,
                 r.drift_rel, r.max_kinetic, r.max_violation, r.status);
    std::fclose(out);
    if (!conds.empty()) {
      const std::string path = csv_cond_path(o.csv);
      std::FILE* oc = std::fopen(path.c_str(), "w");
      if (!oc) {
        std::fprintf(stderr, "chain_bench: cannot write %s\n", path.c_str());
        return 1;
      }
      fmt::print(oc,
                 "N,formulation,dt,rows,cols,cond_start,cond_converged,newton_iterations,"
                 "final_residual,cond_converged_scaled\n");
      for (const auto& c : conds)
        fmt::print(oc, "{},{},{:g},{},{},{:.6g},{:.6g},{},{:.3g},{:.6g}\n", c.N,
                   model::to_string(c.f), c.dt, c.size_rows, c.size_cols, c.cond_start,
                   c.cond_converged, c.newton_iterations, c.final_residual, c.cond_scaled);
      std::fclose(oc);
    }
  }
  return 0;
}
