#include "isoflex/system/kl_model.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "isoflex/loads/kl_edge_moment.hpp"
#include "isoflex/system/compile_error.hpp"

namespace isoflex::system {

namespace {

// A vector load given as three time functions: one load per non-zero component, each the unit
// direction times its own factor.
template <class Make>
void per_component(const std::array<std::string, 3>& f, loads::PatchLoads& out, Make&& make) {
  for (int c = 0; c < 3; ++c) {
    if (f[c] == "0") continue;
    out.push_back(make(Vec3::Unit(c), loads::TimeFunction(f[c])));
  }
}

}  // namespace

void compile_fail(const model::Source& s, const std::string& what, const std::string& msg) {
  throw CompileError(
      fmt::format("{}:{}: {}: {}", s.file.empty() ? "<model>" : s.file, s.line, what, msg));
}

const geometry::NurbsSurface& kl_surface(const model::Model& m, const model::KLShell& s) {
  const auto surf = std::find_if(m.surfaces.begin(), m.surfaces.end(),
                                 [&](const model::Surface& f) { return f.name == s.surface; });
  if (surf == m.surfaces.end())
    compile_fail(s.source, "kl_shells", "no surface named '" + s.surface + "'");
  return surf->surface;
}

std::shared_ptr<elements::KLShellPatch> kl_patch(const model::Model& m, int index,
                                                 const geometry::NurbsSurface& g) {
  const model::KLShell& s = m.kl_shells[index];
  try {
    return std::make_shared<elements::KLShellPatch>(
        g, elements::KLShellSection{s.E, s.nu, s.thickness, s.density, s.eta}, s.quadrature[0],
        s.quadrature[1]);
  } catch (const std::invalid_argument& e) {
    compile_fail(s.source, fmt::format("kl_shells[{}]", index), e.what());
  }
}

elements::KLKinematics kl_kinematics(const model::Model& m) {
  return m.solver.linear ? elements::KLKinematics::linear : elements::KLKinematics::nonlinear;
}

loads::PatchLoads kl_patch_loads(const model::Model& m, const model::KLShell& s,
                                 const geometry::NurbsSurface& g) {
  const geometry::QuadratureOrder order{s.quadrature[0], s.quadrature[1]};
  loads::PatchLoads out;
  for (const model::KLLoad& l : m.kl_loads) {
    if (l.shell != s.name) continue;
    try {
      switch (l.kind) {
        case model::KLLoadKind::area_force:
          per_component(l.force, out, [&](const Vec3& d, loads::TimeFunction f) {
            return std::make_shared<loads::AreaForce>(g, d, std::move(f), order);
          });
          break;
        case model::KLLoadKind::pressure:
          if (l.follower)
            out.push_back(std::make_shared<loads::FollowerPressure>(
                g, 1.0, loads::TimeFunction(l.pressure), order));
          else
            out.push_back(std::make_shared<loads::DeadPressure>(
                g, 1.0, loads::TimeFunction(l.pressure), order));
          break;
        case model::KLLoadKind::self_weight:
          out.push_back(std::make_shared<loads::AreaForce>(loads::self_weight(
              g, s.density, s.thickness, m.gravity, loads::TimeFunction(l.factor))));
          break;
        case model::KLLoadKind::edge_force:
          per_component(l.force, out, [&](const Vec3& d, loads::TimeFunction f) {
            return std::make_shared<loads::LineLoad>(g, loads::patch_edge_from_string(l.edge), d,
                                                     std::move(f));
          });
          break;
        case model::KLLoadKind::edge_moment:
          out.push_back(
              std::make_shared<loads::EdgeMoment>(g, loads::patch_edge_from_string(l.edge), l.axis,
                                                  1.0, loads::TimeFunction(l.moment)));
          break;
        case model::KLLoadKind::point_force:  // projected by the reader
          per_component(l.force, out, [&](const Vec3& d, loads::TimeFunction f) {
            return std::make_shared<loads::PointLoad>(g, l.xi, l.eta, d, std::move(f));
          });
          break;
      }
    } catch (const std::invalid_argument& e) {
      compile_fail(l.source, "kl_loads", e.what());
    }
  }
  return out;
}

namespace {

unsigned mask(const std::array<bool, 3>& c) {
  return (c[0] ? kCompX : 0u) | (c[1] ? kCompY : 0u) | (c[2] ? kCompZ : 0u);
}

}  // namespace

KLBoundaryConditions kl_boundary_conditions(
    const model::Model& m, const geometry::NurbsSurface& g,
    const std::function<bool(const model::KLSupport&)>& which) {
  KLBoundaryConditions bcs(g);
  for (std::size_t k = 0; k < m.kl_supports.size(); ++k) {
    const model::KLSupport& sup = m.kl_supports[k];
    if (!which(sup)) continue;
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
      compile_fail(sup.source, fmt::format("kl_supports[{}]", k), e.what());
    }
  }
  return bcs;
}

}  // namespace isoflex::system
