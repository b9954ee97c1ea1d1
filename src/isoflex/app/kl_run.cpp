#include "isoflex/app/kl_run.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <vector>

#include "isoflex/app/progress.hpp"
#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/io/history_writer.hpp"
#include "isoflex/io/kl_shell_vtk.hpp"
#include "isoflex/io/summary_writer.hpp"

namespace isoflex::app {

void print_kl_check(const integrate::KLShellAnalysis& a, std::FILE* out) {
  const elements::KLShellPatch& p = a.patch();
  fmt::print(out,
             "kl shell         {} on surface {}: {} elements, {} quadrature points ({} x {} "
             "per element; reference data {} bytes per point)\n",
             a.shell().name, a.shell().surface, p.elements(), p.quadrature_points(),
             a.shell().quadrature[0] > 0 ? a.shell().quadrature[0] : p.reference().degree_u() + 1,
             a.shell().quadrature[1] > 0 ? a.shell().quadrature[1] : p.reference().degree_v() + 1,
             p.reference_bytes_per_point());
  fmt::print(out, "control points   {} (3 coordinates each)\n", p.control_points());
  fmt::print(out, "dofs             {}\n", p.dofs());
  fmt::print(out, "eliminated       {}  (fixed control-point components)\n", a.eliminated());
  fmt::print(out, "multipliers      {}  (prescribed edge displacements)\n", a.multipliers());
  fmt::print(out, "unknowns         {}  (free components + multipliers)\n", a.unknowns());
  fmt::print(out, "kinematics       {}\n",
             a.kinematics() == elements::KLKinematics::linear ? "linear" : "nonlinear");
  fmt::print(out, "load steps       {} to t = {:g}{}\n", a.settings().steps, a.settings().t_end,
             a.settings().adaptive
                 ? fmt::format(" (adaptive, at most {} halvings)", a.settings().max_cuts)
                 : "");
}

namespace {

integrate::Snapshot snapshot(const integrate::KLShellAnalysis& a, int step, double t,
                             const VecX& x) {
  integrate::Snapshot s;
  s.step = step;
  s.t = t;
  s.potential_energy = a.patch().energy(x, a.kinematics());
  s.total_energy = s.potential_energy;
  for (const integrate::KLProbe& p : a.probes()) {
    integrate::ProbeValue v;
    v.name = p.name;
    v.position = a.point(x, p.xi, p.eta);
    v.displacement = v.position - p.reference;
    s.probes.push_back(v);
  }
  return s;
}

}  // namespace

int run_kl_static(const std::string& model_file, const model::Model& m,
                  const integrate::KLShellAnalysis& a, const std::filesystem::path& outdir,
                  std::FILE* out, std::FILE* err) {
  std::vector<std::unique_ptr<integrate::Observer>> observers;
  if (m.output.history) {
    observers.push_back(std::make_unique<io::HistoryWriter>(outdir));
    observers.push_back(std::make_unique<io::ProbeWriter>(outdir, m));
  }
  observers.push_back(std::make_unique<ProgressBar>(a.settings().t_end, err));
  io::KLShellVtkWriter vtk(outdir, a, m.output.vtk_every);

  io::RunSummary sum;
  sum.model = model_file;
  sum.formulation = "static";
  sum.n_coordinates = a.patch().dofs();
  sum.n_constraints = a.eliminated() + a.multipliers();
  sum.n_unknowns = a.unknowns();
  sum.dt = a.settings().t_end / a.settings().steps;
  sum.t_end = a.settings().t_end;
  sum.threads = a.patch().threads_used();
  sum.max_energy_drift_after_loads = std::nan("");

  const VecX X = a.patch().reference_positions();
  integrate::Snapshot snap = snapshot(a, 0, 0.0, X);
  for (auto& ob : observers) ob->on_snapshot(snap);
  vtk.write(0, 0.0, X);
  sum.energy_initial = snap.total_energy;

  integrate::KLStaticSolver solver = a.solver();
  VecX last = X;
  int code = 0;
  const auto t0 = std::chrono::steady_clock::now();
  try {
    solver.solve([&](const integrate::LoadStepStats& st, const VecX& x) {
      snap = snapshot(a, st.step, st.t, x);
      snap.newton_iterations = st.iterations;
      snap.residual = st.residual;
      for (auto& ob : observers) ob->on_snapshot(snap);
      vtk.write(st.step, st.t, x);
      last = x;
      ++sum.steps;
      sum.newton_iterations_total += st.iterations;
    });
  } catch (const integrate::NewtonFailure& e) {
    sum.status = "failed";
    sum.message = e.what();
    code = 3;
  }
  sum.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  vtk.write(snap.step, snap.t, last, true);
  for (auto& ob : observers) ob->on_finish();
  sum.energy_final = snap.total_energy;
  sum.probes = snap.probes;
  io::write_summary_json(outdir / "summary.json", sum);
  if (code != 0) {
    fmt::print(err, "error: {}\n(results up to load step {}, t = {:.6g}, are in {})\n", sum.message,
               snap.step, snap.t, outdir.string());
    return code;
  }
  fmt::print(out,
             "{}: {} load steps, {} unknowns (kl shell, {}), {} Newton iterations, {:.3f} s; "
             "strain energy {:.12g}; results in {}\n",
             model_file, sum.steps, sum.n_unknowns,
             a.kinematics() == elements::KLKinematics::linear ? "linear" : "nonlinear",
             sum.newton_iterations_total, sum.wall_time_s, sum.energy_final, outdir.string());
  for (const auto& p : snap.probes)
    fmt::print(out, "  probe {}: displacement ({:.10g}, {:.10g}, {:.10g})\n", p.name,
               p.displacement.x(), p.displacement.y(), p.displacement.z());
  return 0;
}

}  // namespace isoflex::app
