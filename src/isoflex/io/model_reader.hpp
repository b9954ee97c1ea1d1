#pragma once
// Reads a model file (YAML, schema in docs/model-files.md) into model::Model. Every problem
// found (YAML syntax, unknown or missing keys, wrong types, values out of range, references to
// unknown bodies, malformed time functions) throws io::ModelError with FILE:LINE: KEY: message.
#include <string>

#include "isoflex/io/model_error.hpp"
#include "isoflex/model/model.hpp"

namespace isoflex::io {

// Reads the model file at `path` (which becomes Model::file and the FILE of messages).
model::Model read_model(const std::string& path);

// Reads a model from the YAML text `yaml`; `name_for_messages` stands for the file name in
// messages and in Model::file / Source::file.
model::Model read_model_string(const std::string& yaml, const std::string& name_for_messages);

}  // namespace isoflex::io
