// Shell benchmark: a simply supported square plate of N × N elements under a pressure pulse, the
// performance goal of the shell issue (#4): the time per step must grow near-linearly with the
// number of nodes (sparse assembly and factorization). See bench/shells.md.
//
//   shell_bench [--sizes 10,20,40,70,100] [--steps K] [--warmup W]
//               [--formulations constrained,nullspace,reparametrized] [--dt 0.001]
//               [--max-seconds S]
//
// The plate is built as model-file text and read with io::read_model_string, exactly as a model
// file would be: 1 × 1, thickness 0.01, E = 1e7, ν = 0.3, density 1000, all four edges simply
// supported (translation: all), pressure 1000·(t < 0.01). Per N and formulation: W warm-up steps
// (untimed), then K timed steps: wall time per step (steady_clock around integ.step only) and the
// process CPU time per step (CLOCK_PROCESS_CPUTIME_ID, less disturbed by other jobs on a shared
// machine), Newton iterations per step, time per step per node, and the ratio of the CPU time per
// node to that of the smallest N. At the end, the exponent p of a least-squares fit
// time per step ∝ nodes^p (log-log) per formulation.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <exception>
#include <string>
#include <vector>

#include "bench_cli.hpp"
#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/io/model_reader.hpp"
#include "isoflex/model/model.hpp"
#include "isoflex/solve/memory.hpp"
#include "isoflex/system/system.hpp"

namespace {

using namespace isoflex;
using Clock = std::chrono::steady_clock;
using model::Formulation;

struct Options {
  std::vector<int> sizes{10, 20, 40, 70, 100};
  int steps = 5;
  int warmup = 2;
  std::vector<Formulation> formulations{Formulation::reparametrized};
  double dt = 1e-3;
  double max_seconds = 0.0;  // 0 = no limit; otherwise stop timing a size after this much CPU time
};

[[noreturn]] void usage(const std::string& msg) {
  std::fprintf(stderr,
               "shell_bench: %s\n"
               "usage: shell_bench [--sizes 10,20,40,70,100] [--steps K] [--warmup W]\n"
               "                   [--formulations constrained,nullspace,reparametrized]\n"
               "                   [--dt 0.001] [--max-seconds S]\n",
               msg.c_str());
  std::exit(2);
}

Options parse(int argc, char** argv) {
  Options o;
  bench::Args args(argc, argv, usage);
  while (args.next()) {
    if (args.is("--sizes")) {
      o.sizes = args.counts("size");
    } else if (args.is("--steps")) {
      o.steps = args.count("step count");
    } else if (args.is("--warmup")) {
      const std::string v = args.value();
      o.warmup = v == "0" ? 0 : static_cast<int>(bench::parse_int(v, "warm-up count", usage));
    } else if (args.is("--formulations")) {
      o.formulations = bench::parse_formulations(args.value(), usage);
    } else if (args.is("--dt")) {
      o.dt = args.number("time step");
      if (!(o.dt > 0)) usage("--dt must be positive");
    } else if (args.is("--max-seconds")) {
      o.max_seconds = args.number("time limit");
    } else {
      args.unknown();
    }
  }
  return o;
}

// The plate as model-file text (docs/model-files.md, "shells").
std::string plate_yaml(int N, Formulation f, double dt) {
  return fmt::format(R"yaml(
name: plate{0}
solver: {{formulation: {1}, dt: {2}, t_end: 1.0}}
shells:
  - name: p
    plate: {{corners: [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], elements: [{0}, {0}]}}
    material: {{E: 1.0e7, nu: 0.3, thickness: 0.01, density: 1000}}
shell_supports:
  - {{shell: p, edge: u0, translation: all}}
  - {{shell: p, edge: u1, translation: all}}
  - {{shell: p, edge: v0, translation: all}}
  - {{shell: p, edge: v1, translation: all}}
shell_loads:
  - {{shell: p, pressure: "1000*(t<0.01)"}}
)yaml",
                     N, model::to_string(f), dt);
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
  int nodes = 0, n = 0, m = 0, k = 0, unknowns = 0, steps_done = 0;
  double compile_s = 0.0, warmup_s = 0.0;
  double per_step_s = 0.0, cpu_per_step_s = 0.0, avg_iterations = 0.0, max_violation = 0.0;
  std::string solve;
  std::string status = "ok";
};

RunResult run(int N, Formulation f, const Options& o) {
  RunResult r;
  r.N = N;
  r.f = f;
  const double c_compile = cpu_seconds();
  const model::Model m = io::read_model_string(plate_yaml(N, f, o.dt), "plate.yaml");
  const system::System sys = system::System::compile(m);
  const integrate::EnergyMomentumIntegrator integ(sys, m.solver);
  r.compile_s = cpu_seconds() - c_compile;
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
  integrate::State s = integ.initial_state();
  try {
    const double c0 = cpu_seconds();
    for (int i = 0; i < o.warmup; ++i) integ.step(s);
    r.warmup_s = cpu_seconds() - c0;
    Clock::duration stepping{};
    double cpu = 0.0;
    long iterations = 0;
    for (int i = 0; i < o.steps; ++i) {
      const auto t0 = Clock::now();
      const double c1 = cpu_seconds();
      const integrate::StepStats st = integ.step(s);
      cpu += cpu_seconds() - c1;
      stepping += Clock::now() - t0;
      ++r.steps_done;
      iterations += st.iterations;
      r.max_violation = std::max(r.max_violation,
                                 sys.constraints(s.q, s.t).lpNorm<Eigen::Infinity>());  // untimed
      if (o.max_seconds > 0 && cpu > o.max_seconds && i + 1 < o.steps) {
        r.status = fmt::format("stopped by --max-seconds after {} steps", r.steps_done);
        break;
      }
    }
    if (r.steps_done > 0) {
      r.per_step_s = seconds(stepping) / r.steps_done;
      r.cpu_per_step_s = cpu / r.steps_done;
      r.avg_iterations = double(iterations) / r.steps_done;
    }
  } catch (const std::exception& e) {
    r.status = fmt::format("Newton failure: {}", e.what());
  }
  return r;
}

// Least-squares slope of log y against log x.
double loglog_slope(const std::vector<double>& x, const std::vector<double>& y) {
  const double n = double(x.size());
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double lx = std::log(x[i]), ly = std::log(y[i]);
    sx += lx;
    sy += ly;
    sxx += lx * lx;
    sxy += lx * ly;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

}  // namespace

int main(int argc, char** argv) {
  isoflex::solve::retain_freed_memory();  // repeated large factorizations (solve/memory.hpp)
  const Options o = parse(argc, argv);
  fmt::print(
      "simply supported plate 1 x 1 x 0.01, N x N elements, pressure 1000*(t<0.01), dt = {:g}, "
      "{} warm-up + {} timed steps\n\n",
      o.dt, o.warmup, o.steps);
  fmt::print(
      "{:>4} {:<15} {:<8} {:>6} {:>7} {:>7} {:>7} {:>8} {:>9} {:>5} {:>6} {:>10} {:>10} {:>10} "
      "{:>6} {:>9} {}\n",
      "N", "formulation", "solve", "nodes", "n", "m", "k", "unknowns", "compile_s", "steps",
      "avg_it", "s/step", "cpu_s/step", "cpu_us/nd", "ratio", "max|Phi|", "status");
  std::vector<RunResult> runs;
  for (Formulation f : o.formulations) {
    const RunResult* first = nullptr;
    std::vector<RunResult> mine;
    mine.reserve(o.sizes.size());
    for (int N : o.sizes) {
      mine.push_back(run(N, f, o));
      const RunResult& r = mine.back();
      if (!first && r.steps_done > 0) first = &r;
      const double per_node = r.nodes > 0 ? r.cpu_per_step_s / r.nodes : 0.0;
      const double ratio =
          first && r.steps_done > 0 ? per_node / (first->cpu_per_step_s / first->nodes) : 0.0;
      fmt::print(
          "{:>4} {:<15} {:<8} {:>6} {:>7} {:>7} {:>7} {:>8} {:>9.2f} {:>5} {:>6.2f} {:>10.4f} "
          "{:>10.4f} {:>10.2f} {:>6.2f} {:>9.2e} {}\n",
          r.N, model::to_string(r.f), r.solve, r.nodes, r.n, r.m, r.k, r.unknowns, r.compile_s,
          r.steps_done, r.avg_iterations, r.per_step_s, r.cpu_per_step_s, 1e6 * per_node, ratio,
          r.max_violation, r.status);
      std::fflush(stdout);
    }
    runs.insert(runs.end(), mine.begin(), mine.end());
  }
  fmt::print("\nlog-log fit, CPU time ∝ nodes^p (linear: p = 1)\n");
  for (Formulation f : o.formulations) {
    std::vector<double> x, y_step, y_it;
    for (const auto& r : runs)
      if (r.f == f && r.steps_done > 0) {
        x.push_back(r.nodes);
        y_step.push_back(r.cpu_per_step_s);
        y_it.push_back(r.cpu_per_step_s / r.avg_iterations);
      }
    if (x.size() < 2) continue;
    fmt::print("  {:<15} {} sizes: per step p = {:.2f}, per Newton iteration p = {:.2f}\n",
               model::to_string(f), x.size(), loglog_slope(x, y_step), loglog_slope(x, y_it));
  }
  return 0;
}
