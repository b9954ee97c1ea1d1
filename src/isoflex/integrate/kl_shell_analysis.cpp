#include "isoflex/integrate/kl_shell_analysis.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "isoflex/system/compile_error.hpp"
#include "isoflex/system/kl_model.hpp"

namespace isoflex::integrate {

namespace {

using system::compile_fail;

unsigned mask(const std::array<bool, 3>& c) {
  return (c[0] ? kCompX : 0u) | (c[1] ? kCompY : 0u) | (c[2] ? kCompZ : 0u);
}

}  // namespace

KLShellAnalysis KLShellAnalysis::compile(const model::Model& m) {
  if (m.kl_shells.empty()) throw std::logic_error("KLShellAnalysis: the model has no kl_shells");
  const model::KLShell& s = m.kl_shells.front();
  if (m.kl_shells.size() > 1)
    compile_fail(
        m.kl_shells[1].source, "kl_shells[1]",
        "one Kirchhoff–Love patch per model for now (multipatch coupling is not built yet)");
  if (!m.bodies.empty() || !m.beams.empty() || !m.shells.empty())
    compile_fail(
        s.source, "kl_shells[0]",
        "Kirchhoff–Love shells cannot yet be combined with bodies, beams or director shells");
  for (const auto& p : m.probes)
    if (p.kl_shell.empty())
      compile_fail(p.source, "probes",
                   "probe \"" + p.name + "\" names no kl_shell (the model has no bodies)");

  KLShellAnalysis a;
  a.shell_ = s;
  const geometry::NurbsSurface& g = system::kl_surface(m, s);
  a.patch_ = system::kl_patch(m, 0);
  a.kinematics_ = system::kl_kinematics(m);
  a.loads_ = system::kl_patch_loads(m, s);

  KLBoundaryConditions bcs(g);
  for (const model::KLSupport& sup : m.kl_supports) {
    try {
      if (sup.edge.empty()) {
        for (int cp : sup.control_points) bcs.fix_control_point(cp, mask(sup.components));
        continue;
      }
      const loads::PatchEdge e = loads::patch_edge_from_string(sup.edge);
      switch (sup.kind) {
        case model::KLSupportKind::fixed:
          bcs.fix_edge(e, mask(sup.components));
          break;
        case model::KLSupportKind::clamped:
          bcs.clamp_edge(e, mask(sup.components));
          break;
        case model::KLSupportKind::symmetry:
          bcs.symmetry_edge(e, sup.normal);
          break;
        case model::KLSupportKind::displacement: {
          auto f = std::make_shared<std::array<loads::TimeFunction, 3>>(
              std::array<loads::TimeFunction, 3>{loads::TimeFunction(sup.displacement[0]),
                                                 loads::TimeFunction(sup.displacement[1]),
                                                 loads::TimeFunction(sup.displacement[2])});
          bcs.prescribe_edge(
              e, [f](double t, const Vec3&) { return Vec3((*f)[0](t), (*f)[1](t), (*f)[2](t)); });
          break;
        }
      }
    } catch (const std::invalid_argument& e) {
      compile_fail(sup.source, "kl_supports", e.what());
    }
  }
  a.constraints_ = bcs.constraints();

  a.settings_.t_end = m.solver.t_end;
  a.settings_.steps = std::max(1, static_cast<int>(std::lround(m.solver.t_end / m.solver.dt)));
  a.settings_.adaptive = m.solver.max_subdivisions > 0;
  if (a.settings_.adaptive) a.settings_.max_cuts = m.solver.max_subdivisions;
  a.settings_.max_iterations = m.solver.max_iterations;
  a.settings_.residual_tolerance = m.solver.residual_tolerance;
  a.settings_.increment_tolerance = m.solver.increment_tolerance;

  for (const model::Probe& p : m.probes)
    a.probes_.push_back({p.name, p.xi, p.eta, geometry::evaluate(g, p.xi, p.eta).x});
  return a;
}

void KLShellAnalysis::set_threads(int threads) {
  auto p = std::make_shared<elements::KLShellPatch>(*patch_);  // shares the pre-evaluated data
  p->set_threads(threads);
  patch_ = std::move(p);
}

Vec3 KLShellAnalysis::point(const VecX& x, double xi, double eta) const {
  const geometry::NurbsSurface& g = patch_->reference();
  const geometry::SurfaceBasis B = geometry::surface_basis(g, xi, eta);
  Vec3 p = Vec3::Zero();
  for (int k = 0; k < B.R.cols(); ++k) p += B.R(0, k) * x.segment<3>(3 * B.global_index(g, k));
  return p;
}

}  // namespace isoflex::integrate
