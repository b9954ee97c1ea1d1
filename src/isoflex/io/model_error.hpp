#pragma once
// The error thrown by io::read_model for anything wrong with a model file. what() is
//   FILE:LINE: KEY: message   (an entry of the file; LINE 1-based, KEY a dotted path such as
//                              bodies[2].mass or joints[0].type)
//   FILE:LINE: message        (YAML syntax errors, no key)
//   FILE: message             (file-level errors such as a missing file)
#include <stdexcept>
#include <string>
#include <utility>

namespace isoflex::io {

class ModelError : public std::runtime_error {
 public:
  ModelError(std::string file, int line, std::string key, std::string message)
      : std::runtime_error(compose(file, line, key, message)),
        file_(std::move(file)),
        line_(line),
        key_(std::move(key)),
        message_(std::move(message)) {}

  const std::string& file() const { return file_; }
  int line() const { return line_; }               // 1-based; 0 when not tied to a line
  const std::string& key() const { return key_; }  // empty when not tied to a key
  const std::string& message() const { return message_; }

 private:
  static std::string compose(const std::string& file, int line, const std::string& key,
                             const std::string& message) {
    std::string s = file;
    if (line > 0) s.append(":").append(std::to_string(line));
    s.append(": ");
    if (!key.empty()) s.append(key).append(": ");
    return s.append(message);
  }

  std::string file_;
  int line_;
  std::string key_;
  std::string message_;
};

}  // namespace isoflex::io
