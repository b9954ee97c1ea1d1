#include "isoflex/io/kl_shell_reader.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "isoflex/geometry/projection.hpp"

namespace isoflex::io {

namespace {
constexpr int kMaxQuadrature = 12;

double box_diagonal(const geometry::NurbsSurface& s) {
  Vec3 lo = s.points.front(), hi = lo;
  for (const Vec3& x : s.points) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  return (hi - lo).norm();
}
}  // namespace

const model::Surface& kl_surface(const model::Model& m, const model::KLShell& s) {
  const auto it = std::find_if(m.surfaces.begin(), m.surfaces.end(),
                               [&](const model::Surface& f) { return f.name == s.surface; });
  if (it == m.surfaces.end())
    throw std::logic_error("kl shell \"" + s.name + "\": no surface \"" + s.surface + "\"");
  return *it;
}

std::vector<model::KLShell> KLShellReader::shells(
    const YAML::Node& list, const std::vector<model::Surface>& surfaces) const {
  std::vector<model::KLShell> out;
  if (!list || list.IsNull()) return out;
  if (!list.IsSequence()) fail(list, "kl_shells", "expected a list of shells");
  for (std::size_t i = 0; i < list.size(); ++i) {
    out.push_back(shell(list[i], indexed("kl_shells", i), surfaces));
    for (std::size_t k = 0; k + 1 < out.size(); ++k)
      if (out[k].name == out.back().name)
        fail(list[i]["name"], join(indexed("kl_shells", i), "name"),
             fmt::format("duplicate shell name \"{}\"", out.back().name));
  }
  return out;
}

model::KLShell KLShellReader::shell(const YAML::Node& n, const std::string& p,
                                    const std::vector<model::Surface>& surfaces) const {
  expect_map(n, p);
  check_keys(n, p,
             {"name", "surface", "material", "quadrature", "seam", "velocity", "angular_velocity",
              "velocity_point", "node_velocities"});
  model::KLShell s;
  s.source = source(n);
  const YAML::Node name = require(n, p, "name");
  s.name = string(name, join(p, "name"));
  if (s.name.empty() || s.name == "ground" || s.name.find_first_of("[]") != std::string::npos)
    fail(name, join(p, "name"), "must be non-empty, not \"ground\", without '[' or ']'");

  const YAML::Node surf = require(n, p, "surface");
  s.surface = string(surf, join(p, "surface"));
  const auto it = std::find_if(surfaces.begin(), surfaces.end(),
                               [&](const model::Surface& f) { return f.name == s.surface; });
  if (it == surfaces.end())
    fail(surf, join(p, "surface"), "no surface named \"" + s.surface + "\"");
  const geometry::NurbsSurface& g = it->surface;
  if (g.degree_u() < 2 || g.degree_v() < 2)
    fail(surf, join(p, "surface"),
         fmt::format("surface \"{}\" has degrees ({}, {}): a Kirchhoff–Love shell needs degree "
                     "≥ 2 in both directions (C¹ inside the patch, IGA-thesis §4.3); raise it "
                     "with refine: {{elevate: [{}, {}]}}",
                     s.surface, g.degree_u(), g.degree_v(), std::max(0, 2 - g.degree_u()),
                     std::max(0, 2 - g.degree_v())));

  const std::string mp = join(p, "material");
  const YAML::Node m = require(n, p, "material");
  expect_map(m, mp);
  check_keys(m, mp, {"E", "nu", "thickness", "density", "eta"});
  s.E = positive(require(m, mp, "E"), join(mp, "E"));
  s.nu = number(require(m, mp, "nu"), join(mp, "nu"));
  if (!(s.nu > -1.0 && s.nu < 0.5))
    fail(m["nu"], join(mp, "nu"), "Poisson's ratio must lie in (−1, 0.5)");
  s.thickness = positive(require(m, mp, "thickness"), join(mp, "thickness"));
  relative_size(m["thickness"], join(mp, "thickness"), s.thickness, bounding_box_diagonal(g.points),
                fmt::format("the bounding box of the control points of surface \"{}\"", s.surface));
  if (const auto d = m["density"]) s.density = positive(d, join(mp, "density"));
  if (const auto e = m["eta"]) s.eta = damping_factor(e, join(mp, "eta"));

  if (const auto q = n["quadrature"]) {
    const std::string qk = join(p, "quadrature");
    if (!q.IsSequence() || q.size() != 2) fail(q, qk, "expected [points along u, along v]");
    for (int d = 0; d < 2; ++d) {
      s.quadrature[d] = integer(q[d], indexed(qk, d), 1);
      if (s.quadrature[d] > kMaxQuadrature)
        fail(q[d], indexed(qk, d), fmt::format("at most {} points per span", kMaxQuadrature));
    }
  }
  if (const auto seam = n["seam"]) {
    const std::string v = string(seam, join(p, "seam"));
    if (v != "joined" && v != "open")
      fail(seam, join(p, "seam"),
           "unknown seam \"" + v +
               "\" (expected joined: the patch's coincident edges are one interface, or open: "
               "they stay apart, a slit)");
    s.open_seam = v == "open";
  }
  s.initial = node_velocities(n, p, static_cast<int>(g.points.size()),
                              fmt::format("kl_shell \"{}\"", s.name));
  return s;
}

const model::KLShell& KLShellReader::find_shell(const YAML::Node& n, const std::string& key,
                                                const model::Model& m) const {
  const std::string name = string(n, key);
  for (const auto& s : m.kl_shells)
    if (s.name == name) return s;
  fail(n, key, "no kl_shell named \"" + name + "\"");
}

std::string KLShellReader::edge(const YAML::Node& n, const std::string& key) const {
  const std::string e = string(n, key);
  if (e != "u0" && e != "u1" && e != "v0" && e != "v1")
    fail(n, key, "unknown edge \"" + e + "\" (expected u0, u1, v0 or v1)");
  return e;
}

std::array<double, 2> KLShellReader::point_on_surface(const YAML::Node& n, const std::string& key,
                                                      const Vec3& x,
                                                      const model::Surface& s) const {
  const geometry::ProjectionResult r = geometry::project_point(s.surface, x);
  const double tolerance = kOnSurfaceTolerance * box_diagonal(s.surface);
  if (!(r.distance <= tolerance))
    fail(n, key,
         fmt::format("the point ({:.9g}, {:.9g}, {:.9g}) is not on surface \"{}\": its closest "
                     "point ({:.9g}, {:.9g}, {:.9g}) is {:.3g} away (tolerance {:.3g})",
                     x.x(), x.y(), x.z(), s.name, r.point.x(), r.point.y(), r.point.z(), r.distance,
                     tolerance));
  return {r.xi, r.eta};
}

std::vector<model::KLSupport> KLShellReader::supports(const YAML::Node& list,
                                                      const model::Model& m) const {
  std::vector<model::KLSupport> out;
  if (!list || list.IsNull()) return out;
  if (!list.IsSequence()) fail(list, "kl_supports", "expected a list");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const YAML::Node n = list[i];
    const std::string p = indexed("kl_supports", i);
    expect_map(n, p);
    check_keys(n, p,
               {"shell", "edge", "control_points", "fixed", "clamped", "symmetry", "displacement",
                "body"});
    model::KLSupport s;
    s.source = source(n);
    const model::KLShell& shell = find_shell(require(n, p, "shell"), join(p, "shell"), m);
    s.shell = shell.name;
    const int ncp = static_cast<int>(kl_surface(m, shell).surface.points.size());
    if ((n["edge"] ? 1 : 0) + (n["control_points"] ? 1 : 0) != 1)
      fail(n, p, "give exactly one of edge or control_points");
    if (const auto e = n["edge"]) s.edge = edge(e, join(p, "edge"));
    if (const auto b = n["body"]) {
      s.body = string(b, join(p, "body"));
      if (std::none_of(m.bodies.begin(), m.bodies.end(),
                       [&](const model::Body& x) { return x.name == s.body; }))
        fail(b, join(p, "body"), "no body named \"" + s.body + "\"");
    }
    if (const auto c = n["control_points"]) {
      const std::string ck = join(p, "control_points");
      if (!c.IsSequence() || c.size() == 0) fail(c, ck, "expected a list of control-point indices");
      for (std::size_t k = 0; k < c.size(); ++k) {
        const int idx = integer(c[k], indexed(ck, k), 0);
        if (idx >= ncp)
          fail(c[k], indexed(ck, k),
               fmt::format("control point {} out of range: shell \"{}\" has {}", idx, shell.name,
                           ncp));
        s.control_points.push_back(idx);
      }
    }
    const int kinds = (n["fixed"] ? 1 : 0) + (n["clamped"] ? 1 : 0) + (n["symmetry"] ? 1 : 0) +
                      (n["displacement"] ? 1 : 0);
    if (kinds != 1) fail(n, p, "give exactly one of fixed, clamped, symmetry or displacement");
    auto components = [&](const YAML::Node& v, const std::string& key) {
      if (v.IsScalar() && (v.Scalar() == "all" || v.Scalar() == "true")) return;
      if (!v.IsSequence() || v.size() == 0)
        fail(v, key, "expected all or a list of components [x, y, z]");
      s.components = {false, false, false};
      for (std::size_t k = 0; k < v.size(); ++k) {
        const std::string c = string(v[k], indexed(key, k));
        if (c != "x" && c != "y" && c != "z") fail(v[k], indexed(key, k), "expected x, y or z");
        s.components[c[0] - 'x'] = true;
      }
    };
    if (const auto v = n["fixed"]) {
      s.kind = model::KLSupportKind::fixed;
      components(v, join(p, "fixed"));
    } else if (s.edge.empty()) {
      fail(n, p, "clamped, symmetry and displacement act on an edge: give edge");
    } else if (const auto c = n["clamped"]) {
      s.kind = model::KLSupportKind::clamped;
      components(c, join(p, "clamped"));
    } else if (const auto sym = n["symmetry"]) {
      s.kind = model::KLSupportKind::symmetry;
      s.normal = direction(sym, join(p, "symmetry"));
    } else {
      s.kind = model::KLSupportKind::displacement;
      s.displacement = time_functions(n["displacement"], join(p, "displacement"));
    }
    out.push_back(s);
  }
  return out;
}

std::vector<model::KLLoad> KLShellReader::loads(const YAML::Node& list,
                                                const model::Model& m) const {
  std::vector<model::KLLoad> out;
  if (!list || list.IsNull()) return out;
  if (!list.IsSequence()) fail(list, "kl_loads", "expected a list");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const YAML::Node n = list[i];
    const std::string p = indexed("kl_loads", i);
    expect_map(n, p);
    check_keys(n, p,
               {"name", "shell", "area_force", "pressure", "follower", "self_weight", "edge",
                "force_per_length", "moment_per_length", "axis", "point", "force"});
    model::KLLoad l;
    l.source = source(n);
    if (const auto v = n["name"]) l.name = string(v, join(p, "name"));
    const model::KLShell& shell = find_shell(require(n, p, "shell"), join(p, "shell"), m);
    l.shell = shell.name;
    const int kinds = (n["area_force"] ? 1 : 0) + (n["pressure"] ? 1 : 0) +
                      (n["self_weight"] ? 1 : 0) + (n["force_per_length"] ? 1 : 0) +
                      (n["moment_per_length"] ? 1 : 0) + (n["force"] ? 1 : 0);
    if (kinds != 1)
      fail(n, p,
           "give exactly one of area_force, pressure, self_weight, force_per_length or "
           "moment_per_length (with edge) or force (with point)");
    if (n["follower"] && !n["pressure"])
      fail(n["follower"], join(p, "follower"), "only with pressure");
    if (n["edge"] && !n["force_per_length"] && !n["moment_per_length"])
      fail(n["edge"], join(p, "edge"), "only with force_per_length or moment_per_length");
    if (n["axis"] && !n["moment_per_length"])
      fail(n["axis"], join(p, "axis"), "only with moment_per_length");
    if (n["point"] && !n["force"]) fail(n["point"], join(p, "point"), "only with force");
    if (const auto v = n["area_force"]) {
      l.kind = model::KLLoadKind::area_force;
      l.force = time_functions(v, join(p, "area_force"));
    } else if (const auto v = n["pressure"]) {
      l.kind = model::KLLoadKind::pressure;
      l.pressure = time_function(v, join(p, "pressure"));
      if (const auto f = n["follower"]) l.follower = boolean(f, join(p, "follower"));
    } else if (const auto v = n["self_weight"]) {
      l.kind = model::KLLoadKind::self_weight;
      l.factor = time_function(v, join(p, "self_weight"));
      if (!(shell.density > 0))
        fail(v, join(p, "self_weight"),
             "shell \"" + shell.name + "\" has no material.density: self-weight needs it");
      if (m.gravity.norm() == 0)
        fail(v, join(p, "self_weight"), "the model has no gravity: self-weight needs it");
    } else if (const auto v = n["force_per_length"]) {
      l.kind = model::KLLoadKind::edge_force;
      l.edge = edge(require(n, p, "edge"), join(p, "edge"));
      l.force = time_functions(v, join(p, "force_per_length"));
    } else if (const auto v = n["moment_per_length"]) {
      l.kind = model::KLLoadKind::edge_moment;
      l.edge = edge(require(n, p, "edge"), join(p, "edge"));
      l.moment = time_function(v, join(p, "moment_per_length"));
      l.axis = direction(require(n, p, "axis"), join(p, "axis"));
    } else {
      l.kind = model::KLLoadKind::point_force;
      const YAML::Node pt = require(n, p, "point");
      l.point = vec3(pt, join(p, "point"));
      const auto [xi, eta] = point_on_surface(pt, join(p, "point"), l.point, kl_surface(m, shell));
      l.xi = xi;
      l.eta = eta;
      l.force = time_functions(n["force"], join(p, "force"));
    }
    out.push_back(l);
  }
  return out;
}

model::KLCoupling KLShellReader::coupling(const YAML::Node& n, const std::string& key) const {
  const std::string c = string(n, key);
  if (c == "c0") return model::KLCoupling::c0;
  if (c == "bending_strip") return model::KLCoupling::bending_strip;
  if (c == "strip_constraints") return model::KLCoupling::strip_constraints;
  if (c == "perturbed_lagrange") return model::KLCoupling::perturbed_lagrange;
  if (c == "angle") return model::KLCoupling::angle;
  fail(n, key,
       "unknown coupling \"" + c +
           "\" (expected c0, bending_strip, strip_constraints, perturbed_lagrange or angle)");
}

model::KLInterfaces KLShellReader::interfaces(const YAML::Node& n, const model::Model& m) const {
  model::KLInterfaces out;
  if (!n || n.IsNull()) return out;
  const std::string p = "kl_interfaces";
  expect_map(n, p);
  check_keys(n, p, {"coupling", "beta", "tolerance", "pairs"});
  out.source = source(n);
  if (const auto c = n["coupling"]) out.coupling = coupling(c, join(p, "coupling"));
  if (const auto b = n["beta"]) out.beta = positive(b, join(p, "beta"));
  if (const auto t = n["tolerance"]) {
    out.tolerance = positive(t, join(p, "tolerance"));
    if (out.tolerance > 0.01)
      fail(t, join(p, "tolerance"),
           "at most 0.01 (relative to the diagonal of the shells' control-point box)");
  }
  if (const auto list = n["pairs"]) {
    const std::string lp = join(p, "pairs");
    if (!list.IsSequence()) fail(list, lp, "expected a list of {shells: [a, b], coupling, beta}");
    for (std::size_t i = 0; i < list.size(); ++i) {
      const YAML::Node e = list[i];
      const std::string ep = indexed(lp, i);
      expect_map(e, ep);
      check_keys(e, ep, {"shells", "coupling", "beta"});
      model::KLInterfacePair pair{"", "", out.coupling, out.beta, source(e)};
      const YAML::Node sh = require(e, ep, "shells");
      if (!sh.IsSequence() || sh.size() != 2)
        fail(sh, join(ep, "shells"), "expected the names of two kl_shells");
      pair.a = find_shell(sh[0], indexed(join(ep, "shells"), 0), m).name;
      pair.b = find_shell(sh[1], indexed(join(ep, "shells"), 1), m).name;
      if (const auto c = e["coupling"]) pair.coupling = coupling(c, join(ep, "coupling"));
      if (const auto b = e["beta"]) pair.beta = positive(b, join(ep, "beta"));
      out.pairs.push_back(std::move(pair));
    }
  }
  return out;
}

}  // namespace isoflex::io
