#pragma once
// Reads a model file (YAML, schema in docs/model-files.md) into model::Model. Every problem
// found (YAML syntax, unknown or missing keys, wrong types, values out of range, references to
// unknown bodies, malformed time functions) throws io::ModelError with FILE:LINE: KEY: message.
#include <string>
#include <vector>

#include "isoflex/io/model_error.hpp"
#include "isoflex/io/model_overrides.hpp"
#include "isoflex/model/model.hpp"

namespace isoflex::io {

// What the reader may build. A structured shell mesh is made of nodes by the reader itself
// (10⁴ × 10⁴ elements are 10⁸ nodes, issue #15), so its memory estimate
// (system::director_shell_grid) is checked against `memory_limit` before it is built: a located
// ModelError naming the estimate and `memory_limit_text` ("17 GB are available"). 0: no limit.
struct ReadOptions {
  double memory_limit = 0;
  std::string memory_limit_text;
  // Values set over the file's (io/model_overrides.hpp), checked like the file's own; a message
  // about one of them says so instead of a line.
  std::vector<ModelOverride> overrides;
};

// Reads the model file at `path` (which becomes Model::file and the FILE of messages).
model::Model read_model(const std::string& path, const ReadOptions& options = {});

// Reads a model from the YAML text `yaml`; `name_for_messages` stands for the file name in
// messages and in Model::file / Source::file.
model::Model read_model_string(const std::string& yaml, const std::string& name_for_messages,
                               const ReadOptions& options = {});

}  // namespace isoflex::io
