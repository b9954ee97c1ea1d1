// Co-simulation against the monolithic run (IGA-thesis §6.3.2, Fig. 6.8; bench/cosimulation.md):
// for a model whose Kirchhoff–Love shells interact with the rest through springs, the monolithic
// energy–momentum run at the model's dt is the reference; then the co-simulation
// (integrate/cosimulation.hpp) with the macro steps H = k·dt, constant and linear hold. Per run:
// the largest distance of every probe from the reference over the common times, the energy
// balance error max |E + D − W − E₀| / E₀ (E total, D dissipated, W external work), the drift of
// the total linear momentum max |p − p₀| / max |p| (a system without supports and loads keeps
// it), Newton iterations and the wall time of the stepping.
//
//   cosimulation_bench MODEL [--macro 1,2,4,8,16] [--t-end T] [--dt DT]
#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <map>
#include <string>
#include <vector>

#include "bench_cli.hpp"
#include "isoflex/integrate/cosimulation.hpp"
#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/io/model_reader.hpp"

namespace {

using namespace isoflex;
using Clock = std::chrono::steady_clock;

[[noreturn]] void usage(const std::string& message) {
  fmt::print(stderr,
             "cosimulation_bench: {}\nusage: cosimulation_bench MODEL [--macro 1,2,4,8,16] "
             "[--t-end T] [--dt DT]\n",
             message);
  std::exit(2);
}

struct Result {
  std::vector<integrate::Snapshot> snapshots;
  double seconds = 0.0;
  long iterations = 0;
};

double balance(const integrate::Snapshot& s) {
  return s.total_energy + s.dissipated_energy - s.external_work;
}

struct Errors {
  double position = 0.0, energy = 0.0, momentum = 0.0;
};

// r's snapshots every `stride` reference snapshots.
Errors errors(const Result& r, const Result& ref, int stride) {
  Errors e;
  const double E0 = std::abs(balance(r.snapshots.front()));
  double pmax = 0.0;
  for (const auto& s : ref.snapshots) pmax = std::max(pmax, s.linear_momentum.norm());
  for (std::size_t k = 0; k < r.snapshots.size(); ++k) {
    const auto& s = r.snapshots[k];
    const auto& x = ref.snapshots.at(k * static_cast<std::size_t>(stride));
    std::map<std::string, Vec3> at;
    for (const auto& p : x.probes) at[p.name] = p.position;
    for (const auto& p : s.probes)
      e.position = std::max(e.position, (p.position - at[p.name]).norm());
    e.energy = std::max(e.energy, std::abs(balance(s) - balance(r.snapshots.front())) / E0);
    e.momentum = std::max(e.momentum,
                          (s.linear_momentum - r.snapshots.front().linear_momentum).norm() / pmax);
  }
  return e;
}

Result monolithic(const model::Model& m) {
  const auto sys = system::System::compile(m);
  const integrate::EnergyMomentumIntegrator integ(sys, m.solver);
  auto state = integ.initial_state();
  Result r;
  r.snapshots.push_back(integ.snapshot(state, {}, {}));
  const int steps = static_cast<int>(std::lround(m.solver.t_end / m.solver.dt));
  for (int i = 0; i < steps; ++i) {
    const auto t0 = Clock::now();
    const auto st = integ.step(state);
    r.seconds += std::chrono::duration<double>(Clock::now() - t0).count();
    r.iterations += st.iterations;
    r.snapshots.push_back(integ.snapshot(state, st, {}));
  }
  return r;
}

Result cosimulated(model::Model m, int micro, model::CoSimulationHold hold) {
  m.solver.cosimulation = model::CoSimulation{micro * m.solver.dt, hold, 0};
  integrate::CoSimulation co(m);
  Result r;
  r.snapshots.push_back(co.snapshot({}));
  const int steps = static_cast<int>(std::lround(m.solver.t_end / co.macro_step()));
  for (int k = 0; k < steps; ++k) {
    const auto t0 = Clock::now();
    const auto st = co.advance();
    r.seconds += std::chrono::duration<double>(Clock::now() - t0).count();
    r.iterations += st.iterations;
    r.snapshots.push_back(co.snapshot(st));
  }
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) usage("a model file is required");
  std::string file;
  std::vector<int> macro{1, 2, 4, 8, 16};
  double t_end = 0.0, dt = 0.0;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage(a + " needs a value");
      return argv[++i];
    };
    if (a == "--macro") {
      macro.clear();
      for (const auto& s : bench::split(value()))
        macro.push_back(static_cast<int>(bench::parse_int(s, "macro step count", usage)));
    } else if (a == "--dt") {
      dt = bench::parse_double(value(), "step", usage);
    } else if (a == "--t-end") {
      t_end = bench::parse_double(value(), "end time", usage);
    } else if (a.rfind("--", 0) == 0) {
      usage("unknown option " + a);
    } else {
      file = a;
    }
  }
  try {
    model::Model m = io::read_model(file);
    m.solver.cosimulation.reset();
    if (t_end > 0.0) m.solver.t_end = t_end;
    if (dt > 0.0) m.solver.dt = dt;
    int longest = 1;
    for (int k : macro) longest = std::max(longest, k);
    // Whole macro steps of the longest H.
    m.solver.t_end =
        std::floor(m.solver.t_end / (longest * m.solver.dt) + 1e-9) * longest * m.solver.dt;
    const Result ref = monolithic(m);
    const Errors e0 = errors(ref, ref, 1);
    fmt::print("{}: dt = {:g}, t_end = {:g}\n\n", file, m.solver.dt, m.solver.t_end);
    fmt::print(
        "| run | H | probe error | energy balance error | momentum drift | Newton it. | "
        "stepping s |\n|---|---|---|---|---|---|---|\n");
    fmt::print("| monolithic | {:g} | – | {:.1e} | {:.1e} | {} | {:.3f} |\n", m.solver.dt,
               e0.energy, e0.momentum, ref.iterations, ref.seconds);
    for (const auto hold : {model::CoSimulationHold::constant, model::CoSimulationHold::linear})
      for (int k : macro) {
        const Result r = cosimulated(m, k, hold);
        const Errors e = errors(r, ref, k);
        fmt::print("| co-simulation, hold {} | {:g} | {:.2e} | {:.1e} | {:.1e} | {} | {:.3f} |\n",
                   model::to_string(hold), k * m.solver.dt, e.position, e.energy, e.momentum,
                   r.iterations, r.seconds);
      }
  } catch (const std::exception& e) {
    fmt::print(stderr, "cosimulation_bench: {}\n", e.what());
    return 1;
  }
  return 0;
}
