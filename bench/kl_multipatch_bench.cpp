// Multipatch Kirchhoff–Love study (IGA-thesis §6.4.2, Figs. 6.17, 6.21, 6.23, 6.26): a static
// model solved once per penalty β₁ of its bending strips (kl_interfaces.beta) and once per other
// coupling given. Per run, one CSV row: the coupling, β₁, the displacement of probe PROBE at the
// last load step, the Newton iterations, the unknowns, and the 2-norm condition number of the
// static Newton matrix at the converged state over the unknowns the solver solves for (the
// eliminated coordinates removed; dense SVD).
//
//   kl_multipatch_bench MODEL --probe NAME [--betas 1,1e2,1e4] [--couplings c0]
//
// Output on stdout: `coupling,beta,ux,uy,uz,newton_iterations,unknowns,condition_number`
// (a failed run: its message on stderr and empty columns). docs/theory/multipatch.md.
#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>
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
};

[[noreturn]] void usage(const std::string& msg) {
  std::fprintf(stderr,
               "kl_multipatch_bench: %s\n"
               "usage: kl_multipatch_bench MODEL --probe NAME [--betas 1,1e2,1e4] "
               "[--couplings c0]\n",
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
    } else if (args.is("--couplings")) {
      o.couplings = bench::split(args.value());
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

void run(const model::Model& m, const std::string& probe, const std::string& label, double beta) {
  const auto sys = system::System::compile(m);
  const auto it = std::find_if(sys.probes().begin(), sys.probes().end(),
                               [&](const auto& p) { return p.name == probe; });
  if (it == sys.probes().end()) usage("no probe named '" + probe + "'");
  integrate::StaticEquilibrium eq(sys, m.solver);
  int iterations = 0;
  double t = 0.0;
  try {
    const integrate::StaticResult r =
        eq.solve([&](const integrate::LoadStepStats& st, const VecX&) {
          iterations += st.iterations;
          t = st.t;
        });
    const Vec3 u = sys.probe_point(r.x.head(sys.n()), *it) - sys.probe_point(sys.q0(), *it);
    fmt::print("{},{:g},{:.12g},{:.12g},{:.12g},{},{},{:.6g}\n", label, beta, u.x(), u.y(), u.z(),
               iterations, eq.unknowns(), eq.newton_matrix_condition(t, r.x));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s, beta %g: %s\n", label.c_str(), beta, e.what());
    fmt::print("{},{:g},,,,,{},\n", label, beta, eq.unknowns());
  }
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  model::Model m = io::read_model(o.model);
  m.solver.analysis = model::Analysis::statics;
  fmt::print("coupling,beta,ux,uy,uz,newton_iterations,unknowns,condition_number\n");
  for (double beta : o.betas) {
    model::Model mb = m;
    mb.kl_interfaces.coupling = model::KLCoupling::bending_strip;
    mb.kl_interfaces.beta = beta;
    mb.kl_interfaces.pairs.clear();
    run(mb, o.probe, "bending_strip", beta);
  }
  for (const std::string& c : o.couplings) {
    if (c != "c0") usage("unknown coupling '" + c + "' (this bench knows c0)");
    model::Model mc = m;
    mc.kl_interfaces.coupling = model::KLCoupling::c0;
    mc.kl_interfaces.pairs.clear();
    run(mc, o.probe, c, 0.0);
  }
  return 0;
}
