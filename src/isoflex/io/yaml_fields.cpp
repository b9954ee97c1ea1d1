#include "isoflex/io/yaml_fields.hpp"

#include <fmt/format.h>

#include <cmath>
#include <map>

#include "isoflex/loads/time_function.hpp"

namespace isoflex::io {

namespace {
constexpr double kTriadTolerance = 1e-9;
}  // namespace

std::string join(const std::string& path, std::string_view key) {
  return path.empty() ? std::string(key) : path + "." + std::string(key);
}

std::string indexed(const std::string& path, std::size_t i) {
  return path + "[" + std::to_string(i) + "]";
}

std::string list_names(std::initializer_list<const char*> names) {
  std::string s;
  for (const char* n : names) {
    if (!s.empty()) s += ", ";
    s += n;
  }
  return s;
}

int YamlFields::line_of(const YAML::Node& n) const {
  if (n.IsNull())
    for (const auto& [node, line] : null_lines_)
      if (node.is(n)) return line;
  const int line = n.Mark().line;
  return line >= 0 ? line + 1 : 1;
}

void YamlFields::fail(const YAML::Node& at, const std::string& key,
                      const std::string& message) const {
  throw ModelError(file_, line_of(at), key, message);
}

void YamlFields::expect_map(const YAML::Node& n, const std::string& path) const {
  if (!n.IsMap()) fail(n, path, "expected a mapping of keys");
  for (auto it = n.begin(); it != n.end(); ++it)
    if (it->second.IsNull()) null_lines_.emplace_back(it->second, line_of(it->first));
}

void YamlFields::check_keys(const YAML::Node& n, const std::string& path,
                            std::initializer_list<const char*> allowed) const {
  std::map<std::string, int> seen;
  for (auto it = n.begin(); it != n.end(); ++it) {
    const YAML::Node key = it->first;
    if (!key.IsScalar()) fail(key, path, "keys must be plain names");
    const std::string& name = key.Scalar();
    bool known = false;
    for (const char* a : allowed) known = known || name == a;
    if (!known)
      fail(key, join(path, name), "unknown key (valid keys: " + list_names(allowed) + ")");
    if (const auto [pos, inserted] = seen.emplace(name, line_of(key)); !inserted)
      fail(key, join(path, name), fmt::format("duplicate key (first at line {})", pos->second));
  }
}

YAML::Node YamlFields::require(const YAML::Node& map, const std::string& path,
                               const char* key) const {
  const YAML::Node n = map[key];
  if (!n) fail(map, join(path, key), "missing required key");
  return n;
}

YAML::Node YamlFields::optional_list(const YAML::Node& root, const char* key) const {
  const YAML::Node n = root[key];
  if (!n || n.IsNull()) return YAML::Node(YAML::NodeType::Undefined);
  if (!n.IsSequence()) fail(n, key, "expected a list");
  return n;
}

std::string YamlFields::string(const YAML::Node& n, const std::string& key) const {
  if (!n.IsScalar()) fail(n, key, "expected a string");
  return n.Scalar();
}

double YamlFields::number(const YAML::Node& n, const std::string& key) const {
  double x = 0.0;
  if (!n.IsScalar() || !YAML::convert<double>::decode(n, x)) fail(n, key, "expected a number");
  if (!std::isfinite(x)) fail(n, key, "must be a finite number");
  return x;
}

double YamlFields::positive(const YAML::Node& n, const std::string& key) const {
  const double x = number(n, key);
  if (!(x > 0.0)) fail(n, key, fmt::format("must be > 0, got {}", x));
  return x;
}

double bounding_box_diagonal(const std::vector<Vec3>& points) {
  if (points.empty()) return 0.0;
  Vec3 lo = points.front(), hi = points.front();
  for (const Vec3& x : points) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  return (hi - lo).norm();
}

void YamlFields::relative_size(const YAML::Node& n, const std::string& key, double value,
                               double size, const std::string& of) const {
  const double bound = kMinRelativeThickness * size;
  if (!(value >= bound))
    fail(n, key,
         fmt::format("{} is below {:g} x the model size: {:g} x {:.6g} ({}) = {:.6g}", value,
                     kMinRelativeThickness, kMinRelativeThickness, size, of, bound));
}

double YamlFields::damping_factor(const YAML::Node& n, const std::string& key) const {
  const double eta = number(n, key);
  if (eta < 0) fail(n, key, "the damping factor η must be >= 0 (seconds)");
  return eta;
}

int YamlFields::integer(const YAML::Node& n, const std::string& key, int min) const {
  int k = 0;
  if (!n.IsScalar() || !YAML::convert<int>::decode(n, k)) fail(n, key, "expected an integer");
  if (k < min) fail(n, key, fmt::format("must be >= {}, got {}", min, k));
  return k;
}

bool YamlFields::boolean(const YAML::Node& n, const std::string& key) const {
  bool b = false;
  if (!n.IsScalar() || !YAML::convert<bool>::decode(n, b)) fail(n, key, "expected true or false");
  return b;
}

Vec3 YamlFields::vec3(const YAML::Node& n, const std::string& key) const {
  if (!n.IsSequence() || n.size() != 3) fail(n, key, "expected a list of 3 numbers [x, y, z]");
  Vec3 v;
  for (std::size_t i = 0; i < 3; ++i) v(i) = number(n[i], indexed(key, i));
  return v;
}

Vec3 YamlFields::positive_vec3(const YAML::Node& n, const std::string& key) const {
  const Vec3 v = vec3(n, key);
  for (std::size_t i = 0; i < 3; ++i)
    if (!(v(i) > 0.0)) fail(n[i], indexed(key, i), fmt::format("must be > 0, got {}", v(i)));
  return v;
}

Vec3 YamlFields::direction(const YAML::Node& n, const std::string& key) const {
  const Vec3 v = vec3(n, key);
  const double norm = v.stableNorm();
  if (!(norm > 0.0)) fail(n, key, "must be a nonzero vector");
  return v / norm;
}

Mat3 YamlFields::triad(const YAML::Node& n, const std::string& key, const char* what) const {
  if (!n.IsSequence() || n.size() != 3)
    fail(n, key, fmt::format("expected a list of the three {}", what));
  Mat3 R;
  for (std::size_t i = 0; i < 3; ++i) R.col(i) = vec3(n[i], indexed(key, i));
  const double defect = (R.transpose() * R - Mat3::Identity()).cwiseAbs().maxCoeff();
  if (!(defect <= kTriadTolerance) || !(R.determinant() > 0.0))
    fail(n, key, "orientation is not an orthonormal right-handed triad");
  return R;
}

std::string YamlFields::time_function(const YAML::Node& n, const std::string& key) const {
  if (!n.IsScalar()) fail(n, key, "expected a number or an expression in t");
  try {
    loads::TimeFunction check(n.Scalar());
  } catch (const std::invalid_argument& e) {
    fail(n, key, e.what());
  }
  return n.Scalar();
}

std::array<std::string, 3> YamlFields::time_functions(const YAML::Node& n,
                                                      const std::string& key) const {
  if (!n.IsSequence() || n.size() != 3)
    fail(n, key, "expected a list of 3 numbers or expressions in t");
  std::array<std::string, 3> f;
  for (std::size_t i = 0; i < 3; ++i) f[i] = time_function(n[i], indexed(key, i));
  return f;
}

model::NodeVelocities YamlFields::node_velocities(const YAML::Node& n, const std::string& p,
                                                  int node_count, const std::string& what) const {
  model::NodeVelocities out;
  if (const auto v = n["velocity"]) out.velocity = vec3(v, join(p, "velocity"));
  if (const auto v = n["angular_velocity"])
    out.angular_velocity = vec3(v, join(p, "angular_velocity"));
  if (const auto v = n["velocity_point"]) out.velocity_point = vec3(v, join(p, "velocity_point"));
  const YAML::Node list = n["node_velocities"];
  if (!list) return out;
  const std::string key = join(p, "node_velocities");
  if (!list.IsSequence()) fail(list, key, "expected a list of {node, velocity, angular_velocity}");
  for (std::size_t k = 0; k < list.size(); ++k) {
    const std::string e = indexed(key, k);
    expect_map(list[k], e);
    check_keys(list[k], e, {"node", "velocity", "angular_velocity"});
    model::NodeVelocities::Node nv;
    const YAML::Node node = require(list[k], e, "node");
    nv.node = integer(node, join(e, "node"), 0);
    if (nv.node >= node_count)
      fail(node, join(e, "node"), fmt::format("{} has nodes 0 … {}", what, node_count - 1));
    if (const auto v = list[k]["velocity"]) nv.velocity = vec3(v, join(e, "velocity"));
    if (const auto v = list[k]["angular_velocity"])
      nv.angular_velocity = vec3(v, join(e, "angular_velocity"));
    out.nodes.push_back(nv);
  }
  return out;
}

}  // namespace isoflex::io
