#pragma once
// Located reading of YAML values for the model-file readers (model_reader.cpp,
// surface_reader.cpp): every problem is a ModelError "FILE:LINE: KEY: message"
// (docs/model-files.md), so the readers share one set of checks and messages.
#include <yaml-cpp/yaml.h>

#include <array>
#include <initializer_list>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "isoflex/io/model_error.hpp"
#include "isoflex/math/types.hpp"
#include "isoflex/model/model.hpp"

namespace isoflex::io {

std::string join(const std::string& path, std::string_view key);   // "a.b"
std::string indexed(const std::string& path, std::size_t i);       // "a[i]"
std::string list_names(std::initializer_list<const char*> names);  // "x, y, z"

// The diagonal of the bounding box of `points` (0 for none).
double bounding_box_diagonal(const std::vector<Vec3>& points);

// The smallest thickness relative to the model size (YamlFields::relative_size).
inline constexpr double kMinRelativeThickness = 1e-12;

class YamlFields {
 public:
  explicit YamlFields(std::string file) : file_(std::move(file)) {}
  const std::string& file() const { return file_; }

  // 1-based line of `n`. yaml-cpp marks an empty value (`mass:` with nothing after it) at the
  // next token, so those take the line of their key, noted by expect_map.
  int line_of(const YAML::Node& n) const;
  [[noreturn]] void fail(const YAML::Node& at, const std::string& key,
                         const std::string& message) const;
  model::Source source(const YAML::Node& n) const { return {file_, line_of(n)}; }

  void expect_map(const YAML::Node& n, const std::string& path) const;
  // Every key of the mapping `n` must be one of `allowed` and appear once.
  void check_keys(const YAML::Node& n, const std::string& path,
                  std::initializer_list<const char*> allowed) const;
  YAML::Node require(const YAML::Node& map, const std::string& path, const char* key) const;
  // An optional list; an empty value (`joints:` with nothing after it) is an empty list.
  YAML::Node optional_list(const YAML::Node& root, const char* key) const;

  std::string string(const YAML::Node& n, const std::string& key) const;
  double number(const YAML::Node& n, const std::string& key) const;  // finite
  double positive(const YAML::Node& n, const std::string& key) const;
  // A thickness (or cross-section size) `value`, read at `n`, against the size of the geometry it
  // belongs to (`size`, the diagonal of its bounding box, described by `of`): below 1e-12 × size
  // the bending stiffness (∝ h³) is lost to round-off beside the rest and a run overflows.
  void relative_size(const YAML::Node& n, const std::string& key, double value, double size,
                     const std::string& of) const;
  int integer(const YAML::Node& n, const std::string& key, int min) const;
  // A Kelvin–Voigt damping factor η (seconds, ≥ 0): materials' and sections' `eta`.
  double damping_factor(const YAML::Node& n, const std::string& key) const;
  bool boolean(const YAML::Node& n, const std::string& key) const;
  Vec3 vec3(const YAML::Node& n, const std::string& key) const;
  Vec3 positive_vec3(const YAML::Node& n, const std::string& key) const;
  Vec3 direction(const YAML::Node& n, const std::string& key) const;  // nonzero, normalized
  // Three axes (rows of the YAML list, columns of the result), orthonormal and right-handed to
  // 1e-9; `what` names them in the message, e.g. "principal axes [d1, d2, d3]".
  Mat3 triad(const YAML::Node& n, const std::string& key, const char* what) const;
  // A time function (a number or an expression in t, muParser syntax), compiled once to
  // validate it; three of them as a list.
  std::string time_function(const YAML::Node& n, const std::string& key) const;
  std::array<std::string, 3> time_functions(const YAML::Node& n, const std::string& key) const;
  // The initial velocities of a beam's or shell's nodes from the keys `velocity`,
  // `angular_velocity`, `velocity_point` and `node_velocities` of the entry `n` at `path`;
  // `what` ("beam \"b\"") names it in the message for a node index out of 0 … node_count − 1.
  model::NodeVelocities node_velocities(const YAML::Node& n, const std::string& path,
                                        int node_count, const std::string& what) const;

 private:
  std::string file_;
  mutable std::vector<std::pair<YAML::Node, int>> null_lines_;  // empty values → their key's line
};

}  // namespace isoflex::io
