#pragma once
// LU factorization of a sparse matrix made of small dense blocks (at most 6 × 6: the ν-groups of
// the reduced Newton matrix, integrate/reduced_newton_matrix.hpp) with a structurally symmetric
// block pattern. The elimination order (minimum degree on the block graph), the filled pattern
// and the list of block updates are computed once; a factorization is then a right-looking block
// elimination with partial pivoting inside the diagonal blocks only, in fixed-size loops. No
// pivoting across blocks: factorize() reports failure (singular or ill-conditioned pivot block)
// so that the caller can fall back to a general sparse LU.
#include <utility>
#include <vector>

#include "isoflex/math/types.hpp"

namespace isoflex::integrate {

class BlockLU {
 public:
  // Every block is stored as a 6 × 6 matrix, zero outside its groups' widths, so that the
  // products are the fixed-size ones (the zeros stay zero: an L block has no rows or columns
  // beyond its groups' widths, a padded inverse neither).
  using Block6 = Mat<6, 6>;
  BlockLU() = default;
  // Group g occupies rows/columns [offset[g], offset[g] + width[g]) (width ≤ 6); `blocks` lists
  // the nonzero blocks (g, h), every diagonal block included, structurally symmetric.
  BlockLU(std::vector<int> offset, std::vector<int> width,
          const std::vector<std::pair<int, int>>& blocks);
  // values[b]: block `blocks[b]`, zero outside its width[g] × width[h] corner. False if a pivot
  // block is singular or the ratio of its smallest to largest LU pivot is below 1e-12.
  bool factorize(const std::vector<Block6>& values);
  VecX solve(const VecX& b) const;
  void solve(const VecX& b, VecX& x) const;  // the same into x (no allocation once sized)
  // y = A x for the matrix A of `values` (as factorize's): the residual check of a solve in the
  // blocks' fixed-size products.
  void multiply(const std::vector<Block6>& values, const VecX& x, VecX& y) const;
  int size() const { return size_; }
  int filled_blocks() const { return static_cast<int>(blocks_.size()); }

 private:
  struct Update {
    int l, u, target;  // blocks_[target] −= blocks_[l] · blocks_[u]
  };
  struct Pivot {
    int group = 0, diag = 0;
    std::vector<std::pair<int, int>> lower;  // (row group i, block (i, v)) later in the order
    std::vector<std::pair<int, int>> upper;  // (column group j, block (v, j))
    int first_update = 0, last_update = 0;
  };
  std::vector<int> offset_, width_;
  std::vector<std::pair<int, int>> input_groups_;  // (g, h) of each input block
  int size_ = 0;
  std::vector<Pivot> order_;     // elimination order
  std::vector<int> input_;       // storage block of each input block
  std::vector<int> fill_;        // storage blocks that are no input block
  std::vector<Block6> blocks_;   // filled pattern: L (strict lower), U, diagonal
  std::vector<Block6> inverse_;  // D⁻¹ of each pivot (order_ index)
  std::vector<Update> updates_;
  mutable VecX padded_;  // solve's workspace: 6 entries per group
};

}  // namespace isoflex::integrate
