#pragma once
// The error of compiling a model into a system: "FILE:LINE: KEY: message", pointing into the model
// file (model::Source).
#include <stdexcept>
#include <string>

#include "isoflex/model/model.hpp"

namespace isoflex::system {

class CompileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

[[noreturn]] void compile_fail(const model::Source& s, const std::string& what,
                               const std::string& msg);

}  // namespace isoflex::system
