// IGA-thesis Table 6.1 (§6.4.2.5, examples/kl_hinged_plate): Newton iterations per step and the
// condition number of the Newton matrix for fixed steps h, on one patch, on two patches joined by
// a bending strip of penalty β₁ (SBSM) and by the AF-D rows. Per integrator, h and variant, one
// CSV row: the run to the model's t_end (or --t-end) with no step subdivision, so that a step
// whose Newton iteration fails ends the run there, as the thesis' "–"; the condition number is
// the 2-norm one (dense SVD) of the Newton matrix at the first Newton start: S_t (2.27) of the
// DAE scheme as it solves it (scaled by IGA-thesis §2.2.4 unless the model says otherwise), or
// the energy–momentum scheme's in its formulation.
//
//   kl_transient_table_bench ONE_PATCH TWO_PATCH [--dts 1e-1,1e-2,1e-3] [--betas 1e3,1e4,1e5]
//                            [--integrators generalized_alpha,energy_momentum] [--t-end T]
//
// Output on stdout: `integrator,h,variant,beta,unknowns,steps,newton_iterations,
// iterations_per_step,condition_number,failed_at` (failed_at empty when the run reached t_end).
#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "bench_cli.hpp"
#include "isoflex/integrate/dae_integrator.hpp"
#include "isoflex/integrate/newton_loop.hpp"
#include "isoflex/io/model_reader.hpp"
#include "isoflex/solve/linear_solver.hpp"
#include "newton_condition.hpp"

namespace {

using namespace isoflex;

struct Options {
  std::string one_patch, two_patch;
  std::vector<double> dts{1e-1, 1e-2, 1e-3};
  std::vector<double> betas{1e3, 1e4, 1e5};
  std::vector<model::Integrator> integrators{model::Integrator::generalized_alpha,
                                             model::Integrator::energy_momentum};
  double t_end = -1.0;
};

[[noreturn]] void usage(const std::string& msg) {
  std::fprintf(stderr,
               "kl_transient_table_bench: %s\n"
               "usage: kl_transient_table_bench ONE_PATCH TWO_PATCH [--dts 1e-1,1e-2,1e-3]\n"
               "                                [--betas 1e3,1e4,1e5] [--t-end T]\n"
               "                                [--integrators "
               "generalized_alpha,energy_momentum]\n",
               msg.c_str());
  std::exit(2);
}

Options parse(int argc, char** argv) {
  Options o;
  bench::Args args(argc, argv, usage);
  while (args.next()) {
    if (args.is("--dts")) {
      o.dts.clear();
      for (const auto& d : bench::split(args.value()))
        o.dts.push_back(bench::parse_double(d, "time step", usage));
    } else if (args.is("--betas")) {
      o.betas.clear();
      for (const auto& b : bench::split(args.value()))
        o.betas.push_back(bench::parse_double(b, "beta", usage));
    } else if (args.is("--integrators")) {
      o.integrators.clear();
      for (const auto& name : bench::split(args.value())) {
        const auto i = model::integrator_from_string(name);
        if (!i) usage(fmt::format("unknown integrator '{}'", name));
        o.integrators.push_back(*i);
      }
    } else if (args.is("--t-end")) {
      o.t_end = args.number("end time");
    } else if (!args.arg().empty() && args.arg()[0] == '-') {
      args.unknown();
    } else if (o.one_patch.empty()) {
      o.one_patch = args.arg();
    } else if (o.two_patch.empty()) {
      o.two_patch = args.arg();
    } else {
      usage("more than two model files");
    }
  }
  if (o.two_patch.empty()) usage("two model files: the one-patch and the two-patch plate");
  return o;
}

struct Variant {
  std::string name;
  const model::Model* base;
  model::KLCoupling coupling;
  double beta;
};

double first_condition(const system::System& sys, const model::Solver& s) {
  if (s.integrator == model::Integrator::energy_momentum)
    return bench::newton_condition(sys, s).at_start;
  const integrate::DaeIntegrator dae(sys, s);
  return solve::condition_number(MatX(dae.iteration_matrix(dae.initial_state())));
}

void run(const Variant& v, model::Integrator integrator, double h, double t_end) {
  model::Model m = *v.base;
  m.solver.integrator = integrator;
  m.solver.dt = h;
  m.solver.max_subdivisions = 0;
  if (t_end > 0) m.solver.t_end = t_end;
  if (!m.kl_interfaces.pairs.empty()) throw std::invalid_argument("per-pair couplings not varied");
  m.kl_interfaces.coupling = v.coupling;
  m.kl_interfaces.beta = v.beta;
  const auto sys = system::System::compile(m);
  const auto integ = integrate::make_time_integrator(sys, m.solver);
  const int steps = static_cast<int>(std::lround(m.solver.t_end / h));
  integrate::State s = integ->initial_state();
  long iterations = 0;
  int done = 0;
  std::string failed_at;
  try {
    for (; done < steps; ++done) iterations += integ->step(s).iterations;
  } catch (const integrate::NewtonFailure& e) {
    failed_at = fmt::format("{:.6g}", s.t);
    std::fprintf(stderr, "%s, h = %g, %s: %s\n", model::to_string(integrator), h, v.name.c_str(),
                 e.what());
  }
  const bool strip = v.coupling == model::KLCoupling::bending_strip;
  std::printf("%s,%g,%s,%s,%d,%d,%ld,%.3f,%.3e,%s\n", model::to_string(integrator), h,
              v.name.c_str(), strip ? fmt::format("{:g}", v.beta).c_str() : "", integ->unknowns(),
              done, iterations, done > 0 ? double(iterations) / done : 0.0,
              first_condition(sys, m.solver), failed_at.c_str());
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  try {
    const model::Model one = io::read_model(o.one_patch), two = io::read_model(o.two_patch);
    std::vector<Variant> variants{{"one_patch", &one, model::KLCoupling::c0, 0.0}};
    for (double b : o.betas)
      variants.push_back({"sbsm", &two, model::KLCoupling::bending_strip, b});
    variants.push_back({"af_d", &two, model::KLCoupling::angle, 0.0});
    std::printf(
        "integrator,h,variant,beta,unknowns,steps,newton_iterations,iterations_per_step,"
        "condition_number,failed_at\n");
    for (model::Integrator i : o.integrators)
      for (double h : o.dts)
        for (const Variant& v : variants) run(v, i, h, o.t_end);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "kl_transient_table_bench: %s\n", e.what());
    return 1;
  }
}
