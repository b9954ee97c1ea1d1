#include "isoflex/io/shell_reader.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "isoflex/geometry/nurbs_surface.hpp"
#include "isoflex/system/memory_estimate.hpp"

namespace isoflex::io {

namespace {
constexpr int kMaxShellElements = 4'000'000;  // per direction of a structured mesh
constexpr double kCoincidence = 1e-9;         // joined edge nodes: distance / mesh size

// Bilinear map of four corners (counter-clockwise) at (s, t) ∈ [0, 1]², with its derivatives.
Vec3 bilinear(const std::array<Vec3, 4>& c, double s, double t, Vec3* xs, Vec3* xt) {
  if (xs) *xs = (1 - t) * (c[1] - c[0]) + t * (c[2] - c[3]);
  if (xt) *xt = (1 - s) * (c[3] - c[0]) + s * (c[2] - c[1]);
  return (1 - s) * (1 - t) * c[0] + s * (1 - t) * c[1] + s * t * c[2] + (1 - s) * t * c[3];
}

// Parameters of n + 1 nodes at equal arc length along the iso-line through the middle of the other
// direction (a rational parametrization, such as the exact circle, is not uniform in length).
std::vector<double> equal_length_parameters(const geometry::NurbsSurface& g, bool along_u, int n) {
  constexpr int kSamples = 2048;
  const geometry::KnotVector& k = along_u ? g.u : g.v;
  const geometry::KnotVector& o = along_u ? g.v : g.u;
  const double mid = 0.5 * (o.front() + o.back());
  std::vector<double> par(kSamples + 1), len(kSamples + 1, 0.0);
  for (int i = 0; i <= kSamples; ++i) {
    par[i] = k.front() + (k.back() - k.front()) * i / kSamples;
    if (i == 0) continue;
    // Midpoint rule for ∫ |x_ξ| dξ over the sample interval.
    const double c = 0.5 * (par[i - 1] + par[i]);
    const geometry::SurfacePoint x =
        along_u ? geometry::evaluate(g, c, mid) : geometry::evaluate(g, mid, c);
    len[i] = len[i - 1] + (along_u ? x.xu : x.xv).norm() * (par[i] - par[i - 1]);
  }
  std::vector<double> out(n + 1);
  for (int j = 0; j <= n; ++j) {
    const double target = len.back() * j / n;
    const auto it = std::lower_bound(len.begin(), len.end(), target);
    const int i = std::clamp(static_cast<int>(it - len.begin()), 1, kSamples);
    const double w = len[i] > len[i - 1] ? (target - len[i - 1]) / (len[i] - len[i - 1]) : 0.0;
    out[j] = par[i - 1] + w * (par[i] - par[i - 1]);
  }
  out.front() = k.front();
  out.back() = k.back();
  return out;
}

void grid_quads(model::Shell& s) {
  const int nu = s.grid_u + 1;
  for (int j = 0; j < s.grid_v; ++j)
    for (int i = 0; i < s.grid_u; ++i)
      s.quads.push_back({i + nu * j, i + 1 + nu * j, i + 1 + nu * (j + 1), i + nu * (j + 1)});
}
}  // namespace

std::vector<model::Shell> ShellReader::shells(const YAML::Node& list,
                                              const std::vector<model::Surface>& surfaces) const {
  std::vector<model::Shell> out;
  if (!list || list.IsNull()) return out;
  if (!list.IsSequence()) fail(list, "shells", "expected a list of shells");
  for (std::size_t i = 0; i < list.size(); ++i) {
    out.push_back(shell(list[i], indexed("shells", i), surfaces));
    for (std::size_t k = 0; k + 1 < out.size(); ++k)
      if (out[k].name == out.back().name)
        fail(list[i]["name"], join(indexed("shells", i), "name"),
             fmt::format("duplicate shell name \"{}\"", out.back().name));
  }
  return out;
}

model::Shell ShellReader::shell(const YAML::Node& n, const std::string& p,
                                const std::vector<model::Surface>& surfaces) const {
  expect_map(n, p);
  check_keys(n, p,
             {"name", "material", "plate", "surface", "elements", "mesh", "velocity",
              "angular_velocity", "velocity_point", "node_velocities"});
  model::Shell s;
  const YAML::Node name = require(n, p, "name");
  s.name = string(name, join(p, "name"));
  if (s.name.empty() || s.name == "ground" || s.name.find_first_of("[]") != std::string::npos)
    fail(name, join(p, "name"), "must be non-empty, not \"ground\", without '[' or ']'");
  s.source = source(n);

  const std::string mp = join(p, "material");
  const YAML::Node m = require(n, p, "material");
  expect_map(m, mp);
  check_keys(m, mp, {"E", "nu", "thickness", "density", "shear_correction", "eta"});
  s.material.E = positive(require(m, mp, "E"), join(mp, "E"));
  s.material.nu = number(require(m, mp, "nu"), join(mp, "nu"));
  if (!(s.material.nu > -1.0 && s.material.nu < 0.5))
    fail(m["nu"], join(mp, "nu"), "Poisson's ratio must lie in (−1, 0.5)");
  s.material.thickness = positive(require(m, mp, "thickness"), join(mp, "thickness"));
  s.material.density = positive(require(m, mp, "density"), join(mp, "density"));
  if (const auto k = m["shear_correction"])
    s.material.shear_correction = positive(k, join(mp, "shear_correction"));
  if (const auto e = m["eta"]) s.material.eta = damping_factor(e, join(mp, "eta"));

  const int sources = (n["plate"] ? 1 : 0) + (n["surface"] ? 1 : 0) + (n["mesh"] ? 1 : 0);
  if (sources != 1) fail(n, p, "give exactly one of plate, surface or mesh");
  auto grid = [&](const YAML::Node& e, const std::string& key) {
    if (!e.IsSequence() || e.size() != 2) fail(e, key, "expected [elements along u, along v]");
    s.grid_u = integer(e[0], indexed(key, 0), 1);
    s.grid_v = integer(e[1], indexed(key, 1), 1);
    if (s.grid_u > kMaxShellElements || s.grid_v > kMaxShellElements)
      fail(e, key, fmt::format("at most {} elements per direction", kMaxShellElements));
    // Before the mesh is built here (issue #15: 10⁴ × 10⁴ elements ended in std::bad_alloc).
    if (memory_limit_ > 0) {
      const system::MemoryPart part = system::director_shell_grid(s.grid_u, s.grid_v);
      if (part.bytes() > memory_limit_)
        fail(e, key,
             fmt::format("this shell needs about {} ({}: sparse LU {}, sparse matrices {}), {} "
                         "(--max-memory to change)",
                         system::format_bytes(part.bytes()), part.detail,
                         system::format_bytes(part.factor_bytes),
                         system::format_bytes(part.matrix_bytes), memory_limit_text_));
    }
  };

  if (const auto plate = n["plate"]) {
    // A flat or warped quadrilateral from its corners, u along corner 0 → 1, v along 0 → 3.
    const std::string pp = join(p, "plate");
    expect_map(plate, pp);
    check_keys(plate, pp, {"corners", "elements"});
    const YAML::Node c = require(plate, pp, "corners");
    if (!c.IsSequence() || c.size() != 4)
      fail(c, join(pp, "corners"), "expected four corner points, counter-clockwise");
    std::array<Vec3, 4> corner;
    for (int k = 0; k < 4; ++k) corner[k] = vec3(c[k], indexed(join(pp, "corners"), k));
    grid(require(plate, pp, "elements"), join(pp, "elements"));
    for (int j = 0; j <= s.grid_v; ++j)
      for (int i = 0; i <= s.grid_u; ++i) {
        Vec3 xs, xt;
        const double u = double(i) / s.grid_u, v = double(j) / s.grid_v;
        s.points.push_back(bilinear(corner, u, v, &xs, &xt));
        const Vec3 normal = xs.cross(xt);
        if (!(normal.norm() > 1e-12 * xs.norm() * xt.norm()))
          fail(c, join(pp, "corners"), "the corners do not span a quadrilateral");
        s.directors.push_back(normal.normalized());
      }
    grid_quads(s);
  } else if (const auto surf = n["surface"]) {
    // A structured mesh on a NURBS surface of `surfaces`: nodes equally spaced in length along
    // the middle iso-lines, directors along the exact normal x_ξ × x_η.
    const std::string key = join(p, "surface");
    const std::string want = string(surf, key);
    const auto it = std::find_if(surfaces.begin(), surfaces.end(),
                                 [&](const model::Surface& f) { return f.name == want; });
    if (it == surfaces.end()) fail(surf, key, "no surface named \"" + want + "\"");
    grid(require(n, p, "elements"), join(p, "elements"));
    const geometry::NurbsSurface& g = it->surface;
    const std::vector<double> us = equal_length_parameters(g, true, s.grid_u);
    const std::vector<double> vs = equal_length_parameters(g, false, s.grid_v);
    for (int j = 0; j <= s.grid_v; ++j)
      for (int i = 0; i <= s.grid_u; ++i) {
        const double xi = us[i], eta = vs[j];
        const geometry::SurfacePoint x = geometry::evaluate(g, xi, eta);
        s.points.push_back(x.x);
        const Vec3 normal = x.xu.cross(x.xv);
        if (!(normal.norm() > 1e-12 * x.xu.norm() * x.xv.norm()))
          fail(surf, key,
               fmt::format("the surface is degenerate at (ξ, η) = ({:.6g}, {:.6g}) (no normal); "
                           "a shell node there has no director",
                           xi, eta));
        s.directors.push_back(normal.normalized());
      }
    grid_quads(s);
  } else {
    const YAML::Node mesh = n["mesh"];
    const std::string mp2 = join(p, "mesh");
    expect_map(mesh, mp2);
    check_keys(mesh, mp2, {"points", "quads", "directors"});
    if (n["elements"]) fail(n["elements"], join(p, "elements"), "not used with mesh");
    const YAML::Node pts = require(mesh, mp2, "points");
    if (!pts.IsSequence() || pts.size() < 4) fail(pts, join(mp2, "points"), "expected ≥ 4 points");
    for (std::size_t k = 0; k < pts.size(); ++k)
      s.points.push_back(vec3(pts[k], indexed(join(mp2, "points"), k)));
    const YAML::Node quads = require(mesh, mp2, "quads");
    if (!quads.IsSequence() || quads.size() == 0)
      fail(quads, join(mp2, "quads"), "expected a list of quadrilaterals [a, b, c, d]");
    std::vector<Vec3> sum(s.points.size(), Vec3::Zero());
    for (std::size_t e = 0; e < quads.size(); ++e) {
      const std::string qk = indexed(join(mp2, "quads"), e);
      const YAML::Node q = quads[e];
      if (!q.IsSequence() || q.size() != 4) fail(q, qk, "expected four node indices");
      std::array<int, 4> a;
      for (int k = 0; k < 4; ++k) {
        a[k] = integer(q[k], indexed(qk, k), 0);
        if (a[k] >= s.node_count())
          fail(q[k], indexed(qk, k),
               fmt::format("node index {} out of range (0 … {})", a[k], s.node_count() - 1));
      }
      s.quads.push_back(a);
      const Vec3 normal = (s.points[a[2]] - s.points[a[0]]).cross(s.points[a[3]] - s.points[a[1]]);
      if (!(normal.norm() > 0)) fail(q, qk, "degenerate quadrilateral");
      for (int k : a) sum[k] += normal.normalized();
    }
    if (const auto d = mesh["directors"]) {
      if (!d.IsSequence() || d.size() != s.points.size())
        fail(d, join(mp2, "directors"), "expected one director per point");
      for (std::size_t k = 0; k < d.size(); ++k)
        s.directors.push_back(direction(d[k], indexed(join(mp2, "directors"), k)));
    } else {
      for (std::size_t k = 0; k < sum.size(); ++k) {
        if (!(sum[k].norm() > 0))
          fail(pts[k], indexed(join(mp2, "points"), k),
               "belongs to no quadrilateral (or its normals cancel): give directors");
        s.directors.push_back(sum[k].normalized());
      }
    }
  }
  if (n["elements"] && !n["surface"] && !n["mesh"])
    fail(n["elements"], join(p, "elements"), "only used with surface (a plate has its own)");
  relative_size(m["thickness"], join(mp, "thickness"), s.material.thickness,
                bounding_box_diagonal(s.points), "the bounding box of the shell's nodes");
  s.initial = node_velocities(n, p, s.node_count(), fmt::format("shell \"{}\"", s.name));
  return s;
}

const model::Shell& ShellReader::find_shell(const YAML::Node& n, const std::string& key,
                                            const std::vector<model::Shell>& shells) const {
  const std::string name = string(n, key);
  for (const auto& s : shells)
    if (s.name == name) return s;
  fail(n, key, "no shell named \"" + name + "\"");
}

std::vector<int> ShellReader::edge_nodes(const YAML::Node& n, const std::string& key,
                                         const model::Shell& s) const {
  const std::string e = string(n, key);
  if (s.grid_u == 0)
    fail(n, key, fmt::format("shell \"{}\" is an explicit mesh: name its nodes", s.name));
  const std::vector<int> nodes = s.edge(e);
  if (nodes.empty()) fail(n, key, "unknown edge \"" + e + "\" (expected u0, u1, v0 or v1)");
  return nodes;
}

std::vector<int> ShellReader::selected_nodes(const YAML::Node& n, const std::string& p,
                                             const model::Shell& s) const {
  const YAML::Node edge = n["edge"], nodes = n["nodes"];
  if ((edge ? 1 : 0) + (nodes ? 1 : 0) != 1) fail(n, p, "give exactly one of edge or nodes");
  if (edge) return edge_nodes(edge, join(p, "edge"), s);
  if (!nodes.IsSequence() || nodes.size() == 0)
    fail(nodes, join(p, "nodes"), "expected a list of node indices");
  std::vector<int> out;
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    const int i = integer(nodes[k], indexed(join(p, "nodes"), k), 0);
    if (i >= s.node_count())
      fail(nodes[k], indexed(join(p, "nodes"), k),
           fmt::format("node index {} out of range: shell \"{}\" has {} nodes", i, s.name,
                       s.node_count()));
    out.push_back(i);
  }
  return out;
}

std::vector<model::ShellSupport> ShellReader::supports(
    const YAML::Node& list, const std::vector<model::Shell>& shells) const {
  std::vector<model::ShellSupport> out;
  if (!list || list.IsNull()) return out;
  if (!list.IsSequence()) fail(list, "shell_supports", "expected a list");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const YAML::Node n = list[i];
    const std::string p = indexed("shell_supports", i);
    expect_map(n, p);
    check_keys(n, p, {"shell", "edge", "nodes", "translation", "director"});
    model::ShellSupport s;
    const model::Shell& shell = find_shell(require(n, p, "shell"), join(p, "shell"), shells);
    s.shell = shell.name;
    s.nodes = selected_nodes(n, p, shell);
    s.source = source(n);
    if (const auto t = n["translation"]) {
      const std::string tk = join(p, "translation");
      if (t.IsScalar() && t.Scalar() == "all") {
        s.fixed_translation = {true, true, true};
      } else {
        if (!t.IsSequence()) fail(t, tk, "expected all or a list of fixed components [x, y, z]");
        for (std::size_t k = 0; k < t.size(); ++k) {
          const std::string c = string(t[k], indexed(tk, k));
          if (c != "x" && c != "y" && c != "z") fail(t[k], indexed(tk, k), "expected x, y or z");
          s.fixed_translation[c[0] - 'x'] = true;
        }
      }
    }
    if (const auto d = n["director"]) {
      const std::string dk = join(p, "director");
      if (d.IsScalar() && d.Scalar() == "free") {
        s.director = model::DirectorSupport::free;
      } else if (d.IsScalar() && d.Scalar() == "fixed") {
        s.director = model::DirectorSupport::fixed;
      } else if (d.IsSequence()) {
        s.director = model::DirectorSupport::about_axis;
        s.axis = direction(d, dk);
        for (int k : s.nodes)
          if (std::abs(shell.directors[k].dot(s.axis)) > 1e-6)
            fail(d, dk,
                 fmt::format("node {} of shell \"{}\": its director is not perpendicular to the "
                             "symmetry normal (cosine {:.3g})",
                             k, shell.name, shell.directors[k].dot(s.axis)));
      } else {
        fail(d, dk, "expected free, fixed or a symmetry-plane normal [nx, ny, nz]");
      }
    }
    if (s.fixed_translation == std::array<bool, 3>{false, false, false} &&
        s.director == model::DirectorSupport::free)
      fail(n, p, "fixes nothing: give translation and/or director");
    out.push_back(s);
  }
  return out;
}

std::vector<model::Joint> ShellReader::connections(
    const YAML::Node& list, const std::vector<model::Shell>& shells,
    const std::function<bool(const std::string&)>& is_body) const {
  std::vector<model::Joint> out;
  if (!list || list.IsNull()) return out;
  if (!list.IsSequence()) fail(list, "shell_connections", "expected a list");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const YAML::Node n = list[i];
    const std::string p = indexed("shell_connections", i);
    expect_map(n, p);
    check_keys(n, p, {"shell", "edge", "nodes", "attach_to", "join"});
    const model::Shell& a = find_shell(require(n, p, "shell"), join(p, "shell"), shells);
    const std::vector<int> na = selected_nodes(n, p, a);
    if ((n["attach_to"] ? 1 : 0) + (n["join"] ? 1 : 0) != 1)
      fail(n, p, "give exactly one of attach_to (a body) or join (an edge of another shell)");
    if (const auto b = n["attach_to"]) {
      const std::string body = string(b, join(p, "attach_to"));
      if (!is_body(body))
        fail(b, join(p, "attach_to"), "no body or beam node named \"" + body + "\"");
      for (int k : na) {
        model::Joint j;
        j.name = fmt::format("{}[{}]-{}", a.name, k, body);
        j.type = model::JointType::rigid;
        j.body_a = body;
        j.body_b = fmt::format("{}[{}]", a.name, k);
        j.source = source(n);
        out.push_back(j);
      }
      continue;
    }
    const YAML::Node jn = n["join"];
    const std::string jp = join(p, "join");
    expect_map(jn, jp);
    check_keys(jn, jp, {"shell", "edge", "nodes"});
    const model::Shell& b = find_shell(require(jn, jp, "shell"), join(jp, "shell"), shells);
    const std::vector<int> nb = selected_nodes(jn, jp, b);
    if (nb.size() != na.size())
      fail(jn, jp,
           fmt::format("{} nodes to join with {}: the edges need the same number of nodes",
                       nb.size(), na.size()));
    double size = 0;
    for (const auto& x : a.points) size = std::max(size, (x - a.points.front()).norm());
    for (std::size_t k = 0; k < na.size(); ++k) {
      const double gap = (a.points[na[k]] - b.points[nb[k]]).norm();
      if (gap > kCoincidence * std::max(1.0, size))
        fail(jn, jp,
             fmt::format("node {} of \"{}\" and node {} of \"{}\" do not coincide at t = 0 "
                         "(distance {:.3g})",
                         na[k], a.name, nb[k], b.name, gap));
      model::Joint j;
      j.name = fmt::format("{}[{}]-{}[{}]", a.name, na[k], b.name, nb[k]);
      j.type = model::JointType::rigid;
      j.body_a = fmt::format("{}[{}]", a.name, na[k]);
      j.body_b = fmt::format("{}[{}]", b.name, nb[k]);
      j.source = source(n);
      out.push_back(j);
    }
  }
  return out;
}

std::vector<model::ShellLoad> ShellReader::loads(const YAML::Node& list,
                                                 const std::vector<model::Shell>& shells) const {
  std::vector<model::ShellLoad> out;
  if (!list || list.IsNull()) return out;
  if (!list.IsSequence()) fail(list, "shell_loads", "expected a list");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const YAML::Node n = list[i];
    const std::string p = indexed("shell_loads", i);
    expect_map(n, p);
    check_keys(n, p,
               {"name", "shell", "edge", "nodes", "force", "moment", "force_per_length",
                "moment_per_length", "pressure", "area_force"});
    model::ShellLoad l;
    if (const auto v = n["name"]) l.name = string(v, join(p, "name"));
    const model::Shell& s = find_shell(require(n, p, "shell"), join(p, "shell"), shells);
    l.shell = s.name;
    l.source = source(n);
    const bool nodal = n["force"] || n["moment"];
    const bool line = n["force_per_length"] || n["moment_per_length"];
    const bool area = n["pressure"] || n["area_force"];
    if ((nodal ? 1 : 0) + (line ? 1 : 0) + (area ? 1 : 0) != 1)
      fail(n, p,
           "give nodal loads (force, moment), edge loads (force_per_length, moment_per_length) "
           "or area loads (pressure, area_force), one kind per entry");
    if (nodal) {
      l.nodes = selected_nodes(n, p, s);
      if (const auto v = n["force"]) l.force = time_functions(v, join(p, "force"));
      if (const auto v = n["moment"]) l.moment = time_functions(v, join(p, "moment"));
    } else if (line) {
      if (!n["edge"]) fail(n, p, "loads per length act along an edge: give edge");
      l.nodes = selected_nodes(n, p, s);
      l.per_length = true;
      if (const auto v = n["force_per_length"])
        l.force = time_functions(v, join(p, "force_per_length"));
      if (const auto v = n["moment_per_length"])
        l.moment = time_functions(v, join(p, "moment_per_length"));
    } else {
      if (n["edge"] || n["nodes"])
        fail(n, p, "area loads act on the whole shell: no edge or nodes");
      if (const auto v = n["pressure"]) l.pressure = time_function(v, join(p, "pressure"));
      if (const auto v = n["area_force"]) l.area_force = time_functions(v, join(p, "area_force"));
    }
    out.push_back(l);
  }
  return out;
}

}  // namespace isoflex::io
