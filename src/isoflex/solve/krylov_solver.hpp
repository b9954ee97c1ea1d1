#pragma once
// Iterative and PETSc solvers of symmetric positive definite Newton matrices
// (docs/theory/solvers.md §3): conjugate gradients with algebraic multigrid, or MUMPS, in PETSc,
// which lives in a module loaded on first use (krylov_backend.hpp).
#include <Eigen/SparseCore>
#include <memory>
#include <string>
#include <vector>

#include "isoflex/math/types.hpp"
#include "isoflex/solve/krylov_backend.hpp"

namespace isoflex::solve {

// Whether the PETSc module loads here; if not, why not in *why.
bool krylov_available(std::string* why = nullptr);

// "cg_gamg", "cg_hypre", "mumps", "cg_multigrid"
const char* krylov_method_name(KrylovMethod method);

// The rigid-body modes of a structure whose configuration q holds the positions of points at the
// offsets `points` (x, y, z at offset, offset + 1, offset + 2): the three translations and the
// three rotations about the points' centroid, zero in every other entry; n = q.size() rows. The
// near null space of an unsupported stiffness matrix, which algebraic multigrid must
// interpolate exactly (Vaněk, Mandel & Brezina 1996).
MatX rigid_body_modes(const VecX& q, const std::vector<int>& points);

// Solves A x = b with a PETSc solver; one object per sequence of Newton matrices (the matrix,
// the multigrid hierarchy and the symbolic factorization are kept while the pattern is). Throws
// std::runtime_error if the module cannot be loaded (the constructor) or the solver fails (not
// positive definite, no convergence), so that the caller can fall back to a direct solver.
class KrylovSolver {
 public:
  // `distributed`: on MPI's world of several ranks, the matrix solved is the sum of the ranks'
  // matrices (krylov_backend.hpp, docs/theory/solvers.md §6); otherwise every process solves its
  // own matrix alone.
  explicit KrylovSolver(KrylovMethod method, bool distributed = false);
  ~KrylovSolver();
  KrylovSolver(KrylovSolver&&) noexcept;
  KrylovSolver& operator=(KrylovSolver&&) noexcept;

  KrylovMethod method() const { return method_; }
  // Columns spanning the near null space (rows of A); orthonormalized here. Empty: none.
  void set_near_null_space(const MatX& modes);
  // The interpolations of geometric multigrid (cg_multigrid): P_1 (rows of A × n_1), P_2, …
  void set_interpolations(const std::vector<Eigen::SparseMatrix<double>>& P);
  // A symmetric and compressed, both triangles stored; it must stay alive and in place while
  // it is the last matrix solved (PETSc reads its arrays in place). `new_pattern`: A's pattern
  // differs from the last call's (other arrays are seen by the module itself). Solves to ‖b − A x‖₂
  // ≤ max(rtol ‖b‖₂, atol).
  VecX solve(const Eigen::SparseMatrix<double>& A, bool new_pattern, const VecX& b, double rtol,
             double atol, int max_iterations = 5000);
  // The saddle point [A Bᵀ; B 0] u = b of the augmented Lagrangian (docs/theory/solvers.md §5;
  // solve/saddle_point.hpp): A (p × p) as in solve, B (h × p), `schur` the diagonal of the
  // approximation S ≈ −B A⁻¹ Bᵀ (h entries); u and b have p + h entries. FGMRES to
  // ‖b − M u‖₂ ≤ max(rtol ‖b‖₂, atol), preconditioned by the block triangle, A's block by one
  // application of the method's preconditioner. `new_pattern`: A's or B's pattern changed;
  // `new_values`: their values (false: the matrices of the last call, unchanged).
  VecX solve_saddle_point(const Eigen::SparseMatrix<double>& A, bool new_pattern, bool new_values,
                          const Eigen::SparseMatrix<double, Eigen::RowMajor>& B, const VecX& schur,
                          const VecX& b, double rtol, double atol, int max_iterations = 5000);
  const KrylovReport& last() const { return last_; }

 private:
  KrylovMethod method_;
  std::unique_ptr<KrylovBackend> backend_;
  KrylovReport last_;
  std::vector<Eigen::SparseMatrix<double, Eigen::RowMajor>> interpolations_;  // PETSc reads them
};

}  // namespace isoflex::solve
