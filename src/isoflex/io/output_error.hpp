#pragma once
// The error thrown by the output writers (history_writer, summary_writer, vtk_writer) when a file
// or folder cannot be written: a full disk, a folder without write permission, a directory where
// the file goes. what() is "cannot write FILE: CAUSE" (or "cannot create directory DIR: CAUSE"),
// CAUSE being the system's text for errno. The writers leave what they wrote before it complete;
// the run driver ends the run with exit code 4 (app/exit_codes.hpp).
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>

namespace isoflex::io {

class OutputError : public std::runtime_error {
 public:
  // `action` is what failed on `file`: "write" or "create directory".
  OutputError(std::filesystem::path file, std::string cause, const std::string& action = "write")
      : std::runtime_error("cannot " + action + " " + file.string() + ": " + cause),
        file_(std::move(file)),
        cause_(std::move(cause)) {}

  // The error of a failed system call, from its errno value.
  static OutputError from_errno(std::filesystem::path file, int error,
                                const std::string& action = "write") {
    return OutputError(std::move(file), std::strerror(error), action);
  }

  const std::filesystem::path& file() const { return file_; }
  const std::string& cause() const { return cause_; }

 private:
  std::filesystem::path file_;
  std::string cause_;
};

}  // namespace isoflex::io
