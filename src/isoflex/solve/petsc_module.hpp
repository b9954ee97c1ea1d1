#pragma once
// Where the PETSc module (libisoflex_petsc.so, krylov_backend.hpp) is looked for, shared by the
// solvers (krylov_solver.cpp) and the process group (process_group.cpp).
#include <string>

namespace isoflex::solve {

// The address of the module's `symbol` ($ISOFLEX_PETSC_MODULE, next to the executable, the
// installed layout, the search path: platform/loadable_module.hpp), or nullptr with what was
// tried in *tried.
void* petsc_module_symbol(const char* symbol, std::string* tried);

}  // namespace isoflex::solve
