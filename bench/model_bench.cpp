// Model-file benchmark: regenerates DNSM-III Table 4 for any model (bench/slider_crank.md):
// the whole run of every formulation — wall time, Newton iterations per step, the CPU-time ratio
// constrained / reparametrized, the speed relative to real time — and the condition numbers of
// the Newton matrices of the first step at several Δt. With --integrators the DAE schemes
// (integrate/dae_integrator.hpp) run too, next to the energy–momentum formulations, and --cond
// adds the condition numbers of their iteration matrix S_t (2.27) with and without the scaling of
// IGA-thesis §2.2.4.
//
//   model_bench MODEL [--formulations constrained,nullspace,reparametrized] [--repeat R]
//               [--integrators generalized_alpha,bdf1,bdf2] [--rho 0.8]
//               [--t-end T] [--cond 1e-2,1e-3,1e-4] [--no-run]
//
// Timing: steady_clock around integ.step() only (no output is written; System::compile and the
// energy bookkeeping excluded), fastest of R runs, spread (slowest − fastest)/fastest.
#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "bench_cli.hpp"
#include "isoflex/integrate/dae_integrator.hpp"
#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/io/model_reader.hpp"
#include "isoflex/solve/memory.hpp"
#include "newton_condition.hpp"

namespace {

using namespace isoflex;
using Clock = std::chrono::steady_clock;
using model::Formulation;

struct Options {
  std::string model;
  std::vector<Formulation> formulations{Formulation::constrained, Formulation::nullspace,
                                        Formulation::reparametrized};
  std::vector<model::Integrator> integrators;  // DAE schemes besides the formulations
  double rho = -1.0;                           // < 0: the model's ρ∞
  int repeat = 1;
  double t_end = -1.0;  // < 0: the model's
  std::vector<double> cond_dts;
  bool run = true;
};

[[noreturn]] void usage(const std::string& msg) {
  std::fprintf(stderr,
               "model_bench: %s\n"
               "usage: model_bench MODEL [--formulations constrained,nullspace,reparametrized]\n"
               "                   [--integrators generalized_alpha,bdf1,bdf2] [--rho 0.8]\n"
               "                   [--repeat R] [--t-end T] [--cond 1e-2,1e-3,1e-4] [--no-run]\n",
               msg.c_str());
  std::exit(2);
}

Options parse(int argc, char** argv) {
  Options o;
  bench::Args args(argc, argv, usage);
  while (args.next()) {
    if (args.is("--formulations")) {
      o.formulations = bench::parse_formulations(args.value(), usage);
    } else if (args.is("--integrators")) {
      for (const auto& name : bench::split(args.value())) {
        const auto i = model::integrator_from_string(name);
        if (!i || *i == model::Integrator::energy_momentum)
          usage(fmt::format("unknown DAE integrator '{}'", name));
        o.integrators.push_back(*i);
      }
    } else if (args.is("--rho")) {
      o.rho = args.number("rho_infinity");
    } else if (args.is("--repeat")) {
      o.repeat = args.count("repeat count");
    } else if (args.is("--t-end")) {
      o.t_end = args.number("end time");
    } else if (args.is("--cond")) {
      for (const auto& d : bench::split(args.value()))
        o.cond_dts.push_back(bench::parse_double(d, "time step", usage));
    } else if (args.is("--no-run")) {
      o.run = false;
    } else if (!args.arg().empty() && args.arg()[0] == '-') {
      args.unknown();
    } else if (o.model.empty()) {
      o.model = args.arg();
    } else {
      usage("more than one model file");
    }
  }
  if (o.model.empty()) usage("no model file");
  return o;
}

double seconds(Clock::duration d) {
  return std::chrono::duration<double>(d).count();
}

struct RunResult {
  std::string solve;
  int unknowns = 0, steps = 0;
  double seconds = 0.0, spread = 0.0, iterations_per_step = 0.0, max_violation = 0.0;
  double energy_start = 0.0, energy_end = 0.0;
};

std::string solve_kind(const integrate::TimeIntegrator& integ) {
  const auto* em = dynamic_cast<const integrate::EnergyMomentumIntegrator*>(&integ);
  if (!em || em->formulation() == Formulation::constrained) return "full";
  return em->tree_recursion()   ? "tree"
         : em->block_assembly() ? "blocks"
         : em->bordered()       ? "bordered"
                                : "explicit";
}

double energy(const system::System& sys, const integrate::State& s) {
  return 0.5 * s.v.dot(sys.mass() * s.v) + sys.potential(s.q);
}

RunResult run(const system::System& sys, const model::Solver& settings, int repeat) {
  const auto integ = integrate::make_time_integrator(sys, settings);
  RunResult best;
  double slowest = 0.0;
  for (int r = 0; r < repeat; ++r) {
    RunResult x;
    x.unknowns = integ->unknowns();
    x.solve = solve_kind(*integ);
    integrate::State s = integ->initial_state();
    x.energy_start = energy(sys, s);
    x.steps = static_cast<int>(std::lround(settings.t_end / settings.dt));
    Clock::duration stepping{};
    long iterations = 0;
    for (int i = 0; i < x.steps; ++i) {
      const auto t0 = Clock::now();
      const auto st = integ->step(s);
      stepping += Clock::now() - t0;
      iterations += st.iterations;
      x.max_violation =
          std::max(x.max_violation, sys.constraints(s.q, s.t).lpNorm<Eigen::Infinity>());
    }
    x.seconds = seconds(stepping);
    x.energy_end = energy(sys, s);
    x.iterations_per_step = double(iterations) / std::max(1, x.steps);
    slowest = std::max(slowest, x.seconds);
    if (r == 0 || x.seconds < best.seconds) best = x;
  }
  best.spread = (slowest - best.seconds) / best.seconds;
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  isoflex::solve::retain_freed_memory();  // repeated large factorizations (solve/memory.hpp)
  const Options o = parse(argc, argv);
  try {
    model::Model m = io::read_model(o.model);
    if (o.t_end > 0) m.solver.t_end = o.t_end;
    const auto sys = system::System::compile(m);
    fmt::print("model {}: n = {}, m = {}, n - m = {}, dt = {}, t_end = {}\n", o.model, sys.n(),
               sys.m_selected(), sys.n() - sys.m_selected(), m.solver.dt, m.solver.t_end);
    if (o.run) {
      fmt::print("\n{:<17} {:>9} {:>8} {:>6} {:>9} {:>7} {:>8} {:>9} {:>10} {:>9} {:>12}\n",
                 "scheme", "solve", "unknowns", "steps", "time_s", "spread", "it/step", "ms/iter",
                 "x_realtime", "max|Phi|", "E_0", "E_end");
      double t_con = 0.0, t_rep = 0.0;
      std::vector<model::Solver> runs;
      for (Formulation f : o.formulations) {
        runs.push_back(m.solver);
        runs.back().integrator = model::Integrator::energy_momentum;
        runs.back().formulation = f;
      }
      for (model::Integrator i : o.integrators) {
        runs.push_back(m.solver);
        runs.back().integrator = i;
        if (o.rho >= 0) runs.back().rho_infinity = o.rho;
      }
      for (const model::Solver& s : runs) {
        const RunResult r = run(sys, s, o.repeat);
        const bool em = s.integrator == model::Integrator::energy_momentum;
        fmt::print(
            "{:<17} {:>9} {:>8} {:>6} {:>9.3f} {:>6.0f}% {:>8.3f} {:>9.4f} {:>10.2f} {:>9.2e} "
            "{:>12.6g} {:>12.6g}\n",
            em ? model::to_string(s.formulation)
            : s.integrator == model::Integrator::generalized_alpha
                ? fmt::format("gen_alpha {:g}", s.rho_infinity)
                : model::to_string(s.integrator),
            r.solve, r.unknowns, r.steps, r.seconds, 100 * r.spread, r.iterations_per_step,
            1e3 * r.seconds / (r.steps * r.iterations_per_step), s.t_end / r.seconds,
            r.max_violation, r.energy_start, r.energy_end);
        if (em && s.formulation == Formulation::constrained) t_con = r.seconds;
        if (em && s.formulation == Formulation::reparametrized) t_rep = r.seconds;
      }
      if (t_con > 0 && t_rep > 0)
        fmt::print("\nCPU time constrained / reparametrized = {:.2f}  (DNSM-III Table 4: 2.3)\n",
                   t_con / t_rep);
    }
    if (!o.cond_dts.empty()) {
      fmt::print("\ncondition number of the Newton matrix, first step (2-norm, dense SVD)\n");
      fmt::print("{:<15} {:>8} {:>11} {:>12} {:>12} {:>12} {:>4}\n", "formulation", "dt", "size",
                 "cond_start", "cond_conv", "scaled_conv", "it");
      for (Formulation f : o.formulations)
        for (double dt : o.cond_dts) {
          model::Solver s = m.solver;
          s.formulation = f;
          s.dt = dt;
          const auto c = bench::newton_condition(sys, s);
          fmt::print("{:<15} {:>8.0e} {:>11} {:>12.4e} {:>12.4e} {:>12.4e} {:>4}\n",
                     model::to_string(f), dt, fmt::format("{}x{}", c.rows, c.cols), c.at_start,
                     c.converged, c.converged_scaled, c.iterations);
        }
      if (!o.integrators.empty()) {
        fmt::print(
            "\ncondition number of the DAE iteration matrix S_t (2.27) at the first Newton "
            "start (2-norm, dense SVD)\n{:<17} {:>8} {:>11} {:>12} {:>12}\n",
            "scheme", "dt", "size", "scaled", "unscaled");
        for (model::Integrator i : o.integrators)
          for (double dt : o.cond_dts) {
            double cond[2];
            int size = 0;
            for (const bool scaled : {true, false}) {
              model::Solver s = m.solver;
              s.integrator = i;
              s.dt = dt;
              s.scaling = scaled;
              if (o.rho >= 0) s.rho_infinity = o.rho;
              const integrate::DaeIntegrator dae(sys, s);
              const MatX S = MatX(dae.iteration_matrix(dae.initial_state()));
              size = static_cast<int>(S.rows());
              cond[scaled ? 0 : 1] = solve::condition_number(S);
            }
            fmt::print("{:<17} {:>8.0e} {:>11} {:>12.4e} {:>12.4e}\n", model::to_string(i), dt,
                       fmt::format("{}x{}", size, size), cond[0], cond[1]);
          }
      }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "model_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
