// Many-patch Kirchhoff–Love part (issue #17, IGA-thesis ch. 4–5): a square plate, 1 × 1, t = 0.01,
// E = 1e7, ν = 0.3, its edges held (`fixed: all`), under a uniform pressure, cut into a grid of
// PU × PV patches of degree p joined by a coupling, against the same plate as one patch with the
// same elements. Per variant: the compile time (System::compile: joining, couplings, row
// selection), the unknowns, and per Newton iteration of a nonlinear static solve (one load step)
// the assembly time and the linear-solve time (StaticNewtonSolver's LoadStepStats), and their
// ratio to the single patch's per unknown.
//
//   kl_many_patch_bench [--grid 5,4] [--elements 180] [--degree 3]
//                       [--couplings bending_strip,angle] [--threads 1]
//
// --elements: elements per direction of the whole plate (each patch gets elements/PU × /PV).
#include <fmt/format.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "bench_cli.hpp"
#include "isoflex/integrate/static_equilibrium.hpp"
#include "isoflex/io/model_reader.hpp"

namespace {

using namespace isoflex;
using Clock = std::chrono::steady_clock;

struct Options {
  int pu = 5, pv = 4, elements = 180, degree = 3, threads = 1;
  std::vector<std::string> couplings{"bending_strip", "angle"};
};

[[noreturn]] void usage(const std::string& msg) {
  std::fprintf(stderr,
               "kl_many_patch_bench: %s\n"
               "usage: kl_many_patch_bench [--grid 5,4] [--elements 180] [--degree 3]\n"
               "                           [--couplings bending_strip,angle] [--threads 1]\n",
               msg.c_str());
  std::exit(2);
}

Options parse(int argc, char** argv) {
  Options o;
  bench::Args args(argc, argv, usage);
  while (args.next()) {
    if (args.is("--grid")) {
      const auto g = bench::split(args.value());
      if (g.size() != 2) usage("--grid needs PU,PV");
      o.pu = static_cast<int>(bench::parse_double(g[0], "PU", usage));
      o.pv = static_cast<int>(bench::parse_double(g[1], "PV", usage));
    } else if (args.is("--elements")) {
      o.elements = args.count("elements");
    } else if (args.is("--degree")) {
      o.degree = args.count("degree");
    } else if (args.is("--threads")) {
      o.threads = args.count("threads");
    } else if (args.is("--couplings")) {
      o.couplings = bench::split(args.value());
    } else {
      args.unknown();
    }
  }
  if (o.pu < 1 || o.pv < 1 || o.elements % o.pu != 0 || o.elements % o.pv != 0)
    usage("--elements must be a multiple of both grid counts");
  if (o.degree < 2) usage("--degree must be at least 2");
  return o;
}

// The plate as pu × pv patches (pu = pv = 1: one patch) in the model-file language.
std::string plate(const Options& o, int pu, int pv, const std::string& coupling) {
  std::string s = fmt::format(
      "name: many_patch\nsolver: {{analysis: static, dt: 1, t_end: 1, max_iterations: 30}}\n"
      "surfaces:\n");
  const double wu = 1.0 / pu, wv = 1.0 / pv;
  const int eu = o.elements / pu, ev = o.elements / pv;
  std::string shells = "kl_shells:\n", supports = "kl_supports:\n", loads = "kl_loads:\n";
  for (int j = 0; j < pv; ++j)
    for (int i = 0; i < pu; ++i) {
      const std::string n = fmt::format("p{}_{}", i, j);
      s += fmt::format(
          "  - {{name: {}, builtin: {{type: rectangle, size: [{}, {}], corner: [{}, {}, 0]}}, "
          "refine: {{elevate: [{}, {}], knots_per_span: [{}, {}]}}}}\n",
          n, wu, wv, i * wu, j * wv, o.degree - 1, o.degree - 1, eu - 1, ev - 1);
      shells += fmt::format(
          "  - {{name: {}, surface: {}, material: {{E: 1.0e7, nu: 0.3, thickness: 0.01}}}}\n", n,
          n);
      if (i == 0) supports += fmt::format("  - {{shell: {}, edge: u0, fixed: all}}\n", n);
      if (i == pu - 1) supports += fmt::format("  - {{shell: {}, edge: u1, fixed: all}}\n", n);
      if (j == 0) supports += fmt::format("  - {{shell: {}, edge: v0, fixed: all}}\n", n);
      if (j == pv - 1) supports += fmt::format("  - {{shell: {}, edge: v1, fixed: all}}\n", n);
      loads += fmt::format("  - {{shell: {}, area_force: [0, 0, \"-1.0*t\"]}}\n", n);
    }
  s += shells + supports + loads;
  if (pu * pv > 1) s += fmt::format("kl_interfaces: {{coupling: {}, beta: 1000}}\n", coupling);
  return s;
}

double seconds(Clock::duration d) {
  return std::chrono::duration<double>(d).count();
}

struct Result {
  double compile = 0.0, assembly = 0.0, solve = 0.0;  // seconds; assembly, solve per iteration
  int unknowns = 0, iterations = 0;
};

Result run(const Options& o, int pu, int pv, const std::string& coupling) {
  const model::Model m = io::read_model_string(plate(o, pu, pv, coupling), "many_patch.yaml");
  const auto t0 = Clock::now();
  auto sys = system::System::compile(m);
  Result r;
  r.compile = seconds(Clock::now() - t0);
  if (o.threads > 1) sys.set_threads(o.threads);
  integrate::StaticEquilibrium eq(sys, m.solver);
  r.unknowns = eq.unknowns();
  const integrate::StaticResult res = eq.solve();
  for (const auto& st : res.steps) {
    r.iterations += st.iterations;
    r.assembly += st.assembly_seconds;
    r.solve += st.solve_seconds;
  }
  // Evaluations = iterations + 1 (the last residual); solves = iterations.
  r.assembly /= r.iterations + 1;
  r.solve /= r.iterations;
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  try {
    std::printf(
        "variant,patches,unknowns,compile_s,newton_iterations,assembly_s_per_iteration,"
        "solve_s_per_iteration,iteration_s_per_unknown_vs_one_patch\n");
    const Result one = run(o, 1, 1, "");
    const auto per_unknown = [](const Result& r) { return (r.assembly + r.solve) / r.unknowns; };
    std::printf("one_patch,1,%d,%.3f,%d,%.4f,%.4f,1.000\n", one.unknowns, one.compile,
                one.iterations, one.assembly, one.solve);
    std::fflush(stdout);
    for (const std::string& c : o.couplings) {
      const Result r = run(o, o.pu, o.pv, c);
      std::printf("%s,%d,%d,%.3f,%d,%.4f,%.4f,%.3f\n", c.c_str(), o.pu * o.pv, r.unknowns,
                  r.compile, r.iterations, r.assembly, r.solve, per_unknown(r) / per_unknown(one));
      std::fflush(stdout);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "kl_many_patch_bench: %s\n", e.what());
    return 1;
  }
}
