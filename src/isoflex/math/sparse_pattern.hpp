#pragma once
// Whether a compressed sparse matrix already has a given pattern (same size and outer index, as
// the fixed-pattern assemblies keep it), so that its storage can be reused.
#include <Eigen/SparseCore>
#include <algorithm>

namespace isoflex {

inline bool has_pattern(const Eigen::SparseMatrix<double>& K,
                        const Eigen::SparseMatrix<double>& pattern) {
  return K.rows() == pattern.rows() && K.cols() == pattern.cols() && K.isCompressed() &&
         K.nonZeros() == pattern.nonZeros() &&
         std::equal(pattern.outerIndexPtr(), pattern.outerIndexPtr() + pattern.outerSize() + 1,
                    K.outerIndexPtr());
}

}  // namespace isoflex
