#pragma once
// The processes of a run started by an MPI launcher (`mpirun -n N isoflex run --static MODEL`,
// docs/theory/solvers.md §6): their number, this one's rank and a sum over all of them. MPI is
// PETSc's: it lives in the PETSc module (krylov_backend.hpp), so that isoflex itself includes no
// MPI header and a run without a launcher loads neither MPI nor PETSc.
#include <string>

namespace isoflex::solve {

class ProcessGroup {
 public:
  virtual ~ProcessGroup() = default;
  virtual int rank() const = 0;  // 0 … size() − 1
  virtual int size() const = 0;
  // values[i] ← Σ over the ranks of values[i] (count entries, each rank's own array); every rank
  // receives the same sums, bit for bit. Collective: every rank calls it with the same count.
  virtual void sum(double* values, long count) const = 0;
  // Ends every rank's process with exit status `code` (MPI_Abort): for a failure on one rank
  // that the others, which may be waiting for it in a sum, cannot see.
  [[noreturn]] virtual void abort(int code) const = 0;
};

// The ranks the launcher announced in the environment (Open MPI's OMPI_COMM_WORLD_SIZE, the
// PMI_SIZE of MPICH's Hydra), 1 without a launcher or when the variable is not a number ≥ 1.
int launched_ranks();

// This run's processes: a group of one (rank 0, sums unchanged) unless the launcher started
// N > 1 ranks; then MPI's world, started by the PETSc module (loaded here, on the first call).
// Throws std::runtime_error when N > 1 and the module does not load or MPI does not start.
const ProcessGroup& processes();

}  // namespace isoflex::solve
