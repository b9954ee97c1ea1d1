#pragma once
// The error thrown by io::read_cad for anything wrong with a CAD file. what() is one line,
//   FILE: message
// (a missing file, a file that is not IGES/STEP or cannot be parsed, a file without surfaces,
// a surface the importer cannot represent).
#include <stdexcept>
#include <string>
#include <utility>

namespace isoflex::io {

class CadError : public std::runtime_error {
 public:
  CadError(std::string file, std::string message)
      : std::runtime_error(file + ": " + message),
        file_(std::move(file)),
        message_(std::move(message)) {}

  const std::string& file() const { return file_; }
  const std::string& message() const { return message_; }

 private:
  std::string file_;
  std::string message_;
};

}  // namespace isoflex::io
