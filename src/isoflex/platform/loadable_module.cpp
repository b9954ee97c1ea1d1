#include "isoflex/platform/loadable_module.hpp"

#include <dlfcn.h>

#include <cstddef>
#include <cstdlib>
#include <filesystem>
#include <system_error>
#include <vector>

namespace isoflex::platform {

namespace {

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

// The candidates of ModuleLocation. The folders of the search path are searched here rather than
// by dlopen of the bare file name, because dlopen searches the run path of its caller, which is
// the sanitizer runtime when ASan intercepts it. No path of the build tree is compiled in: an
// installed copy of this code must not load a module the build has since changed.
std::vector<std::filesystem::path> candidates(const ModuleLocation& where) {
  std::vector<std::filesystem::path> out;
  if (const char* env = std::getenv(where.env_var)) out.emplace_back(env);
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    out.push_back(exe.parent_path() / where.file_name);
    out.push_back(exe.parent_path() / where.from_bindir);
  }
  for (const auto& folder : program_search_path()) out.push_back(folder / where.file_name);
  return out;
}

}  // namespace

void* load_module_symbol(const ModuleLocation& where, const char* symbol, std::string* tried) {
  const auto add = [&](const std::string& why) {
    if (tried) *tried += (tried->empty() ? "" : "; ") + why;
  };
  for (const auto& path : candidates(where)) {
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
    if (void* address = dlsym(handle, symbol)) return address;
    add(path.string() + ": no " + symbol);
  }
  return nullptr;
}

}  // namespace isoflex::platform
