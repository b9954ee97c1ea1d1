#pragma once
// Least-squares multipliers: (G Gᵀ) λ = rhs for a sparse G of full row rank, by sparse LDLᵀ;
// where G Gᵀ is singular to working precision but G is not, by a pivoted QR of Gᵀ (dense, rare).
// The fill-reducing ordering (AMD) is computed once and reused while the sparsity pattern of
// G Gᵀ stays the same — in a time integration it changes only when an entry becomes exactly zero.
#include <Eigen/SparseCholesky>
#include <vector>

#include "isoflex/math/types.hpp"

namespace isoflex::solve {

class NormalEquations {
 public:
  using SpMat = Eigen::SparseMatrix<double>;
  // Throws std::runtime_error if G is rank deficient (relative to its largest entry).
  VecX solve(const SpMat& G, const VecX& rhs);
  int analyses() const { return analyses_; }    // how often the ordering was computed
  int fallbacks() const { return fallbacks_; }  // how often the QR solve was needed

 private:
  Eigen::SimplicialLDLT<SpMat> ldlt_;
  std::vector<int> outer_, inner_;
  int analyses_ = 0;
  int fallbacks_ = 0;
};

}  // namespace isoflex::solve
