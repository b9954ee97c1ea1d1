#pragma once
// A CadModel as bytes and back, for the pipe from the reading child process to read_cad
// (cad_isolation.hpp). Both ends are the same executable on the same machine, so numbers are
// copied as their bytes: the patches arrive bit for bit as the reader made them. Internal to
// io/cad.
#include <string>
#include <string_view>

#include "isoflex/io/cad/cad_model.hpp"

namespace isoflex::io::detail {

std::string to_bytes(const CadModel& model);
// Throws std::runtime_error if the bytes are cut short or do not make a valid model.
CadModel model_from_bytes(std::string_view bytes);

// A string list (e.g. an error's parts) as bytes and back; same rules.
std::string strings_to_bytes(const std::vector<std::string>& strings);
std::vector<std::string> strings_from_bytes(std::string_view bytes);

}  // namespace isoflex::io::detail
