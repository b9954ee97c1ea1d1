#pragma once
// Least-squares multipliers: (G Gᵀ) λ = rhs for a sparse G of full row rank, by sparse LDLᵀ.
// The fill-reducing ordering (AMD) is computed once and reused while the sparsity pattern of
// G Gᵀ stays the same — in a time integration it changes only when an entry becomes exactly zero.
#include <Eigen/SparseCholesky>
#include <vector>

#include "isoflex/math/types.hpp"

namespace isoflex::solve {

class NormalEquations {
 public:
  using SpMat = Eigen::SparseMatrix<double>;
  // Throws std::runtime_error if G Gᵀ is not positive definite (G rank deficient).
  VecX solve(const SpMat& G, const VecX& rhs);
  int analyses() const { return analyses_; }  // how often the ordering was computed

 private:
  Eigen::SimplicialLDLT<SpMat> ldlt_;
  std::vector<int> outer_, inner_;
  int analyses_ = 0;
};

}  // namespace isoflex::solve
