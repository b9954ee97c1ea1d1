#pragma once
// The upper triangle of a symmetric CSR matrix as PETSc's SeqSBAIJ matrix (block size 1): the
// operator of CG and of the multigrid's finest level (petsc_backend.cpp). It stores half of the
// matrix's entries, so a product reads about half as many bytes as with AIJ: on the quarter
// Scordelis–Lo roof at 3·10⁵ unknowns 20 products took 0.86 s against AIJ's 1.43 s (products are
// memory-bound; docs/theory/solvers.md §4). Its arrays are its own copy (half of A's), refreshed
// from A's values when they change.
#include <petscmat.h>

#include <algorithm>
#include <stdexcept>
#include <vector>

#include "isoflex/solve/krylov_backend.hpp"

namespace isoflex::solve {

class UpperTriangle {
 public:
  UpperTriangle() = default;
  UpperTriangle(const UpperTriangle&) = delete;
  UpperTriangle& operator=(const UpperTriangle&) = delete;
  ~UpperTriangle() { clear(); }

  // Whether every row of A has its diagonal entry, which SBAIJ stores first in each row.
  static bool possible(const CsrView& A) {
    for (int i = 0; i < A.n; ++i)
      if (!std::binary_search(A.columns + A.row_start[i], A.columns + A.row_start[i + 1], i))
        return false;
    return true;
  }

  // The matrix for A's pattern and values (possible(A)).
  void make(const CsrView& A) {
    clear();
    first_.resize(static_cast<std::size_t>(A.n));
    start_.assign(static_cast<std::size_t>(A.n) + 1, 0);
    for (int i = 0; i < A.n; ++i) {
      first_[static_cast<std::size_t>(i)] = static_cast<int>(
          std::lower_bound(A.columns + A.row_start[i], A.columns + A.row_start[i + 1], i) -
          A.columns);
      start_[static_cast<std::size_t>(i) + 1] = start_[static_cast<std::size_t>(i)] +
                                                A.row_start[i + 1] -
                                                first_[static_cast<std::size_t>(i)];
    }
    columns_.resize(static_cast<std::size_t>(start_.back()));
    values_.resize(columns_.size());
    for (int i = 0; i < A.n; ++i)
      std::copy(A.columns + first_[static_cast<std::size_t>(i)], A.columns + A.row_start[i + 1],
                columns_.begin() + start_[static_cast<std::size_t>(i)]);
    copy_values(A);
    const PetscErrorCode code = MatCreateSeqSBAIJWithArrays(
        PETSC_COMM_SELF, 1, A.n, A.n, start_.data(), columns_.data(), values_.data(), &M_);
    if (code != 0) {
      M_ = nullptr;
      throw std::runtime_error("PETSc: MatCreateSeqSBAIJWithArrays failed");
    }
  }

  // A's new values (the pattern of make()). Through PETSc's get/restore of the value array, as
  // for AIJ: the matrix's state is how PETSc knows its values changed.
  void update(const CsrView& A) {
    PetscScalar* values = nullptr;
    if (MatSeqSBAIJGetArray(M_, &values) != 0 || values != values_.data())
      throw std::runtime_error("PETSc: MatSeqSBAIJGetArray failed");
    copy_values(A);
    if (MatSeqSBAIJRestoreArray(M_, &values) != 0)
      throw std::runtime_error("PETSc: MatSeqSBAIJRestoreArray failed");
  }

  Mat mat() const { return M_; }

  void clear() {
    if (M_) MatDestroy(&M_);
    std::vector<PetscInt>().swap(start_);
    std::vector<PetscInt>().swap(columns_);
    std::vector<PetscScalar>().swap(values_);
    std::vector<int>().swap(first_);
  }

 private:
  void copy_values(const CsrView& A) {
    for (std::size_t i = 0; i < first_.size(); ++i)
      std::copy(A.values + first_[i], A.values + A.row_start[i + 1], values_.begin() + start_[i]);
  }

  std::vector<PetscInt> start_, columns_;
  std::vector<PetscScalar> values_;
  std::vector<int> first_;  // the index in A of row i's diagonal
  Mat M_ = nullptr;
};

}  // namespace isoflex::solve
