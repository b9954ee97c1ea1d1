#pragma once
// Linear algebra behind the Newton iterations: direct solves (sparse LU, or dense LU where the
// matrix is dense enough that it is faster), rank-revealing factorizations for redundant
// constraints, and condition numbers. Eigen's decompositions are compiled only here.
#include <Eigen/SparseCore>
#include <memory>
#include <vector>

#include "isoflex/math/types.hpp"

namespace isoflex::solve {

using SpMat = Eigen::SparseMatrix<double>;

// Solves A x = b; throws std::runtime_error if A is numerically singular.
VecX solve(const SpMat& A, const VecX& b);

// Solves A x = b for a sequence of matrices with one sparsity pattern (Newton matrices assembled
// into a fixed pattern): the same dense/sparse choice as solve(), but the fill-reducing ordering
// and the symbolic analysis of the sparse LU (UMFPACK: multifrontal, AMD on A + Aᵀ for the
// structurally symmetric Newton matrices, dense fronts through BLAS) are computed once and kept
// while the pattern (outer and inner indices of the compressed A) is unchanged; only the numeric
// factorization is repeated. Not thread-safe (a cache).
class FixedPatternLU {
 public:
  FixedPatternLU();
  ~FixedPatternLU();
  FixedPatternLU(FixedPatternLU&&) noexcept;
  FixedPatternLU& operator=(FixedPatternLU&&) noexcept;
  // Throws std::runtime_error if A is numerically singular. A must be compressed.
  VecX solve(const SpMat& A, const VecX& b);
  int analyses() const;  // how often the pattern was analysed

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The same for symmetric positive definite matrices (sparse LDLᵀ, AMD ordering kept; the lower
// triangle of A is used). Throws std::runtime_error if A is not positive definite.
class FixedPatternLDLT {
 public:
  FixedPatternLDLT();
  ~FixedPatternLDLT();
  FixedPatternLDLT(FixedPatternLDLT&&) noexcept;
  FixedPatternLDLT& operator=(FixedPatternLDLT&&) noexcept;
  VecX solve(const SpMat& A, const VecX& b);
  int analyses() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The same for large symmetric positive definite matrices (stiffness matrices of static
// analysis): supernodal Cholesky LLᵀ by CHOLMOD (its own choice of AMD or METIS ordering), the
// symbolic analysis kept while the pattern does not change; the lower triangle of A is used.
// Throws std::runtime_error if A is not positive definite.
class FixedPatternCholesky {
 public:
  FixedPatternCholesky();
  ~FixedPatternCholesky();
  FixedPatternCholesky(FixedPatternCholesky&&) noexcept;
  FixedPatternCholesky& operator=(FixedPatternCholesky&&) noexcept;
  VecX solve(const SpMat& A, const VecX& b);
  int analyses() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Independent rows of G (m × n) by Gaussian elimination with full pivoting (IGA-thesis Alg. 5.1,
// (5.27), Rem. 5.5): returns the indices of rank(G) rows that span the row space, in the order of
// G. `threshold` is relative to the largest pivot.
std::vector<int> independent_rows_lu(const MatX& G, double threshold = 1e-10);
// The same selection by Householder QR with column pivoting of Gᵀ.
std::vector<int> independent_rows_qr(const MatX& G, double threshold = 1e-10);

// Gᵀ = [W U] [R; 0] (DNSM-III (12)) for G of full row rank m: W (n × m), U (n × (n − m)).
void qr_range_and_null_space(const MatX& G, MatX& W, MatX& U);

// 2-norm condition number σ_max/σ_min (dense SVD; for analysis, not for production paths).
double condition_number(const MatX& A);

// Least-squares solution of A x = b (A dense, full column rank).
VecX least_squares(const MatX& A, const VecX& b);

}  // namespace isoflex::solve
