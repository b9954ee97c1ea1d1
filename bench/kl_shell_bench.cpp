// Kirchhoff–Love shell benchmark: the performance goals of the KL-shell issue (#6), "assembly of
// residual + tangent for the nonlinear shell: quadrature points per second per core for
// p = 2…5, and the share of time in assembly vs. linear solve for a 50×50-element patch; assembly
// never the bottleneck for p ≤ 4, and total static solve time growing near-linearly with the DOFs
// up to 10⁵ DOFs". See bench/kl_shell.md.
//
//   kl_shell_bench --mode assembly|gradient|split|scaling|solvers [--degrees 2,3,4,5] [--n 50]
//                  [--sizes 10,20,40,70,100,140,180] [--kinematics linear,nonlinear]
//                  [--load-factor F] [--steps S] [--min-seconds T] [--repeat R]
//                  [--max-seconds S] [--tangent-only] [--threads T]
//
// The patch: the Scordelis–Lo roof (IGA-thesis §6.4.1.2), the full roof, not the quarter: the
// cylinder sector geometry::cylinder_sector(R = 25, L = 50, 80°) (ξ along the arc from +x, η along
// the axis z), k-refined to degree p in both directions with N × N knot spans
// (k_refine(s, p − 2, p − 1, N − 1, N − 1)); E = 4.32e8, ν = 0, t = 0.25; self-weight 90 per unit
// area (an AreaForce along −d, d = (cos 40°, sin 40°, 0) the "up" direction through the crown),
// times the load factor F; rigid diaphragms at z = 0 and z = L (x and y of edge rows v0, v1
// eliminated), z of control point 0 eliminated (the rigid translation along the axis), straight
// edges free. Linear reference for the vertical displacement of the midpoint of a free edge
// (ξ = 0, η = ½) at F = 1: −0.3024.
//
// Modes (every time is the process CPU time, CLOCK_PROCESS_CPUTIME_ID, with the wall time next to
// it; only the patch assembly runs on --threads T threads, default 1, KLShellPatch::set_threads;
// with T > 1 the CPU times add up the threads, so compare wall times):
//   assembly  per p on the N × N patch at a deformed state x = X + u (u smooth, |u| ≈ 0.1):
//             KLShellPatch::internal_force with tangent and without (nonlinear), and with the
//             linear tangent (the first call, which computes K_lin and caches it in the patch, on
//             its own, then the later calls); median CPU time per call over ≥ R calls and ≥ T
//             CPU seconds;
//             ns per quadrature point and points per second; DOFs, nnz(K).
//   gradient  per p on the N × N patch: the discrete gradient DV(x₀, x₁) (the energy–momentum
//             step's, docs/theory/kl-shell.md §10) against the internal force at x₁, with and
//             without the tangent, x₀ = X + u and x₁ = X + 1.1 u; median CPU time per call and
//             the ratios (formerly timed inside the unit tests).
//   split     per p a nonlinear static solve on the N × N patch (S load steps of F · self-weight):
//             assembly (residual + tangent, the value map into the Newton matrix) vs linear solve
//             (factorization included) from LoadStepStats, per evaluation, per solve and in all;
//             the assembly share.
//   scaling   per p and kinematics the whole static solve on N × N patches, N from --sizes;
//             log-log fit of the CPU time against the DOFs.
//   solvers   per p and N: the Newton matrix of the static solve at the reference (K_ff, the
//             free dofs) factorized and solved by solve::FixedPatternLDLT (Eigen simplicial LDLᵀ,
//             AMD), FixedPatternCholesky (CHOLMOD supernodal) and FixedPatternLU (UMFPACK):
//             first call (analysis + factorization + solve) and the median of R repeated calls
//             (numeric factorization + solve, the analysis kept).
// --tangent-only (assembly) times the nonlinear residual + tangent only (for profiling).
// --max-seconds S skips the remaining (larger) sizes of scaling/solvers once a run took more CPU
// time than S.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <exception>
#include <functional>
#include <memory>
#include <numbers>
#include <string>
#include <thread>
#include <vector>

#include "bench_cli.hpp"
#include "isoflex/elements/kl_shell_patch.hpp"
#include "isoflex/geometry/builders.hpp"
#include "isoflex/geometry/refinement.hpp"
#include "isoflex/integrate/static_newton.hpp"
#include "isoflex/loads/kl_patch_loads.hpp"
#include "isoflex/solve/linear_solver.hpp"
#include "isoflex/system/kl_boundary_conditions.hpp"
#include "support/kl_static_problem.hpp"

namespace {

using namespace isoflex;
using Clock = std::chrono::steady_clock;
using elements::KLKinematics;
using SpMat = Eigen::SparseMatrix<double>;

enum class Mode { assembly, gradient, split, scaling, solvers };

struct Options {
  Mode mode = Mode::assembly;
  bool mode_given = false;
  std::vector<int> degrees{2, 3, 4, 5};
  bool degrees_given = false;
  int n = 50;
  std::vector<int> sizes{10, 20, 40, 70, 100, 140, 180};
  std::vector<KLKinematics> kinematics{KLKinematics::linear, KLKinematics::nonlinear};
  double load_factor = 5.0;
  int steps = 2;
  double min_seconds = 1.0;
  int repeat = 3;
  double max_seconds = 0.0;
  bool tangent_only = false;  // assembly: time the nonlinear residual + tangent only (profiling)
  int threads = 1;            // KLShellPatch::set_threads
};

[[noreturn]] void usage(const std::string& msg) {
  std::fprintf(stderr,
               "kl_shell_bench: %s\n"
               "usage: kl_shell_bench --mode assembly|gradient|split|scaling|solvers\n"
               "                      [--degrees 2,3,4,5]\n"
               "                      [--n 50] [--sizes 10,20,40,70,100,140,180]\n"
               "                      [--kinematics linear,nonlinear] [--load-factor 5]\n"
               "                      [--steps 2] [--min-seconds 1] [--repeat 3]\n"
               "                      [--max-seconds S] [--tangent-only] [--threads 1]\n",
               msg.c_str());
  std::exit(2);
}

Options parse(int argc, char** argv) {
  Options o;
  bench::Args args(argc, argv, usage);
  while (args.next()) {
    if (args.is("--mode")) {
      const std::string v = args.value();
      o.mode_given = true;
      if (v == "assembly")
        o.mode = Mode::assembly;
      else if (v == "gradient")
        o.mode = Mode::gradient;
      else if (v == "split")
        o.mode = Mode::split;
      else if (v == "scaling")
        o.mode = Mode::scaling;
      else if (v == "solvers")
        o.mode = Mode::solvers;
      else
        usage(fmt::format("unknown mode '{}'", v));
    } else if (args.is("--degrees")) {
      o.degrees = args.counts("degree");
      o.degrees_given = true;
      for (int p : o.degrees)
        if (p < 2 || p > 5) usage(fmt::format("degree {} outside 2 … 5", p));
    } else if (args.is("--n")) {
      o.n = args.count("N");
    } else if (args.is("--sizes")) {
      o.sizes = args.counts("size");
    } else if (args.is("--kinematics")) {
      o.kinematics.clear();
      for (const auto& s : bench::split(args.value())) {
        if (s == "linear")
          o.kinematics.push_back(KLKinematics::linear);
        else if (s == "nonlinear")
          o.kinematics.push_back(KLKinematics::nonlinear);
        else
          usage(fmt::format("unknown kinematics '{}'", s));
      }
      if (o.kinematics.empty()) usage("--kinematics needs at least one value");
    } else if (args.is("--load-factor")) {
      o.load_factor = args.number("load factor");
      if (!(o.load_factor > 0)) usage("--load-factor must be positive");
    } else if (args.is("--steps")) {
      o.steps = args.count("step count");
    } else if (args.is("--min-seconds")) {
      o.min_seconds = args.number("time");
    } else if (args.is("--repeat")) {
      o.repeat = args.count("repeat count");
    } else if (args.is("--max-seconds")) {
      o.max_seconds = args.number("time limit");
    } else if (args.is("--threads")) {
      o.threads = args.count("thread count");
    } else if (args.is("--tangent-only")) {
      o.tangent_only = true;
    } else {
      args.unknown();
    }
  }
  if (!o.mode_given) usage("--mode is required");
  // Scaling: p = 3 unless told otherwise (the degree of interest).
  if (o.mode == Mode::scaling && !o.degrees_given) o.degrees = {3};
  return o;
}

// CPU time of the process, all its threads (--threads; CHOLMOD may add an OpenMP thread).
double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

double seconds(Clock::duration d) {
  return std::chrono::duration<double>(d).count();
}

const char* to_string(KLKinematics k) {
  return k == KLKinematics::linear ? "linear" : "nonlinear";
}

// --- The roof ------------------------------------------------------------------------------------

constexpr double kRadius = 25.0, kLength = 50.0, kYoung = 4.32e8, kPoisson = 0.0, kThickness = 0.25,
                 kWeight = 90.0;
constexpr double kAngle = 80.0 * std::numbers::pi / 180.0;

// "Up": through the middle of the arc (the crown).
Vec3 up() {
  return Vec3(std::cos(0.5 * kAngle), std::sin(0.5 * kAngle), 0.0);
}

geometry::NurbsSurface roof(int p, int N) {
  // cylinder_sector: degree 2 along the arc (one segment ≤ 90°), 1 along the axis.
  return geometry::k_refine(geometry::cylinder_sector(kRadius, kLength, kAngle), p - 2, p - 1,
                            N - 1, N - 1);
}

elements::KLShellPatch roof_patch(const geometry::NurbsSurface& s, int threads) {
  elements::KLShellPatch patch(s, elements::KLShellSection{kYoung, kPoisson, kThickness, 1.0});
  patch.set_threads(threads);
  return patch;
}

system::KLBoundaryConditions roof_supports(const geometry::NurbsSurface& s) {
  system::KLBoundaryConditions bc(s);
  bc.fix_edge(loads::PatchEdge::v0, system::kCompX | system::kCompY);
  bc.fix_edge(loads::PatchEdge::v1, system::kCompX | system::kCompY);
  bc.fix_control_point(0, system::kCompZ);
  return bc;
}

loads::PatchLoads roof_load(const geometry::NurbsSurface& s, double factor) {
  return {std::make_shared<loads::AreaForce>(s, Vec3(-factor * kWeight * up()))};
}

// Vertical displacement of the midpoint of the free edge ξ = 0.
double free_edge_deflection(const geometry::NurbsSurface& s, const VecX& x) {
  geometry::NurbsSurface c = s;
  for (std::size_t a = 0; a < c.points.size(); ++a)
    c.points[a] = x.segment<3>(3 * static_cast<Eigen::Index>(a));
  return (geometry::evaluate(c, 0.0, 0.5).x - geometry::evaluate(s, 0.0, 0.5).x).dot(up());
}

// A smooth deformed state x = X + u, |u| ≈ 0.1 (0.4 % of R): membrane and bending stresses.
VecX deformed(const elements::KLShellPatch& patch) {
  VecX x = patch.reference_positions();
  const double k = std::numbers::pi / kLength;
  for (Eigen::Index a = 0; a < x.size() / 3; ++a) {
    const Vec3 X = x.segment<3>(3 * a);
    const double th = std::atan2(X.y(), X.x());
    x.segment<3>(3 * a) +=
        Vec3(0.02 * std::sin(k * X.z()) * std::cos(3.0 * th),
             -0.1 * std::sin(k * X.z()) * std::cos(th), 0.01 * std::sin(2.0 * k * X.z()));
  }
  return x;
}

// --- Statistics ----------------------------------------------------------------------------------

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
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

struct Timing {
  double cpu = 0.0, wall = 0.0;  // median per call
  int calls = 0;
  double first = 0.0;  // CPU time of a first call (solvers)
};

// Calls f until at least `repeat` calls and `min_seconds` CPU seconds; medians per call.
Timing time_calls(const std::function<void()>& f, int repeat, double min_seconds) {
  std::vector<double> cpu, wall;
  double total = 0.0;
  while (static_cast<int>(cpu.size()) < repeat || total < min_seconds) {
    const auto t0 = Clock::now();
    const double c0 = cpu_seconds();
    f();
    const double c = cpu_seconds() - c0;
    wall.push_back(seconds(Clock::now() - t0));
    cpu.push_back(c);
    total += c;
  }
  return {median(cpu), median(wall), static_cast<int>(cpu.size()), 0.0};
}

// --- assembly ------------------------------------------------------------------------------------

void run_assembly(const Options& o) {
  fmt::print(
      "Scordelis-Lo roof (full), {0} x {0} knot spans, degree p in both directions, Gauss (p+1)^2 "
      "per span; deformed state x = X + u; median of >= {1} calls and >= {2:g} CPU s\n"
      "times are CPU per call; ns/pt = CPU ns per quadrature point; Mpt/s = 1e6 points per CPU "
      "second (one thread)\n\n",
      o.n, o.repeat, o.min_seconds);
  fmt::print(
      "{:>2} {:>5} {:>7} {:>7} {:>9} {:>7} | {:>9} {:>8} {:>6} {:>5} | {:>9} {:>7} {:>6} | "
      "{:>9} {:>8} {:>9} {:>6} | {:>7}\n",
      "p", "N", "dofs", "qp", "nnz(K)", "setup_s", "nl+K_s", "ns/pt", "Mpt/s", "wall%", "nl_r_s",
      "ns/pt", "Mpt/s", "lin1_s", "ns/pt", "lin+K_s", "ns/pt", "K/r");
  for (int p : o.degrees) {
    const double c0 = cpu_seconds();
    const auto s = roof(p, o.n);
    const auto patch = roof_patch(s, o.threads);
    const double setup = cpu_seconds() - c0;
    const VecX x = deformed(patch);
    const double qp = patch.quadrature_points();
    SpMat K = patch.pattern();
    VecX r;
    const Timing tk = time_calls([&] { r = patch.internal_force(x, KLKinematics::nonlinear, &K); },
                                 o.repeat, o.min_seconds);
    if (o.tangent_only) {
      fmt::print("{:>2} {:>5} {:>7} {:>7} {:>9} {:>7.2f} | {:>9.4f} {:>8.0f} {:>6.3f} {:>5.0f}\n",
                 p, o.n, patch.dofs(), patch.quadrature_points(), K.nonZeros(), setup, tk.cpu,
                 1e9 * tk.cpu / qp, 1e-6 * qp / tk.cpu, 100.0 * tk.wall / tk.cpu);
      continue;
    }
    const Timing tr =
        time_calls([&] { r = patch.internal_force(x, KLKinematics::nonlinear, nullptr); }, o.repeat,
                   o.min_seconds);
    // The first linear call computes K_lin and caches it in the patch; the later ones copy it.
    const double cl = cpu_seconds();
    r = patch.internal_force(x, KLKinematics::linear, &K);
    const double lin_first = cpu_seconds() - cl;
    const Timing tl = time_calls([&] { r = patch.internal_force(x, KLKinematics::linear, &K); },
                                 o.repeat, o.min_seconds);
    auto ns = [&](const Timing& t) { return 1e9 * t.cpu / qp; };
    auto mps = [&](const Timing& t) { return 1e-6 * qp / t.cpu; };
    fmt::print(
        "{:>2} {:>5} {:>7} {:>7} {:>9} {:>7.2f} | {:>9.4f} {:>8.0f} {:>6.3f} {:>5.0f} | {:>9.4f} "
        "{:>7.0f} {:>6.3f} | {:>9.4f} {:>8.0f} {:>9.4f} {:>6.0f} | {:>7.1f}\n",
        p, o.n, patch.dofs(), patch.quadrature_points(), K.nonZeros(), setup, tk.cpu, ns(tk),
        mps(tk), 100.0 * tk.wall / tk.cpu, tr.cpu, ns(tr), mps(tr), lin_first, 1e9 * lin_first / qp,
        tl.cpu, ns(tl), tk.cpu / tr.cpu);
    std::fflush(stdout);
  }
  fmt::print(
      "\nnl+K: nonlinear residual + tangent; nl_r: nonlinear residual only; lin1: the first "
      "linear residual + tangent (computes K_lin, one call); lin+K: the later ones (K_lin cached "
      "in "
      "the patch);\nwall% = wall / CPU of nl+K (100: undisturbed); K/r = nl+K over "
      "nl_r\n");
}

// --- gradient ------------------------------------------------------------------------------------

void run_gradient(const Options& o) {
  fmt::print(
      "Scordelis-Lo roof (full), {0} x {0} knot spans; x0 = X + u, x1 = X + 1.1 u; median CPU s "
      "per call of >= {1} calls and >= {2:g} CPU s\n\n",
      o.n, o.repeat, o.min_seconds);
  fmt::print("{:>2} {:>5} {:>7} {:>7} | {:>9} {:>9} {:>6} | {:>9} {:>9} {:>6}\n", "p", "N", "dofs",
             "qp", "f+K_s", "DV+K_s", "ratio", "f_s", "DV_s", "ratio");
  for (int p : o.degrees) {
    const auto patch = roof_patch(roof(p, o.n), o.threads);
    const VecX X = patch.reference_positions();
    const VecX x0 = deformed(patch), x1 = x0 + 0.1 * (x0 - X);
    SpMat K = patch.pattern();
    VecX r;
    const auto nl = KLKinematics::nonlinear;
    const Timing fk =
        time_calls([&] { r = patch.internal_force(x1, nl, &K); }, o.repeat, o.min_seconds);
    const Timing gk =
        time_calls([&] { r = patch.discrete_gradient(x0, x1, nl, &K); }, o.repeat, o.min_seconds);
    const Timing f =
        time_calls([&] { r = patch.internal_force(x1, nl, nullptr); }, o.repeat, o.min_seconds);
    const Timing g = time_calls([&] { r = patch.discrete_gradient(x0, x1, nl, nullptr); }, o.repeat,
                                o.min_seconds);
    fmt::print(
        "{:>2} {:>5} {:>7} {:>7} | {:>9.4f} {:>9.4f} {:>6.2f} | {:>9.4f} {:>9.4f} {:>6.2f}\n", p,
        o.n, patch.dofs(), patch.quadrature_points(), fk.cpu, gk.cpu, gk.cpu / fk.cpu, f.cpu, g.cpu,
        g.cpu / f.cpu);
    std::fflush(stdout);
  }
}

// --- static solves (split, scaling) --------------------------------------------------------------

struct SolveRun {
  int p = 0, N = 0, dofs = 0, free = 0, qp = 0;
  KLKinematics kin{};
  long nnz = 0;
  int steps = 0, iterations = 0, evals_tangent = 0, evals_plain = 0, analyses = 0;
  double setup_cpu = 0.0;
  double asm_wall = 0.0, solve_wall = 0.0, wall = 0.0, cpu = 0.0, eval_cpu = 0.0;
  double deflection = 0.0;
  std::string status = "ok";
};

SolveRun run_static(int p, int N, KLKinematics kin, const Options& o) {
  SolveRun r;
  r.p = p;
  r.N = N;
  r.kin = kin;
  const double c0 = cpu_seconds();
  const auto s = roof(p, N);
  const auto patch = roof_patch(s, o.threads);
  const auto bcs = roof_supports(s);
  // Linear kinematics: the roof benchmark itself, one load step of the plain self-weight.
  const bool linear = kin == KLKinematics::linear;
  integrate::StaticProblem pb =
      test::kl_static_problem(patch, roof_load(s, linear ? 1.0 : o.load_factor), kin);
  // Wrap the provider: CPU time of the patch evaluation (residual, tangent, loads) and counts.
  auto inner = pb.evaluate;
  pb.evaluate = [&r, inner](const VecX& x, double t, bool with_tangent,
                            integrate::ResidualEvaluation& out) {
    const double c = cpu_seconds();
    inner(x, t, with_tangent, out);
    r.eval_cpu += cpu_seconds() - c;
    ++(with_tangent ? r.evals_tangent : r.evals_plain);
  };
  integrate::StaticSettings set;
  set.steps = linear ? 1 : o.steps;
  integrate::StaticNewtonSolver solver(std::move(pb), bcs.constraints(), set);
  r.setup_cpu = cpu_seconds() - c0;
  r.dofs = patch.dofs();
  r.free = solver.dofs().n_free();
  r.qp = patch.quadrature_points();
  r.nnz = patch.pattern().nonZeros();
  try {
    const auto t0 = Clock::now();
    const double c1 = cpu_seconds();
    const integrate::StaticResult res = solver.solve();
    r.cpu = cpu_seconds() - c1;
    r.wall = seconds(Clock::now() - t0);
    r.analyses = res.analyses;
    for (const auto& st : res.steps) {
      ++r.steps;
      r.iterations += st.iterations;
      r.asm_wall += st.assembly_seconds;
      r.solve_wall += st.solve_seconds;
    }
    r.deflection = free_edge_deflection(s, res.x);
  } catch (const std::exception& e) {
    r.status = fmt::format("failed: {}", e.what());
  }
  return r;
}

void run_split(const Options& o) {
  fmt::print(
      "Scordelis-Lo roof (full), {0} x {0} knot spans, nonlinear, {1:g} x self-weight in {2} "
      "load steps (residual tolerance 1e-10)\n"
      "asm = residual + tangent + value map into the Newton matrix; solve = factorization + "
      "solve; wall seconds from LoadStepStats,\nCPU: the whole solve and the patch evaluation "
      "alone (process CPU time)\n\n",
      o.n, o.load_factor, o.steps);
  fmt::print(
      "{:>2} {:>5} {:>7} {:>7} {:>5} {:>5} {:>5} {:>4} | {:>8} {:>8} {:>8} {:>8} {:>6} | {:>8} "
      "{:>8} {:>8} {:>6} | {:>9} {}\n",
      "p", "N", "dofs", "free", "steps", "iter", "evals", "evK", "asm_s", "solve_s", "asm/ev",
      "slv/it", "asm%", "wall_s", "cpu_s", "evalcpu", "ev%cpu", "w_edge", "status");
  for (int p : o.degrees) {
    const SolveRun r = run_static(p, o.n, KLKinematics::nonlinear, o);
    const int evals = r.evals_tangent + r.evals_plain;
    fmt::print(
        "{:>2} {:>5} {:>7} {:>7} {:>5} {:>5} {:>5} {:>4} | {:>8.3f} {:>8.3f} {:>8.4f} {:>8.4f} "
        "{:>6.1f} | {:>8.3f} {:>8.3f} {:>8.3f} {:>6.1f} | {:>9.5f} {}\n",
        p, r.N, r.dofs, r.free, r.steps, r.iterations, evals, r.evals_tangent, r.asm_wall,
        r.solve_wall, evals ? r.asm_wall / evals : 0.0,
        r.iterations ? r.solve_wall / r.iterations : 0.0,
        100.0 * r.asm_wall / (r.asm_wall + r.solve_wall), r.wall, r.cpu, r.eval_cpu,
        100.0 * r.eval_cpu / r.cpu, r.deflection, r.status);
    std::fflush(stdout);
  }
  fmt::print(
      "\nevals: provider evaluations (one more per load step than iterations: the converged "
      "state is checked with a fresh residual), evK: those with the tangent;\nasm/ev, slv/it: wall "
      "s "
      "per evaluation and per linear solve; asm% = asm / (asm + solve); ev%cpu = evaluation CPU / "
      "solve CPU;\nw_edge: vertical displacement of the midpoint of a free edge\n");
}

void run_scaling(const Options& o) {
  fmt::print(
      "Scordelis-Lo roof (full), N x N knot spans; linear: the self-weight in one load step (one "
      "solve); nonlinear: {0:g} x self-weight in {1} load steps\n\n",
      o.load_factor, o.steps);
  fmt::print(
      "{:>2} {:<9} {:>4} {:>7} {:>7} {:>9} {:>7} {:>5} {:>5} | {:>8} {:>8} {:>6} | {:>8} "
      "{:>8} {:>10} {:>6} | {:>9} {}\n",
      "p", "kin", "N", "dofs", "qp", "nnz(K)", "setup_s", "steps", "iter", "asm_s", "solve_s",
      "asm%", "wall_s", "cpu_s", "cpu_us/dof", "ratio", "w_edge", "status");
  for (int p : o.degrees)
    for (KLKinematics kin : o.kinematics) {
      std::vector<double> x, y, y_it;
      double first = 0.0;
      for (int N : o.sizes) {
        const SolveRun r = run_static(p, N, kin, o);
        const double per_dof = r.cpu / r.dofs;
        if (first == 0.0 && r.status == "ok") first = per_dof;
        fmt::print(
            "{:>2} {:<9} {:>4} {:>7} {:>7} {:>9} {:>7.2f} {:>5} {:>5} | {:>8.3f} {:>8.3f} {:>6.1f} "
            "| {:>8.3f} {:>8.3f} {:>10.2f} {:>6.2f} | {:>9.5f} {}\n",
            p, to_string(kin), N, r.dofs, r.qp, r.nnz, r.setup_cpu, r.steps, r.iterations,
            r.asm_wall, r.solve_wall, 100.0 * r.asm_wall / (r.asm_wall + r.solve_wall), r.wall,
            r.cpu, 1e6 * per_dof, first > 0 ? per_dof / first : 0.0, r.deflection, r.status);
        std::fflush(stdout);
        if (r.status == "ok") {
          x.push_back(r.dofs);
          y.push_back(r.cpu);
          y_it.push_back(r.cpu / std::max(1, r.iterations));
        }
        if (o.max_seconds > 0 && r.cpu > o.max_seconds) {
          fmt::print("   (larger sizes skipped: {:.1f} CPU s > --max-seconds)\n", r.cpu);
          break;
        }
      }
      if (x.size() >= 2) {
        fmt::print("   log-log fit, CPU time of the solve ∝ dofs^e: {} sizes, e = {:.2f}", x.size(),
                   loglog_slope(x, y));
        if (kin == KLKinematics::nonlinear)
          fmt::print(" (per Newton iteration e = {:.2f})", loglog_slope(x, y_it));
        if (x.size() >= 3) {
          const std::size_t k = x.size();
          fmt::print("; last two sizes e = {:.2f}",
                     std::log(y[k - 1] / y[k - 2]) / std::log(x[k - 1] / x[k - 2]));
        }
        fmt::print("\n");
      }
    }
  fmt::print(
      "\ncpu_s: process CPU time of solve() (setup excluded: geometry, refinement, patch, loads, "
      "constraints: setup_s);\nratio: CPU per dof over that of the first size (linear cost: 1)\n");
}

// --- solvers -------------------------------------------------------------------------------------

// K_ff: the tangent at the reference restricted to the free dofs (the Newton matrix of the first
// iteration, without multipliers: the same pattern as in every later iteration).
SpMat free_matrix(const elements::KLShellPatch& patch, const integrate::DofMap& dm) {
  SpMat K;
  patch.internal_force(patch.reference_positions(), KLKinematics::nonlinear, &K);
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(static_cast<std::size_t>(K.nonZeros()));
  for (int j = 0; j < K.outerSize(); ++j) {
    const int fj = dm.full_to_free[static_cast<std::size_t>(j)];
    if (fj < 0) continue;
    for (SpMat::InnerIterator it(K, j); it; ++it) {
      const int fi = dm.full_to_free[static_cast<std::size_t>(it.row())];
      if (fi >= 0) trip.emplace_back(fi, fj, it.value());
    }
  }
  SpMat A(dm.n_free(), dm.n_free());
  A.setFromTriplets(trip.begin(), trip.end());
  A.makeCompressed();
  return A;
}

void run_solvers(const Options& o) {
  fmt::print(
      "Scordelis-Lo roof (full), N x N knot spans: K_ff at the reference (free dofs), right-hand "
      "side the self-weight;\nfirst = analysis + factorization + solve (CPU s); again = median "
      "CPU s of >= {} repeated factorization + solve (analysis kept)\n\n",
      o.repeat);
  fmt::print(
      "{:>2} {:>4} {:>7} {:>9} | {:>9} {:>9} | {:>9} {:>9} | {:>9} {:>9} | {:>7} {:>5} {:>9}\n",
      "p", "N", "free", "nnz(A)", "ldlt_1st", "ldlt_again", "chol_1st", "chol_again", "lu_1st",
      "lu_again", "ldlt/ch", "wall%", "max|dx|");
  for (int p : o.degrees)
    for (int N : o.sizes) {
      const auto s = roof(p, N);
      const auto patch = roof_patch(s, o.threads);
      const auto cons = roof_supports(s).constraints();
      const auto dm = integrate::DofMap::build(patch.dofs(), cons.eliminated);
      const SpMat A = free_matrix(patch, dm);
      const VecX f = -roof_load(s, 1.0)[0]->force(patch.reference_positions());
      VecX b(dm.n_free());
      for (int k = 0; k < dm.n_free(); ++k) b(k) = f(dm.free[static_cast<std::size_t>(k)]);
      VecX x_ldlt, x_chol, x_lu;
      auto first_and_again = [&](auto& solver, VecX& x) {
        const double c = cpu_seconds();
        x = solver.solve(A, b);
        const double first = cpu_seconds() - c;
        Timing again = time_calls([&] { x = solver.solve(A, b); }, o.repeat, 0.0);
        again.first = first;
        return again;
      };
      solve::FixedPatternLDLT ldlt;
      solve::FixedPatternCholesky chol;
      solve::FixedPatternLU lu;
      const auto tl = first_and_again(ldlt, x_ldlt);
      const auto tc = first_and_again(chol, x_chol);
      const auto tu = first_and_again(lu, x_lu);
      const double dx = std::max((x_ldlt - x_chol).lpNorm<Eigen::Infinity>(),
                                 (x_lu - x_chol).lpNorm<Eigen::Infinity>()) /
                        x_chol.lpNorm<Eigen::Infinity>();
      fmt::print(
          "{:>2} {:>4} {:>7} {:>9} | {:>9.3f} {:>9.3f} | {:>9.3f} {:>9.3f} | {:>9.3f} {:>9.3f} | "
          "{:>7.2f} {:>5.0f} {:>9.1e}\n",
          p, N, dm.n_free(), A.nonZeros(), tl.first, tl.cpu, tc.first, tc.cpu, tu.first, tu.cpu,
          tl.cpu / tc.cpu, 100.0 * (tl.wall + tc.wall + tu.wall) / (tl.cpu + tc.cpu + tu.cpu), dx);
      std::fflush(stdout);
      if (o.max_seconds > 0 && tl.first + tc.first + tu.first > o.max_seconds) {
        fmt::print("   (larger sizes skipped: > --max-seconds)\n");
        break;
      }
    }
  fmt::print(
      "\nldlt/ch: repeated LDLT over repeated Cholesky; wall%: wall over CPU of the repeated calls "
      "(100: one thread, undisturbed);\nmax|dx|: largest difference of the three solutions "
      "relative to |x|\n");
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  fmt::print("assembly threads: {} (hardware threads: {})\n", o.threads,
             std::thread::hardware_concurrency());
  try {
    switch (o.mode) {
      case Mode::assembly:
        run_assembly(o);
        break;
      case Mode::gradient:
        run_gradient(o);
        break;
      case Mode::split:
        run_split(o);
        break;
      case Mode::scaling:
        run_scaling(o);
        break;
      case Mode::solvers:
        run_solvers(o);
        break;
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "kl_shell_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
