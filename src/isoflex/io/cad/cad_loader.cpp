#include <fmt/format.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "isoflex/io/cad/cad_isolation.hpp"
#include "isoflex/io/cad/cad_reader.hpp"
#include "isoflex/platform/loadable_module.hpp"

namespace isoflex::io {

namespace {

using ReadFn = detail::CadReadFn;

constexpr double kDefaultTimeLimit = 60;  // s; the largest shared file reads in well under 1 s

ReadFn load_module(const std::string& file) {
  // $ISOFLEX_CAD_MODULE, next to the executable, the installed layout, the search path
  // (platform/loadable_module.hpp; io/cad/CMakeLists.txt gives the names).
  const platform::ModuleLocation where{"ISOFLEX_CAD_MODULE", ISOFLEX_CAD_MODULE_NAME,
                                       ISOFLEX_CAD_MODULE_FROM_BINDIR};
  std::string tried;
  if (void* fn = platform::load_module_symbol(where, "isoflex_cad_read", &tried))
    return reinterpret_cast<ReadFn>(fn);
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
