#pragma once
// Sparse patterns: whether a matrix already has one (so that its storage can be reused), and
// building one column by column.
#include <Eigen/SparseCore>
#include <algorithm>
#include <cstdint>
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

// A 64-bit fingerprint of K's structure (size, outer and inner indices): to tell whether a matrix
// still has the pattern something was built for without keeping a copy of its indices (half a
// gigabyte at 10⁶ unknowns). Each index is mixed in by a multiply and xor-shift (MurmurHash3's
// finalizer), so that moving one entry changes the result; the inner indices in four independent
// lanes, so that the multiplies overlap (one pass at memory speed).
inline std::uint64_t pattern_fingerprint(const Eigen::SparseMatrix<double>& K) {
  const auto mix = [](std::uint64_t h, std::uint64_t x) {
    h = (h ^ x) * 0xff51afd7ed558ccdULL;
    return h ^ (h >> 33);
  };
  std::uint64_t h = 0x9e3779b97f4a7c15ULL;
  h = mix(h, static_cast<std::uint64_t>(K.rows()));
  h = mix(h, static_cast<std::uint64_t>(K.cols()));
  h = mix(h, static_cast<std::uint64_t>(K.nonZeros()));
  for (Eigen::Index j = 0; j <= K.outerSize(); ++j)
    h = mix(h, static_cast<std::uint32_t>(K.outerIndexPtr()[j]));
  std::uint64_t lane[4] = {h, h + 1, h + 2, h + 3};
  const int* inner = K.innerIndexPtr();
  const Eigen::Index nnz = K.nonZeros();
  Eigen::Index k = 0;
  for (; k + 4 <= nnz; k += 4)
    for (int l = 0; l < 4; ++l) lane[l] = mix(lane[l], static_cast<std::uint32_t>(inner[k + l]));
  for (; k < nnz; ++k) lane[0] = mix(lane[0], static_cast<std::uint32_t>(inner[k]));
  for (int l = 0; l < 4; ++l) h = mix(h, lane[l]);
  return h;
}

// K := P's structure (size, outer and inner indices); K's values are left to the caller.
inline void copy_structure(const Eigen::SparseMatrix<double>& P, Eigen::SparseMatrix<double>& K) {
  K.resize(P.rows(), P.cols());
  K.resizeNonZeros(P.nonZeros());
  std::copy(P.outerIndexPtr(), P.outerIndexPtr() + P.outerSize() + 1, K.outerIndexPtr());
  std::copy(P.innerIndexPtr(), P.innerIndexPtr() + P.nonZeros(), K.innerIndexPtr());
}

// Makes P the rows × cols pattern whose column c holds the rows that column_rows(c, out) appends
// to out (any order, repeats allowed); its values zero, or, with zero_values false, not written
// (a pattern whose values nobody reads: its value array is then never touched, so never
// resident). Each column is made twice, counted and then written, so P is allocated once at its
// size and reuses its storage: no triplets, whose transposed copy in setFromTriplets was
// gigabytes at 10⁶ unknowns.
template <class ColumnRows>
void pattern_by_columns(int rows, int cols, ColumnRows&& column_rows,
                        Eigen::SparseMatrix<double>& P, bool zero_values = true) {
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
  if (zero_values) std::fill_n(P.valuePtr(), P.nonZeros(), 0.0);
}

}  // namespace isoflex
