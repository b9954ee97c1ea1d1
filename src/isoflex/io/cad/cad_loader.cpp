#include <dlfcn.h>
#include <fmt/format.h>

#include <cmath>
#include <cstdlib>
#include <string>
#include <system_error>
#include <vector>

#include "isoflex/io/cad/cad_isolation.hpp"
#include "isoflex/io/cad/cad_reader.hpp"

namespace isoflex::io {

namespace {

using ReadFn = detail::CadReadFn;

constexpr double kDefaultTimeLimit = 60;  // s; the largest shared file reads in well under 1 s

// Where the import module may be: $ISOFLEX_CAD_MODULE; next to the running executable (the build
// tree's isoflex); where `cmake --install` puts it relative to the executable (the installed
// isoflex: bin/ → lib/isoflex/); and by its file name alone, which dlopen looks for along the
// executable's run path: the build folder for the build tree's other executables, the installed
// lib/isoflex for programs linked against the installed package (io/cad/CMakeLists.txt). No path
// of the build tree is compiled in: an installed copy of this code must not load a module that
// the build has since changed.
std::vector<std::filesystem::path> module_candidates() {
  std::vector<std::filesystem::path> out;
  if (const char* env = std::getenv("ISOFLEX_CAD_MODULE")) out.emplace_back(env);
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    out.push_back(exe.parent_path() / ISOFLEX_CAD_MODULE_NAME);
    out.push_back(exe.parent_path() / ISOFLEX_CAD_MODULE_FROM_BINDIR);
  }
  out.emplace_back(ISOFLEX_CAD_MODULE_NAME);
  return out;
}

ReadFn load_module(const std::string& file) {
  std::string tried;
  for (const auto& path : module_candidates()) {
    // RTLD_NODELETE keeps the module loaded; a second dlopen of it is only a lookup.
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL | RTLD_NODELETE);
    if (!handle) {
      tried += (tried.empty() ? "" : "; ") + std::string(dlerror());
      continue;
    }
    if (auto fn = reinterpret_cast<ReadFn>(dlsym(handle, "isoflex_cad_read"))) return fn;
    tried += (tried.empty() ? "" : "; ") + path.string() + ": no isoflex_cad_read";
  }
  throw CadError(file, "cannot load the CAD import module (" + tried + ")");
}

double time_limit(const CadReadOptions& options, const std::string& file) {
  if (options.time_limit_s) return *options.time_limit_s;
  const char* env = std::getenv("ISOFLEX_CAD_TIME_LIMIT");
  if (!env || !*env) return kDefaultTimeLimit;
  char* end = nullptr;
  const double s = std::strtod(env, &end);
  if (*end != '\0' || !(s > 0) || !std::isfinite(s))
    throw CadError(file, fmt::format("ISOFLEX_CAD_TIME_LIMIT='{}' is not a positive number of "
                                     "seconds",
                                     env));
  return s;
}

}  // namespace

CadModel read_cad(const std::filesystem::path& file, const CadReadOptions& options) {
  const double limit = time_limit(options, file.string());
  // Loaded here, before the fork, so that each child finds OpenCASCADE already relocated.
  const ReadFn read = load_module(file.string());
  return detail::read_in_child(file, read, limit);
}

}  // namespace isoflex::io
