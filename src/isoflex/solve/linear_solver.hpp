#pragma once
// Linear algebra behind the Newton iterations: direct solves (sparse LU, or dense LU where the
// matrix is dense enough that it is faster), rank-revealing factorizations for redundant
// constraints, and condition numbers. Eigen's decompositions are compiled only here.
#include <Eigen/SparseCore>
#include <vector>

#include "isoflex/math/types.hpp"

namespace isoflex::solve {

using SpMat = Eigen::SparseMatrix<double>;

// Solves A x = b; throws std::runtime_error if A is numerically singular.
VecX solve(const SpMat& A, const VecX& b);

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
