#include "isoflex/io/kl_shell_vtk.hpp"

#include <fmt/format.h>

#include <functional>
#include <iterator>
#include <memory>
#include <stdexcept>
#include <vector>

#include "isoflex/io/nurbs_vtk_writer.hpp"
#include "isoflex/io/summary_writer.hpp"
#include "isoflex/io/vtk_writer.hpp"

namespace isoflex::io {

std::string kl_shell_vtu(const elements::KLShellPatch& patch, elements::KLKinematics kin,
                         const VecX& x, int n_per_span, model::VtkFormat format) {
  if (x.size() != patch.dofs()) {
    throw std::invalid_argument(
        fmt::format("KL shell VTU: {} coordinates for a patch of {} control points", x.size(),
                    patch.control_points()));
  }
  geometry::NurbsSurface deformed = patch.reference();
  std::vector<double> u(static_cast<std::size_t>(x.size()));
  const VecX X = patch.reference_positions();
  for (std::size_t k = 0; k < deformed.points.size(); ++k) {
    deformed.points[k] = x.segment<3>(3 * static_cast<int>(k));
    for (int c = 0; c < 3; ++c) u[3 * k + c] = x(3 * static_cast<int>(k) + c) - X(3 * k + c);
  }
  // The writer asks for every field at one point before it moves on: recover once per point.
  struct Cache {
    double xi = -1e300, eta = -1e300;
    elements::KLShellStress s;
  };
  auto cache = std::make_shared<Cache>();
  const geometry::NurbsSurface& ref = patch.reference();
  auto at = [&, cache](double xi, double eta) -> const elements::KLShellStress& {
    if (xi != cache->xi || eta != cache->eta) {
      // At a collapsed edge (a sphere's pole) the tangent plane has no frame: recover just inside
      // the domain, 1e-4 of its width towards the centre (closer, the metric A₁₁ ~ distance² loses
      // the digits), which gives the limit values to about 1e-4.
      const geometry::SurfacePoint g = geometry::evaluate(ref, xi, eta);
      const double size = g.xu.norm() + g.xv.norm();
      double xr = xi, er = eta;
      if (!(g.xu.cross(g.xv).norm() > 1e-10 * size * size)) {
        xr += 1e-4 * (0.5 * (ref.u.front() + ref.u.back()) - xi);
        er += 1e-4 * (0.5 * (ref.v.front() + ref.v.back()) - eta);
      }
      cache->s = patch.stress(x, xr, er, kin);
      cache->xi = xi;
      cache->eta = eta;
    }
    return cache->s;
  };
  using Get = std::function<void(const elements::KLShellStress&, double*)>;
  auto field = [&](const char* name, int nc, Get get) {
    return SampledField{name, nc, {}, [at, get](double xi, double eta, const Vec3&, double* out) {
                          get(at(xi, eta), out);
                        }};
  };
  auto vec3 = [](const Vec3& v, double* out) {
    for (int c = 0; c < 3; ++c) out[c] = v(c);
  };
  std::vector<SampledField> fields;
  fields.push_back({"displacement", 3, u, {}});
  fields.push_back(field("n", 3, [&](const auto& s, double* o) { vec3(s.n, o); }));
  fields.push_back(field("m", 3, [&](const auto& s, double* o) { vec3(s.m, o); }));
  fields.push_back(field("sigma_top", 3, [&](const auto& s, double* o) { vec3(s.sigma_top, o); }));
  fields.push_back(
      field("sigma_bottom", 3, [&](const auto& s, double* o) { vec3(s.sigma_bottom, o); }));
  fields.push_back(field("principal_top", 2, [](const auto& s, double* o) {
    o[0] = s.principal_top(0);
    o[1] = s.principal_top(1);
  }));
  fields.push_back(field("principal_bottom", 2, [](const auto& s, double* o) {
    o[0] = s.principal_bottom(0);
    o[1] = s.principal_bottom(1);
  }));
  fields.push_back(
      field("von_mises_top", 1, [](const auto& s, double* o) { o[0] = s.von_mises_top; }));
  fields.push_back(
      field("von_mises_bottom", 1, [](const auto& s, double* o) { o[0] = s.von_mises_bottom; }));
  fields.push_back(field("e1", 3, [&](const auto& s, double* o) { vec3(s.frame.col(0), o); }));
  return nurbs_tessellated_vtu(deformed, n_per_span, format, fields);
}

}  // namespace isoflex::io
