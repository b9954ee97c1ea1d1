#pragma once
// Model values set from outside the file: `isoflex run MODEL --set solver.dt=1e-3 --set
// bodies[crank].mass=2` (README "A short tour"), applied to the YAML tree before the model is
// read, so that a value set this way is checked like one written in the file.
#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

namespace isoflex::io {

// KEY=VALUE. KEY is a dotted path of map keys and list entries: `solver.dt`, `bodies[0].mass`,
// or an entry by its `name`, `bodies[crank].mass`; a missing last key (or missing maps on the
// way) is added, so a default can be set (`output.vtk_every`). VALUE is YAML: `2`, `"sin(t)"`,
// `[0, 0, 1]`, `{type: sphere, radius: 0.1}`.
struct ModelOverride {
  std::string key, value;
};

// Parses "KEY=VALUE" (split at the first '='); throws std::invalid_argument naming the text.
ModelOverride parse_model_override(const std::string& text);

// Applies the overrides to `root` in order and returns their keys as the reader's messages
// write them (entries by index: bodies[1].mass); throws ModelError(file, 0, KEY, message) for a
// path that does not lead anywhere (an index past the end, no entry of that name, a key below a
// scalar) or a VALUE that is not YAML.
std::vector<std::string> apply_model_overrides(YAML::Node& root,
                                               const std::vector<ModelOverride>& overrides,
                                               const std::string& file);

}  // namespace isoflex::io
