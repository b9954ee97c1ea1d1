// Multipatch Kirchhoff–Love study (IGA-thesis §6.4.2, Figs. 6.17, 6.21, 6.23, 6.26): a static
// model solved once per penalty β₁ of its bending strips (kl_interfaces.beta) and once per other
// coupling given. Per run, one CSV row: the coupling, β₁, the displacement of probe PROBE at the
// last load step, the Newton iterations, the unknowns, and the 2-norm condition number of the
// static Newton matrix at the converged state over the unknowns the solver solves for (the
// eliminated coordinates removed; dense SVD), and with --angle-at the relative change
// |θ − θ₀|/θ₀ of the angle between the patches at the interface triple whose shared control
// point is nearest to the given point (the angle of the triple's legs, which are the tangents
// across the edge: Fig. 6.21's error; in a linear analysis its linearized change).
//
//   kl_multipatch_bench MODEL --probe NAME [--betas 1,1e2,1e4] [--perturbed]
//                       [--couplings c0,strip_constraints,angle] [--angle-at X,Y,Z]
//
// --perturbed: also the perturbed Lagrange coupling (5.24) with α₁ over the same values.
//
// Output on stdout: `coupling,beta,ux,uy,uz,newton_iterations,unknowns,condition_number,
// angle_error` (a failed run: its message on stderr and empty columns).
// docs/theory/multipatch.md.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <optional>
#include <string>
#include <vector>

#include "bench_cli.hpp"
#include "isoflex/integrate/static_equilibrium.hpp"
#include "isoflex/io/model_reader.hpp"
#include "isoflex/system/system.hpp"

namespace {

using namespace isoflex;

struct Options {
  std::string model, probe;
  std::vector<double> betas{1.0, 1e2, 1e4};
  std::vector<std::string> couplings;  // besides bending_strip
  bool perturbed = false;              // perturbed_lagrange with α₁ over the betas too
  std::optional<Vec3> angle_at;
};

[[noreturn]] void usage(const std::string& msg) {
  std::fprintf(stderr,
               "kl_multipatch_bench: %s\n"
               "usage: kl_multipatch_bench MODEL --probe NAME [--betas 1,1e2,1e4] [--perturbed]\n"
               "                           [--couplings c0,strip_constraints,angle] "
               "[--angle-at X,Y,Z]\n",
               msg.c_str());
  std::exit(2);
}

Options parse(int argc, char** argv) {
  Options o;
  bench::Args args(argc, argv, usage);
  while (args.next()) {
    if (args.is("--probe")) {
      o.probe = args.value();
    } else if (args.is("--betas")) {
      o.betas.clear();
      for (const auto& b : bench::split(args.value()))
        o.betas.push_back(bench::parse_double(b, "beta", usage));
    } else if (args.is("--perturbed")) {
      o.perturbed = true;
    } else if (args.is("--couplings")) {
      o.couplings = bench::split(args.value());
    } else if (args.is("--angle-at")) {
      const auto c = bench::split(args.value());
      if (c.size() != 3) usage("--angle-at needs X,Y,Z");
      Vec3 x;
      for (int k = 0; k < 3; ++k) {
        char* end = nullptr;
        x[k] = std::strtod(c[static_cast<std::size_t>(k)].c_str(), &end);
        if (*end != '\0') usage("bad coordinate '" + c[static_cast<std::size_t>(k)] + "'");
      }
      o.angle_at = x;
    } else if (o.model.empty() && args.arg()[0] != '-') {
      o.model = args.arg();
    } else {
      usage("unknown argument '" + args.arg() + "'");
    }
  }
  if (o.model.empty()) usage("no model file");
  if (o.probe.empty()) usage("--probe is required");
  return o;
}

// The angle of the legs of a triple (inner a, shared, inner b) in q.
double triple_angle(const system::System& sys, const VecX& q, const std::array<int, 3>& nodes) {
  const VecX x = sys.stacked(q, {nodes[0], nodes[1], nodes[2]});
  const Vec3 a = x.segment<3>(0) - x.segment<3>(3), b = x.segment<3>(6) - x.segment<3>(3);
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

// The triple nodes of the interface triple whose shared point is nearest to p.
std::array<int, 3> nearest_triple(const system::System& sys, const Vec3& p) {
  std::array<int, 3> best{-1, -1, -1};
  double d = INFINITY;
  for (const auto& I : sys.kl_interfaces())
    for (std::size_t k = 0; k < I.triple_nodes.size(); k += 3) {
      const double dk = (Vec3(sys.stacked(sys.q0(), {I.triple_nodes[k + 1]})) - p).norm();
      if (dk < d) {
        d = dk;
        best = {I.triple_nodes[k], I.triple_nodes[k + 1], I.triple_nodes[k + 2]};
      }
    }
  if (best[0] < 0) usage("--angle-at: the model has no interface");
  return best;
}

// One run: compile, solve, print the row (throws what compile and the solver throw).
void solve_and_print(const model::Model& m, const std::string& probe, const std::string& label,
                     double beta, const std::optional<Vec3>& angle_at) {
  const auto sys = system::System::compile(m);
  const auto it = std::find_if(sys.probes().begin(), sys.probes().end(),
                               [&](const auto& p) { return p.name == probe; });
  if (it == sys.probes().end()) usage("no probe named '" + probe + "'");
  integrate::StaticEquilibrium eq(sys, m.solver);
  int iterations = 0;
  double t = 0.0;
  const integrate::StaticResult r = eq.solve([&](const integrate::LoadStepStats& st, const VecX&) {
    iterations += st.iterations;
    t = st.t;
  });
  const VecX dq = r.x.head(sys.n()) - sys.q0();
  const Vec3 u = sys.probe_point(sys.q0() + dq, *it) - sys.probe_point(sys.q0(), *it);
  std::string angle;
  if (angle_at) {
    const std::array<int, 3> T = nearest_triple(sys, *angle_at);
    const double th0 = triple_angle(sys, sys.q0(), T);
    // A linear analysis: the linearized change θ'(Δq), (θ(q₀ + Δq) − θ(q₀ − Δq))/2 (the
    // quadratic part of θ(q₀ + s Δq) cancels), so that the constraints' own accuracy shows.
    const double dth =
        m.solver.linear
            ? 0.5 * (triple_angle(sys, sys.q0() + dq, T) - triple_angle(sys, sys.q0() - dq, T))
            : triple_angle(sys, sys.q0() + dq, T) - th0;
    angle = fmt::format("{:.6g}", std::abs(dth) / th0);
  }
  fmt::print("{},{:g},{:.12g},{:.12g},{:.12g},{},{},{:.6g},{}\n", label, beta, u.x(), u.y(), u.z(),
             iterations, eq.unknowns(), eq.newton_matrix_condition(t, r.x), angle);
}

void run(const model::Model& m, const std::string& probe, const std::string& label, double beta,
         const std::optional<Vec3>& angle_at) {
  try {
    solve_and_print(m, probe, label, beta, angle_at);
  } catch (const std::exception& e) {  // a model this coupling cannot compile, or no convergence
    std::fprintf(stderr, "%s, beta %g: %s\n", label.c_str(), beta, e.what());
    fmt::print("{},{:g},,,,,,,\n", label, beta);
  }
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  model::Model m = io::read_model(o.model);
  m.solver.analysis = model::Analysis::statics;
  fmt::print("coupling,beta,ux,uy,uz,newton_iterations,unknowns,condition_number,angle_error\n");
  for (const bool perturbed : {false, true}) {
    if (perturbed && !o.perturbed) continue;
    for (double beta : o.betas) {
      model::Model mb = m;
      mb.kl_interfaces.coupling =
          perturbed ? model::KLCoupling::perturbed_lagrange : model::KLCoupling::bending_strip;
      mb.kl_interfaces.beta = beta;
      mb.kl_interfaces.pairs.clear();
      run(mb, o.probe, perturbed ? "perturbed_lagrange" : "bending_strip", beta, o.angle_at);
    }
  }
  for (const std::string& c : o.couplings) {
    model::Model mc = m;
    if (c == "c0")
      mc.kl_interfaces.coupling = model::KLCoupling::c0;
    else if (c == "strip_constraints")
      mc.kl_interfaces.coupling = model::KLCoupling::strip_constraints;
    else if (c == "angle")
      mc.kl_interfaces.coupling = model::KLCoupling::angle;
    else
      usage("unknown coupling '" + c + "' (c0, strip_constraints or angle)");
    mc.kl_interfaces.pairs.clear();
    run(mc, o.probe, c, 0.0, o.angle_at);
  }
  return 0;
}
