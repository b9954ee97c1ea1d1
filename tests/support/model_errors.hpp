#pragma once
// The located messages of model files that do not read (io::ModelError), for reader tests.
#include <string>

#include "isoflex/io/model_error.hpp"
#include "isoflex/io/model_reader.hpp"

namespace isoflex::test {

// what() of the io::ModelError thrown for `yaml` (read as "m.yaml"); "(no error)" if it reads.
inline std::string error_of(const std::string& yaml) {
  try {
    io::read_model_string(yaml, "m.yaml");
  } catch (const io::ModelError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace isoflex::test
