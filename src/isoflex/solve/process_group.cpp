#include "isoflex/solve/process_group.hpp"

#include <cstdlib>
#include <stdexcept>

#include "isoflex/solve/krylov_backend.hpp"
#include "isoflex/solve/petsc_module.hpp"

namespace isoflex::solve {

namespace {

class SingleProcess final : public ProcessGroup {
 public:
  int rank() const override { return 0; }
  int size() const override { return 1; }
  void sum(double*, long) const override {}
  [[noreturn]] void abort(int code) const override { std::exit(code); }
};

using ProcessesFn = const ProcessGroup* (*)(std::string*);

const ProcessGroup& start() {
  static const SingleProcess single;
  if (launched_ranks() <= 1) return single;
  std::string tried;
  const auto world =
      reinterpret_cast<ProcessesFn>(petsc_module_symbol("isoflex_petsc_processes", &tried));
  const std::string ranks = std::to_string(launched_ranks());
  if (!world)
    throw std::runtime_error("started on " + ranks +
                             " MPI ranks, but the PETSc module that runs them does not load (" +
                             tried + ")");
  std::string error;
  const ProcessGroup* group = world(&error);
  if (!group) throw std::runtime_error("started on " + ranks + " MPI ranks: " + error);
  if (group->size() != launched_ranks())
    throw std::runtime_error("started on " + ranks + " MPI ranks, but MPI's world has " +
                             std::to_string(group->size()) +
                             " (is the module built against the launcher's MPI?)");
  return *group;
}

}  // namespace

int launched_ranks() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"}) {
    const char* text = std::getenv(name);
    if (!text) continue;
    char* end = nullptr;
    const long n = std::strtol(text, &end, 10);
    if (end != text && *end == '\0' && n >= 1 && n < (1L << 30)) return static_cast<int>(n);
  }
  return 1;
}

const ProcessGroup& processes() {
  // Started once; a failure is thrown again on every call (a static that throws is retried).
  static const ProcessGroup& group = start();
  return group;
}

}  // namespace isoflex::solve
