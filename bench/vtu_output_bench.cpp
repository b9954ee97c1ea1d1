// VTU output benchmark (issue #21, bench/vtu_output.md): the size of vtk/ and the wall time of
// io::VtkSeriesWriter in each output.vtk_format, apart from the solve. The model is solved once
// (statically with --static, as `isoflex run --static`; else by its time integrator) with its
// snapshots kept in memory, then the snapshots are written R times per format into a fresh
// folder; the time is the fastest of the R, from the writer's construction to on_finish (the
// meshes, the stresses of the Kirchhoff–Love patches, the text or bytes and the files).
//
//   vtu_output_bench MODEL [--static] [--set KEY=VALUE ...] [--repeat R] [--out DIR]
//
// DIR (default: a folder in the system's temp directory) holds DIR/binary and DIR/ascii after the
// run, for inspection.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench_cli.hpp"
#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/integrate/static_equilibrium.hpp"
#include "isoflex/integrate/time_integrator.hpp"
#include "isoflex/io/model_overrides.hpp"
#include "isoflex/io/model_reader.hpp"
#include "isoflex/io/vtk_writer.hpp"
#include "isoflex/system/system.hpp"

namespace {

using namespace isoflex;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct Options {
  std::string model;
  bool statics = false;
  std::vector<io::ModelOverride> overrides;
  int repeat = 3;
  fs::path out = fs::temp_directory_path() / "isoflex_vtu_output_bench";
};

[[noreturn]] void usage(const std::string& msg) {
  std::fprintf(stderr,
               "vtu_output_bench: %s\n"
               "usage: vtu_output_bench MODEL [--static] [--set KEY=VALUE ...] [--repeat R] "
               "[--out DIR]\n",
               msg.c_str());
  std::exit(2);
}

Options parse(int argc, char** argv) {
  Options o;
  bench::Args args(argc, argv, usage);
  while (args.next()) {
    if (args.is("--static")) {
      o.statics = true;
    } else if (args.is("--set")) {
      try {
        o.overrides.push_back(io::parse_model_override(args.value()));
      } catch (const std::invalid_argument& e) {
        usage(e.what());
      }
    } else if (args.is("--repeat")) {
      o.repeat = args.count("repeat count");
    } else if (args.is("--out")) {
      o.out = args.value();
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

std::vector<std::string> body_names(const model::Model& m) {
  std::vector<std::string> names;
  for (const auto& b : m.bodies) names.push_back(b.name);
  for (const auto& b : m.beams)
    for (int i = 0; i < b.node_count(); ++i) names.push_back(fmt::format("{}[{}]", b.name, i));
  return names;
}

// The snapshots of the run: the initial state, then one per time or load step.
std::vector<integrate::Snapshot> run(const system::System& sys, const model::Model& m,
                                     bool statics) {
  const auto names = body_names(m);
  integrate::State state;
  state.q = sys.q0();
  state.v = statics ? VecX::Zero(sys.n()) : sys.v0();
  std::vector<integrate::Snapshot> snapshots{integrate::snapshot(sys, state, {}, names)};
  if (statics) {
    integrate::StaticEquilibrium equilibrium(sys, m.solver);
    equilibrium.solve([&](const integrate::LoadStepStats& st, const VecX& x) {
      state.q = x.head(sys.n());
      state.lambda = x.segment(sys.n(), sys.m_selected());
      state.t = st.t;
      state.step = st.step;
      snapshots.push_back(
          integrate::snapshot(sys, state, {st.iterations, st.residual, st.cuts + 1}, names));
    });
  } else {
    const auto integ = integrate::make_time_integrator(sys, m.solver);
    const int steps = static_cast<int>(std::lround(m.solver.t_end / m.solver.dt));
    for (int i = 0; i < steps; ++i) {
      const auto st = integ->step(state);
      snapshots.push_back(integrate::snapshot(sys, state, st, names));
    }
  }
  return snapshots;
}

std::uintmax_t folder_bytes(const fs::path& dir) {
  std::uintmax_t bytes = 0;
  for (const auto& e : fs::directory_iterator(dir)) bytes += e.file_size();
  return bytes;
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  try {
    io::ReadOptions read;
    read.overrides = o.overrides;
    const model::Model m = io::read_model(o.model, read);
    auto t0 = Clock::now();
    const auto sys = system::System::compile(m);
    const double compile_s = seconds(Clock::now() - t0);
    t0 = Clock::now();
    const std::vector<integrate::Snapshot> snapshots = run(sys, m, o.statics);
    const double solve_s = seconds(Clock::now() - t0);
    fmt::print(
        "model {}: {} coordinates, {} snapshots, vtk_every {}; compile {:.3f} s, solve {:.3f} s\n",
        o.model, sys.n(), snapshots.size(), m.output.vtk_every, compile_s, solve_s);
    fmt::print("{:<7} {:>6} {:>14} {:>10} {:>9} {:>8}\n", "format", "files", "bytes", "MB",
               "write_s", "spread");
    for (const auto format : {model::VtkFormat::binary, model::VtkFormat::ascii}) {
      const fs::path dir = o.out / (format == model::VtkFormat::binary ? "binary" : "ascii");
      double best = 0.0, slowest = 0.0;
      std::size_t files = 0;
      for (int r = 0; r < o.repeat; ++r) {
        fs::remove_all(dir);
        const auto start = Clock::now();
        {
          io::VtkSeriesWriter w(dir, m, m.output.vtk_every, format);
          for (const auto& s : snapshots) w.on_snapshot(s);
          w.on_finish();
          files = w.files().size();
        }
        const double t = seconds(Clock::now() - start);
        best = r == 0 ? t : std::min(best, t);
        slowest = std::max(slowest, t);
      }
      const std::uintmax_t bytes = folder_bytes(dir / "vtk");
      fmt::print("{:<7} {:>6} {:>14} {:>10.2f} {:>9.3f} {:>7.0f}%\n",
                 format == model::VtkFormat::binary ? "binary" : "ascii", files, bytes, bytes / 1e6,
                 best, 100 * (slowest - best) / best);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "vtu_output_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
