#pragma once
// Sparse patterns: whether a matrix already has one (so that its storage can be reused), and
// building one column by column.
#include <Eigen/SparseCore>
#include <algorithm>
#include <vector>

namespace isoflex {

// Whether K has the pattern (same size and outer index, as the fixed-pattern assemblies keep it).
inline bool has_pattern(const Eigen::SparseMatrix<double>& K,
                        const Eigen::SparseMatrix<double>& pattern) {
  return K.rows() == pattern.rows() && K.cols() == pattern.cols() && K.isCompressed() &&
         K.nonZeros() == pattern.nonZeros() &&
         std::equal(pattern.outerIndexPtr(), pattern.outerIndexPtr() + pattern.outerSize() + 1,
                    K.outerIndexPtr());
}

// Makes P the rows × cols pattern (zero values) whose column c holds the rows that
// column_rows(c, out) appends to out (any order, repeats allowed). Each column is made twice,
// counted and then written, so P is allocated once at its size and reuses its storage: no
// triplets, whose transposed copy in setFromTriplets was gigabytes at 10⁶ unknowns.
template <class ColumnRows>
void pattern_by_columns(int rows, int cols, ColumnRows&& column_rows,
                        Eigen::SparseMatrix<double>& P) {
  std::vector<int> column;
  const auto make = [&](int c) {
    column.clear();
    column_rows(c, column);
    if (!std::is_sorted(column.begin(), column.end())) std::sort(column.begin(), column.end());
    column.erase(std::unique(column.begin(), column.end()), column.end());
  };
  P.resize(rows, cols);
  P.makeCompressed();
  int* outer = P.outerIndexPtr();
  outer[0] = 0;
  for (int c = 0; c < cols; ++c) {
    make(c);
    outer[c + 1] = outer[c] + static_cast<int>(column.size());
  }
  P.resizeNonZeros(outer[cols]);
  for (int c = 0; c < cols; ++c) {
    make(c);
    std::copy(column.begin(), column.end(), P.innerIndexPtr() + P.outerIndexPtr()[c]);
  }
  std::fill_n(P.valuePtr(), P.nonZeros(), 0.0);
}

}  // namespace isoflex
