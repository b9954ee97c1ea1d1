#pragma once
// The shell blocks of a model file (docs/model-files.md "shells"): `shells` (meshes of bilinear
// director-shell elements: a plate from its corners, a sampled NURBS surface of `surfaces`, or an
// explicit mesh), `shell_supports`, `shell_connections` (edges attached to bodies, edges of two
// shells joined at their angle at t = 0, DNSM-III Ex. 5.3) and `shell_loads`. Called by
// io::read_model; errors follow its conventions (FILE:LINE: shells[i].KEY: message).
#include <yaml-cpp/yaml.h>

#include <functional>
#include <string>
#include <vector>

#include "isoflex/io/yaml_fields.hpp"
#include "isoflex/model/model.hpp"

namespace isoflex::io {

class ShellReader : YamlFields {
 public:
  // memory_limit > 0: a structured mesh whose estimate (system::director_shell_grid) exceeds it
  // is a located error before its nodes are made; memory_limit_text says what the limit is.
  explicit ShellReader(std::string file, double memory_limit = 0,
                       std::string memory_limit_text = "")
      : YamlFields(std::move(file)),
        memory_limit_(memory_limit),
        memory_limit_text_(std::move(memory_limit_text)) {}

  std::vector<model::Shell> shells(const YAML::Node& list,
                                   const std::vector<model::Surface>& surfaces) const;
  std::vector<model::ShellSupport> supports(const YAML::Node& list,
                                            const std::vector<model::Shell>& shells) const;
  // Rigid joints, one per node pair: edge nodes to a body (`attach_to`) or to the matching nodes
  // of another shell's edge (`join`). `is_body` tells whether a name is a body or a beam node.
  std::vector<model::Joint> connections(
      const YAML::Node& list, const std::vector<model::Shell>& shells,
      const std::function<bool(const std::string&)>& is_body) const;
  std::vector<model::ShellLoad> loads(const YAML::Node& list,
                                      const std::vector<model::Shell>& shells) const;

 private:
  model::Shell shell(const YAML::Node& n, const std::string& p,
                     const std::vector<model::Surface>& surfaces) const;
  const model::Shell& find_shell(const YAML::Node& n, const std::string& key,
                                 const std::vector<model::Shell>& shells) const;
  // The nodes an entry names by `edge` or `nodes` (exactly one of them).
  std::vector<int> selected_nodes(const YAML::Node& n, const std::string& p,
                                  const model::Shell& s) const;
  std::vector<int> edge_nodes(const YAML::Node& n, const std::string& key,
                              const model::Shell& s) const;

 private:
  double memory_limit_ = 0;
  std::string memory_limit_text_;
};

}  // namespace isoflex::io
