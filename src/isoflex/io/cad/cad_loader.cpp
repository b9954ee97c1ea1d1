#include <dlfcn.h>

#include <cstdlib>
#include <string>
#include <system_error>
#include <vector>

#include "isoflex/io/cad/cad_reader.hpp"

namespace isoflex::io {

namespace {

using ReadFn = int (*)(const char*, CadModel*, std::string*, std::string*);

// Where the import module may be: $ISOFLEX_CAD_MODULE, next to the running executable, and where
// the build put it (tests and benchmarks run from other directories of the build tree).
std::vector<std::filesystem::path> module_candidates() {
  std::vector<std::filesystem::path> out;
  if (const char* env = std::getenv("ISOFLEX_CAD_MODULE")) out.emplace_back(env);
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) out.push_back(exe.parent_path() / ISOFLEX_CAD_MODULE_NAME);
  out.emplace_back(ISOFLEX_CAD_MODULE_PATH);
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

}  // namespace

CadModel read_cad(const std::filesystem::path& file) {
  const ReadFn read = load_module(file.string());
  CadModel model;
  std::string where, message;
  switch (read(file.c_str(), &model, &where, &message)) {
    case 0:
      return model;
    case 1:
      throw CadError(where, message);
    default:
      throw CadError(file.string(), message);
  }
}

}  // namespace isoflex::io
