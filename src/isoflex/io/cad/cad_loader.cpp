#include <dlfcn.h>
#include <fmt/format.h>

#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include "isoflex/io/cad/cad_isolation.hpp"
#include "isoflex/io/cad/cad_reader.hpp"

namespace isoflex::io {

namespace {

using ReadFn = detail::CadReadFn;

constexpr double kDefaultTimeLimit = 60;  // s; the largest shared file reads in well under 1 s

// The folders in which the dynamic loader looks for the libraries of the object `handle`: its
// run path, LD_LIBRARY_PATH and the system folders, in the loader's order.
std::vector<std::filesystem::path> search_path(void* handle) {
  std::vector<std::filesystem::path> out;
  Dl_serinfo size;
  if (dlinfo(handle, RTLD_DI_SERINFOSIZE, &size) == 0) {
    std::vector<std::max_align_t> buffer(size.dls_size / sizeof(std::max_align_t) + 1);
    auto* info = reinterpret_cast<Dl_serinfo*>(buffer.data());
    if (dlinfo(handle, RTLD_DI_SERINFOSIZE, info) == 0 &&
        dlinfo(handle, RTLD_DI_SERINFO, info) == 0)
      for (unsigned i = 0; i < info->dls_cnt; ++i) out.emplace_back(info->dls_serpath[i].dls_name);
  }
  return out;
}

// The search path of the running program, then that of the shared object this code is linked
// into, if it is one (the Python module isoflex._isoflex: its run path names the module's folder).
std::vector<std::filesystem::path> program_search_path() {
  std::vector<std::filesystem::path> out;
  if (void* program = dlopen(nullptr, RTLD_LAZY)) {
    out = search_path(program);
    dlclose(program);
  }
  Dl_info self;
  if (dladdr(reinterpret_cast<void*>(&search_path), &self) != 0 && self.dli_fname) {
    if (void* object = dlopen(self.dli_fname, RTLD_LAZY | RTLD_NOLOAD)) {
      for (auto& folder : search_path(object)) out.push_back(std::move(folder));
      dlclose(object);
    }
  }
  return out;
}

// Where the import module may be: $ISOFLEX_CAD_MODULE; next to the running executable (the build
// tree's isoflex); where `cmake --install` puts it relative to the executable (the installed
// isoflex: bin/ → lib/isoflex/); and in the folders of the program's search path, of which its run
// path gives the build folder to the build tree's other executables and the installed lib/isoflex
// to programs linked against the installed package (io/cad/CMakeLists.txt). Those folders are
// searched here rather than by dlopen of the bare file name, because dlopen searches the run path
// of its caller, which is the sanitizer runtime when ASan intercepts it. No path of the build tree
// is compiled in: an installed copy of this code must not load a module the build has since
// changed.
std::vector<std::filesystem::path> module_candidates() {
  std::vector<std::filesystem::path> out;
  if (const char* env = std::getenv("ISOFLEX_CAD_MODULE")) out.emplace_back(env);
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    out.push_back(exe.parent_path() / ISOFLEX_CAD_MODULE_NAME);
    out.push_back(exe.parent_path() / ISOFLEX_CAD_MODULE_FROM_BINDIR);
  }
  for (const auto& folder : program_search_path()) out.push_back(folder / ISOFLEX_CAD_MODULE_NAME);
  return out;
}

ReadFn load_module(const std::string& file) {
  std::string tried;
  const auto add = [&](const std::string& why) { tried += (tried.empty() ? "" : "; ") + why; };
  for (const auto& path : module_candidates()) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) {
      add(path.string() + ": no such file");
      continue;
    }
    // RTLD_NODELETE keeps the module loaded; a second dlopen of it is only a lookup.
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL | RTLD_NODELETE);
    if (!handle) {
      add(dlerror());
      continue;
    }
    if (auto fn = reinterpret_cast<ReadFn>(dlsym(handle, "isoflex_cad_read"))) return fn;
    add(path.string() + ": no isoflex_cad_read");
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
