#pragma once
// Files for tests: temporary directories, and whole text files read and written.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>

namespace isoflex::test {

// Empties `dir` (removing what was there), creates it with its parents and returns it.
inline std::filesystem::path make_empty_dir(const std::filesystem::path& dir) {
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// The empty directory `prefix` + `name` + "_" + process id below the system temp directory (the
// process id keeps concurrent test runs apart); the test removes it.
inline std::filesystem::path temp_dir(const std::string& prefix, const std::string& name) {
  return make_empty_dir(std::filesystem::temp_directory_path() /
                        (prefix + name + "_" + std::to_string(::getpid())));
}

// An empty directory at `path` for the lifetime of the object, removed with all its contents by
// the destructor (errors ignored).
class TempDir {
 public:
  explicit TempDir(const std::filesystem::path& path) : path_(make_empty_dir(path)) {}
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// The whole content of the file `p` (empty if it cannot be opened).
inline std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Writes `text` to the file `p` (replacing it); the file is closed on return.
inline void write_text(const std::filesystem::path& p, const std::string& text) {
  std::ofstream(p) << text;
}

}  // namespace isoflex::test
