#include "isoflex/integrate/kl_shell_analysis.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "isoflex/loads/kl_edge_moment.hpp"
#include "isoflex/system/system.hpp"

namespace isoflex::integrate {

namespace {

[[noreturn]] void fail(const model::Source& s, const std::string& what, const std::string& msg) {
  throw system::CompileError(
      fmt::format("{}:{}: {}: {}", s.file.empty() ? "<model>" : s.file, s.line, what, msg));
}

loads::PatchEdge patch_edge(const std::string& e) {
  if (e == "u0") return loads::PatchEdge::u0;
  if (e == "u1") return loads::PatchEdge::u1;
  if (e == "v0") return loads::PatchEdge::v0;
  return loads::PatchEdge::v1;
}

unsigned mask(const std::array<bool, 3>& c) {
  return (c[0] ? kCompX : 0u) | (c[1] ? kCompY : 0u) | (c[2] ? kCompZ : 0u);
}

// A vector load given as three time functions: one load per non-zero component, each the unit
// direction times its own factor.
template <class Make>
void per_component(const std::array<std::string, 3>& f, PatchLoads& out, Make&& make) {
  for (int c = 0; c < 3; ++c) {
    if (f[c] == "0") continue;
    out.push_back(make(Vec3::Unit(c), loads::TimeFunction(f[c])));
  }
}

}  // namespace

KLShellAnalysis KLShellAnalysis::compile(const model::Model& m) {
  if (m.kl_shells.empty()) throw std::logic_error("KLShellAnalysis: the model has no kl_shells");
  const model::KLShell& s = m.kl_shells.front();
  if (m.kl_shells.size() > 1)
    fail(m.kl_shells[1].source, "kl_shells[1]",
         "one Kirchhoff–Love patch per model for now (multipatch coupling is not built yet)");
  if (!m.bodies.empty() || !m.beams.empty() || !m.shells.empty())
    fail(s.source, "kl_shells[0]",
         "Kirchhoff–Love shells cannot yet be combined with bodies, beams or director shells");
  for (const auto& p : m.probes)
    if (p.kl_shell.empty())
      fail(p.source, "probes",
           "probe \"" + p.name + "\" names no kl_shell (the model has no bodies)");

  KLShellAnalysis a;
  a.shell_ = s;
  const auto surf = std::find_if(m.surfaces.begin(), m.surfaces.end(),
                                 [&](const model::Surface& f) { return f.name == s.surface; });
  if (surf == m.surfaces.end()) throw std::logic_error("KLShellAnalysis: surface not found");
  const geometry::NurbsSurface& g = surf->surface;
  try {
    a.patch_ = std::make_shared<elements::KLShellPatch>(
        g, elements::KLShellSection{s.E, s.nu, s.thickness, s.density}, s.quadrature[0],
        s.quadrature[1]);
  } catch (const std::invalid_argument& e) {
    fail(s.source, "kl_shells[0]", e.what());
  }
  a.kinematics_ =
      m.solver.linear ? elements::KLKinematics::linear : elements::KLKinematics::nonlinear;

  const geometry::QuadratureOrder order{s.quadrature[0], s.quadrature[1]};
  for (const model::KLLoad& l : m.kl_loads) {
    try {
      switch (l.kind) {
        case model::KLLoadKind::area_force:
          per_component(l.force, a.loads_, [&](const Vec3& d, loads::TimeFunction f) {
            return std::make_shared<loads::AreaForce>(g, d, std::move(f), order);
          });
          break;
        case model::KLLoadKind::pressure:
          if (l.follower)
            a.loads_.push_back(std::make_shared<loads::FollowerPressure>(
                g, 1.0, loads::TimeFunction(l.pressure), order));
          else
            a.loads_.push_back(std::make_shared<loads::DeadPressure>(
                g, 1.0, loads::TimeFunction(l.pressure), order));
          break;
        case model::KLLoadKind::self_weight:
          a.loads_.push_back(std::make_shared<loads::AreaForce>(loads::self_weight(
              g, s.density, s.thickness, m.gravity, loads::TimeFunction(l.factor))));
          break;
        case model::KLLoadKind::edge_force:
          per_component(l.force, a.loads_, [&](const Vec3& d, loads::TimeFunction f) {
            return std::make_shared<loads::LineLoad>(g, patch_edge(l.edge), d, std::move(f));
          });
          break;
        case model::KLLoadKind::edge_moment:
          a.loads_.push_back(std::make_shared<loads::EdgeMoment>(g, patch_edge(l.edge), l.axis, 1.0,
                                                                 loads::TimeFunction(l.moment)));
          break;
        case model::KLLoadKind::point_force:  // projected by the reader
          per_component(l.force, a.loads_, [&](const Vec3& d, loads::TimeFunction f) {
            return std::make_shared<loads::PointLoad>(g, l.xi, l.eta, d, std::move(f));
          });
          break;
      }
    } catch (const std::invalid_argument& e) {
      fail(l.source, "kl_loads", e.what());
    }
  }

  KLBoundaryConditions bcs(g);
  for (const model::KLSupport& sup : m.kl_supports) {
    try {
      if (sup.edge.empty()) {
        for (int cp : sup.control_points) bcs.fix_control_point(cp, mask(sup.components));
        continue;
      }
      const loads::PatchEdge e = patch_edge(sup.edge);
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
      fail(sup.source, "kl_supports", e.what());
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
