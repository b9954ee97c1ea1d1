#pragma once
// Symmetric saddle-point systems
//     [ A  Bᵀ ] [x]   [b_x]
//     [ B  Z  ] [λ] = [b_λ],   A (p × p) symmetric, Z diagonal,
// the Newton matrices of constrained statics (multiplier rows of supports and of multipatch
// couplings, IGA-thesis (3.40), (5.5)), solved at the speed of a sparse Cholesky factorization
// instead of a sparse LU of the whole matrix (docs/theory/solvers.md §1).
//
// Rows with Z_ii ≠ 0 (compliant rows, and rows with the equation λ_i = b_i) are eliminated
// exactly; the others (Z_ii = 0, the set H) by the augmented Lagrangian: with W = diag(w_i),
// w_i = −1/Z_ii on the first and ρ_i on the second,
//     Â = A + Bᵀ W B,     [ Â  B_Hᵀ ] [x  ]   [b_x + Bᵀ W b_λ]
//                         [ B_H  0  ] [λ_H] = [b_H           ],
// an equivalent system whose Â is positive definite wherever A is positive definite on the null
// space of B_H (a stable equilibrium of the constrained problem), factorized by CHOLMOD. That
// system is solved by GMRES, right-preconditioned with the block-triangular
//     P = [ Â  B_Hᵀ ; 0  −W_H⁻¹ ]
// (Benzi & Olshanskii 2006, SIAM J. Sci. Comput. 28; Golub & Greif 2003): the preconditioned
// matrix has the eigenvalue 1 on the primal block and ρ σ/(1 + ρ σ) on the constraints (σ the
// eigenvalues of B_H A⁻¹ B_Hᵀ), clustered at 1 for ρ large; each iteration costs one pair of
// triangular solves. ρ_i = α max_j |A_jj| / ‖B_i‖² over the row's columns j (α = penalty_factor):
// the augmentation is α times the stiffness it meets, whatever the units of the row.
// The compliant rows' multipliers follow from λ_S = (b_S − B_S x)/Z_S.
#include <Eigen/SparseCore>
#include <memory>
#include <optional>

#include "isoflex/math/types.hpp"

namespace isoflex::solve {

using SpMat = Eigen::SparseMatrix<double>;

struct SaddlePointOptions {
  double penalty_factor = 1e2;     // α of the header
  double gmres_tolerance = 1e-12;  // of a GMRES cycle, relative to its right-hand side
  // A solve is accepted at the normwise backward error ‖b − M z‖∞ / (‖M‖∞ ‖z‖∞ + ‖b‖∞) ≤ this
  // (a sparse LU reaches 10⁻¹⁶–10⁻¹⁵); GMRES cycles from the true residual until it is reached.
  double backward_error = 1e-13;
  int max_iterations = 60;  // GMRES iterations of a solve, all cycles
};

struct SaddlePointStats {
  int iterations = 0;         // GMRES iterations of the last solve
  double backward_error = 0;  // its final normwise backward error (SaddlePointOptions)
  int hard_rows = 0;          // rows with Z_ii = 0
};

class SaddlePointSolver {
 public:
  explicit SaddlePointSolver(SaddlePointOptions options = {});
  ~SaddlePointSolver();
  SaddlePointSolver(SaddlePointSolver&&) noexcept;
  SaddlePointSolver& operator=(SaddlePointSolver&&) noexcept;

  // Prepares the solves with M (kept by reference: M must outlive them), compressed and symmetric
  // with the block form of the header at the primal size p: Â and its Cholesky factorization.
  // Throws std::runtime_error if M's lower right block is not diagonal or Â is not positive
  // definite (the caller then falls back to a sparse LU), OutOfMemory if the factor does not fit.
  // The symbolic analysis is kept while M's pattern is.
  void factorize(const SpMat& M, int p);
  // M z = b with the last factorization; throws std::runtime_error if GMRES does not reach the
  // tolerance.
  VecX solve(const VecX& b);
  const SaddlePointStats& last() const;
  int analyses() const;  // symbolic analyses of Â

  // The augmented system of the header without Â's factorization, for another solver of it (the
  // PETSc path of integrate/static_newton.cpp, docs/theory/solvers.md §5): forms Â, B and W from
  // M (kept by reference) as factorize does, with the same exceptions but no factorization.
  void augment(const SpMat& M, int p);
  // The same for a caller that names M's patterns: `pattern_key` equal to the last call's (and
  // the same sizes and number of entries) means the same pattern, not compared, and the solver
  // keeps no copy of it (nnz(M) ints; 0.6 GB at 10⁶ unknowns). A new pattern needs a new key.
  void augment(const SpMat& M, int p, std::optional<long> pattern_key);
  // Â (p × p, symmetric, compressed; its pattern is kept while M's is, its arrays in place).
  const SpMat& augmented_matrix() const;
  // B_H (the hard rows, h × p, in compressed rows) and their weights w_H of the last augment.
  Eigen::SparseMatrix<double, Eigen::RowMajor> hard_rows() const;
  VecX hard_weights() const;
  // The augmented right-hand side f = (b_x + Bᵀ W b_λ, b_H) of M z = b, and z of M from the
  // augmented system's solution u = (x, λ_H) (λ_S = (b_S − B_S x)/Z_S).
  VecX augmented_rhs(const VecX& b) const;
  VecX expand(const VecX& u, const VecX& b) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace isoflex::solve
