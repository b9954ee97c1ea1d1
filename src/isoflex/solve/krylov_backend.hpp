#pragma once
// The interface between isoflex and its PETSc module (libisoflex_petsc.so, solve/petsc/): the
// module is opened by KrylovSolver (krylov_solver.hpp) when a model asks for an iterative or a
// PETSc solver, and only then, so that no other run loads PETSc's libraries (about 100 of them,
// 60–80 ms per process). Module and caller are built by the same compiler against the same
// libstdc++, so C++ objects and exceptions pass through.
#include <string>

#include "isoflex/solve/process_group.hpp"

namespace isoflex::solve {

// The PETSc solvers (docs/theory/solvers.md §3–4): conjugate gradients preconditioned by smoothed-
// aggregation algebraic multigrid (PCGAMG) with the near-null-space of set_near_null_space, the
// same with hypre's BoomerAMG (classical AMG; no near-null-space), MUMPS's sparse Cholesky, and
// conjugate gradients preconditioned by geometric multigrid (PCMG) with the interpolations of
// set_interpolations (the knot hierarchy of the NURBS patches, Galerkin coarse matrices).
enum class KrylovMethod { cg_gamg, cg_hypre, mumps, cg_multigrid };

// A matrix in compressed sparse rows (PETSc's AIJ layout; a symmetric Eigen column-major matrix
// is its own CSR). The arrays are the caller's: the module reads them in place.
struct CsrView {
  int n = 0;                       // rows
  int cols = 0;                    // 0: square
  const int* row_start = nullptr;  // n + 1 entries
  const int* columns = nullptr;    // sorted within a row
  const double* values = nullptr;
};

struct KrylovReport {
  int iterations = 0;
  double residual = 0.0;  // ‖b − A x‖₂ at the end, by the solver's recurrence
  std::string reason;     // PETSc's converged/diverged reason
};

// A distributed backend (isoflex_petsc_create's `distributed`, on MPI's world of N > 1 ranks:
// mpirun, process_group.hpp) makes every call collective, with the same arguments on every rank
// but for A's values: the matrix solved is the sum of the ranks' matrices (each holds its own
// elements' part, in the same pattern), b is the same on every rank and x comes back whole on
// every rank. The matrix is PETSc's MPIAIJ with contiguous blocks of rows (docs/theory/solvers.md
// §6); the saddle point is not distributed. Any other backend solves its own process's matrix
// alone, also on one of several ranks.
class KrylovBackend {
 public:
  virtual ~KrylovBackend() = default;
  // A basis of the near null space (n rows, `count` orthonormal columns, column-major), given to
  // the algebraic multigrid with every matrix from now on.
  virtual void set_near_null_space(int n, int count, const double* columns) = 0;
  // The multigrid interpolations P_1 (n × n_1, onto A's unknowns), P_2 (n_1 × n_2), …, the
  // coarsest last (cg_multigrid only); their arrays must stay alive and unchanged.
  virtual void set_interpolations(int count, const CsrView* P) = 0;
  // x = A⁻¹ b to ‖b − A x‖₂ ≤ max(rtol ‖b‖₂, atol) from x = 0. `new_pattern`: A's arrays are not
  // those of the last call (else only their values changed, and the module reuses its matrix,
  // the multigrid hierarchy's aggregates and the symbolic factorization). Throws
  // std::runtime_error when the solver fails (not positive definite, no convergence in
  // max_iterations), with PETSc's reason.
  virtual KrylovReport solve(const CsrView& A, bool new_pattern, const double* b, double* x,
                             double rtol, double atol, int max_iterations) = 0;
  // The saddle point [A Bᵀ; B 0] [x; y] = b (docs/theory/solvers.md §5): A (p × p) symmetric
  // positive definite, in place as in solve; B (h × p), copied; b, x: p + h entries. FGMRES with
  // the block-triangular preconditioner [A Bᵀ; 0 S] (PCFIELDSPLIT, Schur, upper), A's block by
  // one application of the method's preconditioner (a multigrid cycle, MUMPS's solve), S by the
  // diagonal matrix `schur` (h entries). `new_pattern`: A's or B's pattern changed; else
  // `new_values`: their values did (the preconditioner is set up again), or not (a refinement
  // step with the same matrices). Throws as solve does.
  virtual KrylovReport solve_saddle_point(const CsrView& A, bool new_pattern, bool new_values,
                                          const CsrView& B, const double* schur, const double* b,
                                          double* x, double rtol, double atol,
                                          int max_iterations) = 0;
};

}  // namespace isoflex::solve

// MPI's world (PETSc and MPI started on the first call, as for isoflex_petsc_create); nullptr with
// the reason in *error if they fail to start. The group lives as long as the process.
extern "C" const isoflex::solve::ProcessGroup* isoflex_petsc_processes(std::string* error);

// The module's entry point: a new backend of `method` (a KrylovMethod), distributed over MPI's
// world if `distributed` is non-zero and the world has more than one rank, PETSc initialized on
// the first call; nullptr with the reason in *error if PETSc fails to start.
extern "C" isoflex::solve::KrylovBackend* isoflex_petsc_create(int method, int distributed,
                                                               std::string* error);
