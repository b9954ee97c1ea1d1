#pragma once
// Linear algebra behind the Newton iterations: direct solves (sparse LU, or dense LU where the
// matrix is dense enough that it is faster), rank-revealing factorizations for redundant
// constraints, and condition numbers. Eigen's decompositions are compiled only here.
#include <Eigen/SparseCore>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include "isoflex/math/types.hpp"

namespace isoflex::solve {

using SpMat = Eigen::SparseMatrix<double>;

// A factorization ran out of memory (the solver's own report, UMFPACK_ERROR_out_of_memory or
// CHOLMOD_OUT_OF_MEMORY / CHOLMOD_TOO_LARGE, or a std::bad_alloc while factorizing): what() says
// which factorization and at how many unknowns. A std::bad_alloc, not a std::runtime_error, so
// that no fallback meant for a numerical failure (Cholesky → LU, a halved step) retries it.
class OutOfMemory : public std::bad_alloc {
 public:
  explicit OutOfMemory(std::string what) : what_(std::move(what)) {}
  const char* what() const noexcept override { return what_.c_str(); }

 private:
  std::string what_;
};

// Which integer type the sparse factorizations (UMFPACK, CHOLMOD) index with. With 32-bit
// indices (umfpack_di_*, cholmod_*) the factors are limited to 2³¹ entries and UMFPACK's
// numeric object to 2³¹ 8-byte units: a 177 000-unknown Kirchhoff–Love patch failed with
// UMFPACK_ERROR_out_of_memory at 4.8 GB resident (issue #15). The 64-bit interfaces
// (umfpack_dl_*, cholmod_l_*: SuiteSparse_long, Eigen 3.4 UmfPackLU / CholmodBase with
// StorageIndex = SuiteSparse_long) are bounded by memory only; they copy the matrix's index
// arrays once per pattern and its values once per factorization. `automatic`: 64-bit from
// kLongIndexUnknowns unknowns on, 32-bit below, so that small systems factorize exactly as
// before (the two give the same numbers; docs/memory.md).
enum class IndexWidth { automatic, int32, int64 };
inline constexpr int kLongIndexUnknowns = 20000;

// Solves A x = b; throws std::runtime_error if A is numerically singular, OutOfMemory if the
// factorization does not fit.
VecX solve(const SpMat& A, const VecX& b);
// The same for the columns of B, with one factorization.
MatX solve_columns(const SpMat& A, const MatX& B);

// Solves A x = b for a sequence of matrices with one sparsity pattern (Newton matrices assembled
// into a fixed pattern): the same dense/sparse choice as solve(), but the fill-reducing ordering
// and the symbolic analysis of the sparse LU (UMFPACK: multifrontal, AMD on A + Aᵀ for the
// structurally symmetric Newton matrices, dense fronts through BLAS) are computed once and kept
// while the pattern (outer and inner indices of the compressed A) is unchanged; only the numeric
// factorization is repeated. Not thread-safe (a cache).
class FixedPatternLU {
 public:
  explicit FixedPatternLU(IndexWidth width = IndexWidth::automatic);
  ~FixedPatternLU();
  FixedPatternLU(FixedPatternLU&&) noexcept;
  FixedPatternLU& operator=(FixedPatternLU&&) noexcept;
  // Throws std::runtime_error if A is numerically singular, OutOfMemory if the LU does not fit.
  // A must be compressed.
  VecX solve(const SpMat& A, const VecX& b);
  MatX solve_columns(const SpMat& A, const MatX& B);  // the columns of B, one factorization
  int analyses() const;                               // how often the pattern was analysed
  bool used_long_indices() const;  // the last sparse factorization was the 64-bit one

 private:
  template <class Rhs>
  Rhs solve_any(const SpMat& A, const Rhs& b);
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
// Throws std::runtime_error if A is not positive definite, OutOfMemory if the factor does not fit.
class FixedPatternCholesky {
 public:
  explicit FixedPatternCholesky(IndexWidth width = IndexWidth::automatic);
  ~FixedPatternCholesky();
  FixedPatternCholesky(FixedPatternCholesky&&) noexcept;
  FixedPatternCholesky& operator=(FixedPatternCholesky&&) noexcept;
  VecX solve(const SpMat& A, const VecX& b);
  MatX solve_columns(const SpMat& A, const MatX& B);  // the columns of B, one factorization
  // The factorization alone, and solves with the last one (iterative solvers built on it).
  void factorize(const SpMat& A);
  VecX solve(const VecX& b) const;
  int analyses() const;
  bool used_long_indices() const;

 private:
  template <class Rhs>
  Rhs solve_any(const Rhs& b) const;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Independent rows of G (m × n) by Gaussian elimination with full pivoting (IGA-thesis Alg. 5.1,
// (5.27), Rem. 5.5): returns the indices of rank(G) rows that span the row space, in the order of
// G. `threshold` is relative to the largest pivot.
std::vector<int> independent_rows_lu(const MatX& G, double threshold = 1e-10);
// The `count` rows of G at the first pivot positions of its full-pivot LU (the largest pivots
// first), sorted; all rows if G has fewer.
std::vector<int> leading_rows_lu(const MatX& G, int count);
// The same selection by Householder QR with column pivoting of Gᵀ.
std::vector<int> independent_rows_qr(const MatX& G, double threshold = 1e-10);

// Gᵀ = [W U] [R; 0] (DNSM-III (12)) for G of full row rank m: W (n × m), U (n × (n − m)).
void qr_range_and_null_space(const MatX& G, MatX& W, MatX& U);

// 2-norm condition number σ_max/σ_min (dense SVD; for analysis, not for production paths).
double condition_number(const MatX& A);

// Least-squares solution of A x = b (A dense, full column rank).
VecX least_squares(const MatX& A, const VecX& b);

}  // namespace isoflex::solve
