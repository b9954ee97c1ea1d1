#include "isoflex/solve/petsc_module.hpp"

#include "isoflex/platform/loadable_module.hpp"

namespace isoflex::solve {

void* petsc_module_symbol(const char* symbol, std::string* tried) {
  static const platform::ModuleLocation where{"ISOFLEX_PETSC_MODULE", ISOFLEX_PETSC_MODULE_NAME,
                                              ISOFLEX_PETSC_MODULE_FROM_BINDIR};
  return platform::load_module_symbol(where, symbol, tried);
}

}  // namespace isoflex::solve
