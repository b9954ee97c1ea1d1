#pragma once
// The optional parts of isoflex that are built as loadable modules (the CAD import on
// OpenCASCADE, io/cad; the PETSc solvers, solve/petsc): a module is opened with dlopen when it is
// first needed, so that a run that does not need it does not load its libraries.
#include <string>

namespace isoflex::platform {

// Where a module may be, in this order: the file named by the environment variable `env_var`;
// `file_name` next to the running executable (the build tree); `from_bindir` relative to the
// executable's folder (the installed layout, bin/ → lib/isoflex/); `file_name` in the folders of
// the program's search path (its run path, LD_LIBRARY_PATH, the system folders) and in those of
// the shared object this code is linked into (the Python module).
struct ModuleLocation {
  const char* env_var;
  const char* file_name;
  const char* from_bindir;
};

// The address of `symbol` in the first candidate that opens and exports it (the module stays
// loaded), or nullptr with every candidate tried and why it failed in *tried ("…; …").
void* load_module_symbol(const ModuleLocation& where, const char* symbol, std::string* tried);

}  // namespace isoflex::platform
