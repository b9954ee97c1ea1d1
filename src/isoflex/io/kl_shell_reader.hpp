#pragma once
// The Kirchhoff–Love shell blocks of a model file (docs/model-files.md "kl_shells"): `kl_shells`
// (isogeometric shell patches on surfaces of `surfaces`), `kl_supports`, `kl_loads` and
// `kl_interfaces`. Called
// by io::read_model; errors follow its conventions (FILE:LINE: kl_shells[i].KEY: message).
#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

#include "isoflex/io/yaml_fields.hpp"
#include "isoflex/model/model.hpp"

namespace isoflex::io {

// A point given in a model file lies on a surface if it is within this distance, relative to
// the diagonal of the surface's control-point box, of its closest point (IGA-thesis §4.1.5).
inline constexpr double kOnSurfaceTolerance = 1e-6;

class KLShellReader : YamlFields {
 public:
  explicit KLShellReader(std::string file) : YamlFields(std::move(file)) {}

  std::vector<model::KLShell> shells(const YAML::Node& list,
                                     const std::vector<model::Surface>& surfaces) const;
  std::vector<model::KLSupport> supports(const YAML::Node& list, const model::Model& m) const;
  std::vector<model::KLLoad> loads(const YAML::Node& list, const model::Model& m) const;
  model::KLInterfaces interfaces(const YAML::Node& n, const model::Model& m) const;
  // The parameters (ξ, η) of a point that must lie on the shell's surface; fails at `n` with
  // the distance otherwise.
  std::array<double, 2> point_on_surface(const YAML::Node& n, const std::string& key, const Vec3& x,
                                         const model::Surface& s) const;

 private:
  model::KLShell shell(const YAML::Node& n, const std::string& p,
                       const std::vector<model::Surface>& surfaces) const;
  const model::KLShell& find_shell(const YAML::Node& n, const std::string& key,
                                   const model::Model& m) const;
  std::string edge(const YAML::Node& n, const std::string& key) const;
  model::KLCoupling coupling(const YAML::Node& n, const std::string& key) const;
};

// The surface a Kirchhoff–Love shell lies on.
const model::Surface& kl_surface(const model::Model& m, const model::KLShell& s);

}  // namespace isoflex::io
