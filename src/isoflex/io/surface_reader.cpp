#include "isoflex/io/surface_reader.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <array>
#include <cmath>
#include <exception>
#include <filesystem>
#include <initializer_list>
#include <map>
#include <numbers>
#include <stdexcept>
#include <string_view>
#include <utility>

#include "isoflex/geometry/builders.hpp"
#include "isoflex/geometry/clamping.hpp"
#include "isoflex/geometry/refinement.hpp"
#include "isoflex/io/cad/cad_checks.hpp"
#include "isoflex/io/cad/cad_reader.hpp"
#include "isoflex/io/yaml_fields.hpp"

namespace isoflex::io {

namespace {

namespace fs = std::filesystem;

// Control points of one surface after refinement; keeps a mistyped refinement from exhausting
// the memory (a million points are three million unknowns of a shell).
constexpr double kMaxSurfacePoints = 1e6;
constexpr std::initializer_list<const char*> kBuiltinTypes = {
    "rectangle",     "cylinder_sector", "cylinder",   "annulus",
    "sphere_sector", "spherical_cap",   "hemisphere", "disc"};

double radians(double degrees) {
  return degrees / 180.0 * std::numbers::pi;  // exact for 90, 180, 360 (÷180 first)
}

const char* direction_name(std::size_t d) {
  return d == 0 ? "u" : "v";
}

// The same checks and messages as the model reader (YamlFields).
class SurfaceReader : YamlFields {
 public:
  explicit SurfaceReader(std::string file)
      : YamlFields(std::move(file)), base_dir_(fs::path(this->file()).parent_path()) {}

  std::vector<model::Surface> read(const YAML::Node& list) {
    std::vector<model::Surface> out;
    if (!list || list.IsNull()) return out;
    if (!list.IsSequence()) fail(list, "surfaces", "expected a list");
    for (std::size_t i = 0; i < list.size(); ++i)
      out.push_back(read_surface(list[i], indexed("surfaces", i)));
    return out;
  }

 private:
  // A list of two integers ≥ 0, [u, v].
  std::array<int, 2> pair_uv(const YAML::Node& n, const std::string& key) const {
    if (!n.IsSequence() || n.size() != 2) fail(n, key, "expected a list of 2 integers [u, v]");
    return {integer(n[0], indexed(key, 0), 0), integer(n[1], indexed(key, 1), 0)};
  }

  // ---- entries ------------------------------------------------------------------------------

  model::Surface read_surface(const YAML::Node& n, const std::string& p) {
    expect_map(n, p);
    check_keys(n, p, {"name", "cad", "builtin", "refine", "placement"});
    model::Surface s;
    s.source = source(n);

    const YAML::Node name = require(n, p, "name");
    s.name = string(name, join(p, "name"));
    if (s.name.empty()) fail(name, join(p, "name"), "must not be empty");
    if (const auto [pos, inserted] = name_lines_.emplace(s.name, line_of(name)); !inserted)
      fail(name, join(p, "name"),
           fmt::format("duplicate surface name \"{}\" (first at line {})", s.name, pos->second));

    const YAML::Node cad = n["cad"];
    const YAML::Node builtin = n["builtin"];
    if (cad && builtin) fail(builtin, join(p, "builtin"), "give either cad or builtin, not both");
    if (!cad && !builtin) fail(n, p, "one of cad and builtin is required");
    CadPatch patch;  // the surface with what the file says about its face (defaults: builtin)
    std::vector<model::SurfaceFinding> clamping_notes;
    if (cad) {
      s.kind = model::SurfaceSourceKind::cad;
      patch = read_cad_source(cad, join(p, "cad"), s);
      clamping_notes = clamp(cad, join(p, "cad"), patch.surface);  // before refine (elevation)
    } else {
      s.kind = model::SurfaceSourceKind::builtin;
      patch.surface = read_builtin(builtin, join(p, "builtin"), s);
    }

    if (const auto v = n["refine"]) patch.surface = refine(v, join(p, "refine"), patch.surface, s);
    if (const auto v = n["placement"]) place(v, join(p, "placement"), patch.surface, s);

    for (const Finding& f : check_patch(patch)) {  // on the final geometry
      if (f.severity == Severity::error)
        fail(n, p, fmt::format("the surface cannot be used: {} (fix: {})", f.issue, f.fix));
      s.findings.push_back({to_string(f.severity), f.issue, f.fix});
    }
    s.findings.insert(s.findings.end(), clamping_notes.begin(), clamping_notes.end());
    s.surface = std::move(patch.surface);
    return s;
  }

  // `cad: {file: PATH, patch: N or "name"}`.
  CadPatch read_cad_source(const YAML::Node& n, const std::string& p, model::Surface& s) {
    expect_map(n, p);
    check_keys(n, p, {"file", "patch"});
    const YAML::Node file = require(n, p, "file");
    const std::string file_key = join(p, "file");
    s.cad_file = string(file, file_key);
    if (s.cad_file.empty()) fail(file, file_key, "must not be empty");
    const fs::path written(s.cad_file);
    const fs::path path = written.is_absolute() ? written : base_dir_ / written;
    s.cad_path = path.string();

    auto cached = cad_models_.find(s.cad_path);
    if (cached == cad_models_.end()) {
      try {
        cached = cad_models_.emplace(s.cad_path, read_cad(path)).first;
      } catch (const CadError& e) {
        fail(file, file_key,
             fmt::format("cannot read CAD file \"{}\": {}", s.cad_path, e.message()));
      } catch (const std::exception& e) {
        fail(file, file_key, fmt::format("cannot read CAD file \"{}\": {}", s.cad_path, e.what()));
      }
    }
    const std::vector<CadPatch>& patches = cached->second.patches;
    const int count = static_cast<int>(patches.size());
    const std::string patch_key = join(p, "patch");
    const std::string holds = fmt::format("\"{}\" holds {} patch{} (0 … {})", s.cad_file, count,
                                          count == 1 ? "" : "es", count - 1);

    int index = 0;
    const YAML::Node patch = n["patch"];
    if (!patch) {
      if (count != 1)
        fail(n, patch_key,
             fmt::format("missing required key: {}; name one by index or name", holds));
    } else {
      if (!patch.IsScalar()) fail(patch, patch_key, "expected a patch index or a patch name");
      long long k = 0;
      double x = 0.0;
      // A plain (unquoted) integer is an index; anything else, or a quoted value, is a name.
      const bool plain = patch.Tag() == "?";
      if (plain && YAML::convert<long long>::decode(patch, k)) {
        if (k < 0) fail(patch, patch_key, fmt::format("must be >= 0, got {}", k));
        if (k >= count) fail(patch, patch_key, fmt::format("patch {} out of range: {}", k, holds));
        index = static_cast<int>(k);
      } else if (plain && YAML::convert<double>::decode(patch, x)) {
        fail(patch, patch_key,
             "expected a patch index (an integer >= 0) or a patch name (quote a name that looks "
             "like a number)");
      } else {
        const std::string& wanted = patch.Scalar();
        std::vector<int> found;
        for (const CadPatch& c : patches)
          if (c.name == wanted) found.push_back(c.index);
        if (found.empty()) {
          std::string names;
          for (const CadPatch& c : patches)
            names += fmt::format("{}{} \"{}\"", names.empty() ? "" : ", ", c.index, c.name);
          fail(patch, patch_key,
               fmt::format("no patch named \"{}\" in \"{}\" (its patches: {})", wanted, s.cad_file,
                           names));
        }
        if (found.size() > 1)
          fail(patch, patch_key,
               fmt::format("{} patches are named \"{}\" in \"{}\" (indices {}): give the index",
                           found.size(), wanted, s.cad_file, fmt::join(found, ", ")));
        index = found.front();
      }
    }

    const CadPatch& c = patches[static_cast<std::size_t>(index)];
    s.cad_patch = c.index;
    s.cad_patch_name = c.name;
    s.trimmed = c.trimmed;
    s.reversed_orientation = c.reversed_orientation;
    // Errors (a split patch, non-positive weights) before refinement, which cannot handle them.
    for (const Finding& f : check_patch(c))
      if (f.severity == Severity::error)
        fail(patch ? patch : n, patch ? patch_key : p,
             fmt::format("patch {} \"{}\" of \"{}\" cannot be used: {} (fix: {})", c.index, c.name,
                         s.cad_file, f.issue, f.fix));
    return c;
  }

  // A CAD patch whose knot vector is not open in a direction (an unclamped or periodic B-spline:
  // OCCT writes a periodic surface to STEP and IGES with the knots of its periodic extension) is
  // clamped there (geometry/clamping.hpp): the same surface and parametrization on the same
  // domain, with the end knots p+1-fold, as supports on control points, patch coupling and degree
  // elevation need. Returns an info finding per clamped direction.
  std::vector<model::SurfaceFinding> clamp(const YAML::Node& n, const std::string& p,
                                           geometry::NurbsSurface& surface) const {
    std::vector<model::SurfaceFinding> notes;
    for (std::size_t d = 0; d < 2; ++d) {
      const geometry::KnotVector& kv = d == 0 ? surface.u : surface.v;
      if (kv.is_open()) continue;
      const int before = kv.n_basis();
      const int degree = kv.degree();
      const double a = kv.front(), b = kv.back();
      try {
        surface =
            geometry::clamped(surface, d == 0 ? geometry::Direction::u : geometry::Direction::v);
      } catch (const std::invalid_argument& e) {
        fail(n, p,
             fmt::format("cannot clamp the knot vector in {}: {}", direction_name(d), e.what()));
      }
      const int after = (d == 0 ? surface.u : surface.v).n_basis();
      notes.push_back(
          {"info",
           fmt::format("the knot vector in {0} is not open in the file (end knots not repeated {1} "
                       "times: an unclamped or periodic B-spline); clamped on its domain [{2:g}, "
                       "{3:g}] by knot insertion, the same surface and parametrization: {4} → {5} "
                       "control points in {0}",
                       direction_name(d), degree + 1, a, b, before, after),
           "nothing to do"});
    }
    return notes;
  }

  // `builtin: {type: ..., parameters}`; angles in degrees.
  geometry::NurbsSurface read_builtin(const YAML::Node& n, const std::string& p,
                                      model::Surface& s) {
    expect_map(n, p);
    const YAML::Node type = require(n, p, "type");
    s.builtin_type = string(type, join(p, "type"));
    const std::string& t = s.builtin_type;
    auto radius = [&] { return positive(require(n, p, "radius"), join(p, "radius")); };
    try {
      if (t == "rectangle") {
        check_keys(n, p, {"type", "size", "corner", "edge_u", "edge_v"});
        const Vec3 corner = n["corner"] ? vec3(n["corner"], join(p, "corner")) : Vec3::Zero();
        if (const auto size = n["size"]) {
          for (const char* k : {"edge_u", "edge_v"})
            if (n[k]) fail(n[k], join(p, k), "give either size or edge_u and edge_v, not both");
          const std::string key = join(p, "size");
          if (!size.IsSequence() || size.size() != 2)
            fail(size, key, "expected a list of 2 numbers [lx, ly]");
          const double lx = positive(size[0], indexed(key, 0));
          const double ly = positive(size[1], indexed(key, 1));
          return geometry::planar_rectangle(corner, Vec3(lx, 0, 0), Vec3(0, ly, 0));
        }
        if (!n["edge_u"] && !n["edge_v"])
          fail(n, join(p, "size"), "missing required key (or give edge_u and edge_v)");
        const Vec3 eu = vec3(require(n, p, "edge_u"), join(p, "edge_u"));
        const YAML::Node ev_node = require(n, p, "edge_v");
        const Vec3 ev = vec3(ev_node, join(p, "edge_v"));
        if (!(eu.cross(ev).norm() > 1e-14 * eu.norm() * ev.norm()) || !(eu.cross(ev).norm() > 0))
          fail(ev_node, join(p, "edge_v"), "must be nonzero and not parallel to edge_u");
        return geometry::planar_rectangle(corner, eu, ev);
      }
      if (t == "cylinder_sector") {
        check_keys(n, p, {"type", "radius", "length", "angle"});
        const double r = radius();
        const double length = positive(require(n, p, "length"), join(p, "length"));
        return geometry::cylinder_sector(r, length, radians(full_turn_angle(n, p, true)));
      }
      if (t == "cylinder") {
        check_keys(n, p, {"type", "radius", "length"});
        const double r = radius();
        return geometry::cylinder(r, positive(require(n, p, "length"), join(p, "length")));
      }
      if (t == "annulus") {
        check_keys(n, p, {"type", "inner_radius", "outer_radius", "angle"});
        const double inner = positive(require(n, p, "inner_radius"), join(p, "inner_radius"));
        const YAML::Node outer_node = require(n, p, "outer_radius");
        const double outer = positive(outer_node, join(p, "outer_radius"));
        if (!(outer > inner))
          fail(outer_node, join(p, "outer_radius"),
               fmt::format("must be > inner_radius = {}, got {}", inner, outer));
        return geometry::annulus(inner, outer, radians(full_turn_angle(n, p, false)));
      }
      if (t == "sphere_sector") {
        check_keys(n, p, {"type", "radius", "azimuth", "lat_from", "lat_to"});
        const double r = radius();
        const YAML::Node azimuth = require(n, p, "azimuth");
        const double az = number(azimuth, join(p, "azimuth"));
        if (!(az > 0.0 && az <= 360.0))
          fail(azimuth, join(p, "azimuth"), fmt::format("must be in (0, 360] degrees, got {}", az));
        const YAML::Node from = require(n, p, "lat_from");
        const double lat_from = number(from, join(p, "lat_from"));
        if (!(lat_from >= -90.0 && lat_from < 90.0))
          fail(from, join(p, "lat_from"),
               fmt::format("must be in [-90, 90) degrees, got {}", lat_from));
        const YAML::Node to = require(n, p, "lat_to");
        const double lat_to = number(to, join(p, "lat_to"));
        if (!(lat_to > lat_from && lat_to <= 90.0))
          fail(to, join(p, "lat_to"),
               fmt::format("must be in (lat_from, 90] = ({}, 90] degrees, got {}", lat_from,
                           lat_to));
        return geometry::sphere_sector(r, radians(az), radians(lat_from), radians(lat_to));
      }
      if (t == "spherical_cap") {
        check_keys(n, p, {"type", "radius", "angle"});
        const double r = radius();
        const YAML::Node angle = require(n, p, "angle");
        const double a = number(angle, join(p, "angle"));
        if (!(a > 0.0 && a < 180.0))
          fail(angle, join(p, "angle"),
               fmt::format("must be in (0, 180) degrees (the polar angle of the rim), got {}", a));
        return geometry::spherical_cap(r, radians(a));
      }
      if (t == "hemisphere") {
        check_keys(n, p, {"type", "radius"});
        return geometry::hemisphere(radius());
      }
      if (t == "disc") {
        check_keys(n, p, {"type", "radius"});
        return geometry::disc(radius());
      }
    } catch (const std::invalid_argument& e) {  // ranges are checked above; kept as a backstop
      fail(n, p, e.what());
    }
    fail(type, join(p, "type"),
         "unknown builtin type \"" + t + "\" (valid: " + list_names(kBuiltinTypes) + ")");
  }

  // The key `angle` of an arc in degrees, in (0, 360]; required, or 360 when left out.
  double full_turn_angle(const YAML::Node& n, const std::string& p, bool required) const {
    const YAML::Node angle = required ? require(n, p, "angle") : n["angle"];
    if (!angle) return 360.0;
    const double a = number(angle, join(p, "angle"));
    if (!(a > 0.0 && a <= 360.0))
      fail(angle, join(p, "angle"), fmt::format("must be in (0, 360] degrees, got {}", a));
    return a;
  }

  // `refine: {elevate: [tu, tv], knots_per_span: [ku, kv]}`: elevation first, then insertion.
  geometry::NurbsSurface refine(const YAML::Node& n, const std::string& p,
                                const geometry::NurbsSurface& in, model::Surface& s) {
    expect_map(n, p);
    check_keys(n, p, {"elevate", "knots_per_span"});
    const YAML::Node elevate = n["elevate"];
    const YAML::Node knots = n["knots_per_span"];
    const std::string elevate_key = join(p, "elevate");
    const std::string knots_key = join(p, "knots_per_span");
    if (elevate) s.refine.elevate = pair_uv(elevate, elevate_key);
    if (knots) s.refine.knots_per_span = pair_uv(knots, knots_key);

    const geometry::KnotVector* kv[2] = {&in.u, &in.v};
    double size[2] = {0, 0};
    for (std::size_t d = 0; d < 2; ++d) {
      const int deg = kv[d]->degree(), t = s.refine.elevate[d];
      if (t > 0) {
        if (t > geometry::kMaxDegree - deg)
          fail(elevate[d], indexed(elevate_key, d),
               fmt::format("degree {} + {} in {} is above the maximum degree {}", deg, t,
                           direction_name(d), geometry::kMaxDegree));
        if (!kv[d]->is_open())
          fail(elevate[d], indexed(elevate_key, d),
               fmt::format("cannot elevate the degree in {}: its knot vector is not open (end "
                           "knots not repeated {} times); re-export the surface clamped",
                           direction_name(d), deg + 1));
      }
      // Elevation adds t to the multiplicity of every distinct knot of the domain.
      const double distinct = static_cast<double>(kv[d]->breakpoints().size());
      const double spans = static_cast<double>(kv[d]->element_spans().size());
      size[d] = kv[d]->n_basis() + static_cast<double>(t) * (distinct - 1) +
                static_cast<double>(s.refine.knots_per_span[d]) * spans;
    }
    if (size[0] * size[1] > kMaxSurfacePoints)
      fail(knots ? knots : n, knots ? knots_key : p,
           fmt::format("too many control points after refinement ({:.0f} x {:.0f} = {:.0f}, at "
                       "most {:.0f})",
                       size[0], size[1], size[0] * size[1], kMaxSurfacePoints));

    geometry::NurbsSurface out = in;
    try {
      for (std::size_t d = 0; d < 2; ++d)
        if (s.refine.elevate[d] > 0)
          out = geometry::elevate_degree(
              out, d == 0 ? geometry::Direction::u : geometry::Direction::v, s.refine.elevate[d]);
    } catch (const std::invalid_argument& e) {
      fail(elevate, elevate_key, fmt::format("cannot elevate the degree: {}", e.what()));
    }
    try {
      for (std::size_t d = 0; d < 2; ++d)
        if (s.refine.knots_per_span[d] > 0) {
          const auto dir = d == 0 ? geometry::Direction::u : geometry::Direction::v;
          out = geometry::refine_knots(
              out, dir,
              geometry::uniform_new_knots(d == 0 ? out.u : out.v, s.refine.knots_per_span[d]));
        }
    } catch (const std::invalid_argument& e) {
      fail(knots, knots_key, fmt::format("cannot insert the knots: {}", e.what()));
    }
    return out;
  }

  // `placement: {origin: V, orientation: [e1, e2, e3]}`: x ↦ origin + [e1 e2 e3] x.
  void place(const YAML::Node& n, const std::string& p, geometry::NurbsSurface& surface,
             model::Surface& s) {
    expect_map(n, p);
    check_keys(n, p, {"origin", "orientation"});
    if (const auto v = n["origin"]) s.origin = vec3(v, join(p, "origin"));
    if (const auto v = n["orientation"])
      s.orientation = triad(v, join(p, "orientation"), "axes [e1, e2, e3]");
    for (Vec3& x : surface.points) x = s.origin + s.orientation * x;
  }

  fs::path base_dir_;
  std::map<std::string, int> name_lines_;       // surface name → line of its definition
  std::map<std::string, CadModel> cad_models_;  // each file read once, by its resolved path
};

}  // namespace

std::vector<model::Surface> read_surfaces(const YAML::Node& list, const std::string& file) {
  return SurfaceReader(file).read(list);
}

}  // namespace isoflex::io
