// Many-patch Kirchhoff–Love part (issue #17, IGA-thesis ch. 4–5): a square plate, 1 × 1, t = 0.01,
// E = 1e7, ν = 0.3, its edges held (`fixed: all`), under a uniform pressure, cut into a grid of
// PU × PV patches of degree p joined by a coupling, against the same plate as one patch with the
// same elements. Per variant: the compile time (System::compile: joining, couplings, row
// selection), the unknowns, and per Newton iteration of a nonlinear static solve (one load step)
// the assembly time and the linear-solve time (StaticNewtonSolver's LoadStepStats), and their
// ratio to the single patch's per unknown; the GMRES iterations and LU fallbacks of the
// augmented-Lagrangian saddle-point solver (AF-BS, docs/theory/solvers.md), and per load step the
// rest of its wall time (AF-BS: the row selection at its start).
//
//   kl_many_patch_bench [--grid 5,4] [--elements 180] [--degree 3]
//                       [--couplings bending_strip,angle] [--threads 1]
//                       [--saddle-point auto|lu|augmented_lagrangian]
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
#include "support/kl_plate_grid.hpp"

namespace {

using namespace isoflex;
using Clock = std::chrono::steady_clock;

struct Options {
  int pu = 5, pv = 4, elements = 180, degree = 3, threads = 1;
  std::vector<std::string> couplings{"bending_strip", "angle"};
  std::string saddle_point = "auto";  // solver.saddle_point_solver
};

[[noreturn]] void usage(const std::string& msg) {
  std::fprintf(stderr,
               "kl_many_patch_bench: %s\n"
               "usage: kl_many_patch_bench [--grid 5,4] [--elements 180] [--degree 3]\n"
               "                           [--couplings bending_strip,angle] [--threads 1]\n"
               "                           [--saddle-point auto|lu|augmented_lagrangian]\n",
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
    } else if (args.is("--saddle-point")) {
      o.saddle_point = args.value();
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
  test::PlateGrid g;
  g.pu = pu;
  g.pv = pv;
  g.elements = o.elements;
  g.degree = o.degree;
  g.coupling = coupling;
  g.interface_keys = ", beta: 1000";
  g.solver = "{analysis: static, dt: 1, t_end: 1, max_iterations: 30, saddle_point_solver: " +
             o.saddle_point + "}";
  return test::plate_grid_yaml(g);
}

double seconds(Clock::duration d) {
  return std::chrono::duration<double>(d).count();
}

struct Result {
  double compile = 0.0, assembly = 0.0, solve = 0.0;  // seconds; assembly, solve per iteration
  double other = 0.0;  // per load step: the rest of its wall time (the row selection of AF-BS)
  int unknowns = 0, iterations = 0, krylov = 0, fallbacks = 0;
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
    r.other += st.wall_seconds - st.assembly_seconds - st.solve_seconds;
    r.krylov += st.krylov_iterations;
    r.fallbacks += st.saddle_point_fallbacks;
  }
  // Evaluations = iterations + 1 (the last residual); solves = iterations.
  r.assembly /= r.iterations + 1;
  r.solve /= r.iterations;
  r.other /= static_cast<double>(res.steps.size());
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  try {
    std::printf(
        "variant,patches,unknowns,compile_s,newton_iterations,assembly_s_per_iteration,"
        "solve_s_per_iteration,iteration_s_per_unknown_vs_one_patch,krylov_iterations,"
        "saddle_point_fallbacks,other_s_per_load_step\n");
    const Result one = run(o, 1, 1, "");
    const auto per_unknown = [](const Result& r) { return (r.assembly + r.solve) / r.unknowns; };
    std::printf("one_patch,1,%d,%.3f,%d,%.4f,%.4f,1.000,0,0,%.3f\n", one.unknowns, one.compile,
                one.iterations, one.assembly, one.solve, one.other);
    std::fflush(stdout);
    for (const std::string& c : o.couplings) {
      const Result r = run(o, o.pu, o.pv, c);
      std::printf("%s,%d,%d,%.3f,%d,%.4f,%.4f,%.3f,%d,%d,%.3f\n", c.c_str(), o.pu * o.pv,
                  r.unknowns, r.compile, r.iterations, r.assembly, r.solve,
                  per_unknown(r) / per_unknown(one), r.krylov, r.fallbacks, r.other);
      std::fflush(stdout);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "kl_many_patch_bench: %s\n", e.what());
    return 1;
  }
}
