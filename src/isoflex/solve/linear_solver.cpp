#include "isoflex/solve/linear_solver.hpp"

#include <Eigen/CholmodSupport>
#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <Eigen/UmfPackSupport>
#include <algorithm>
#include <stdexcept>
#include <type_traits>

namespace isoflex::solve {

namespace {
// 64-bit column pointers and row indices (SuiteSparse_long: int64_t on Debian's SuiteSparse 5.12),
// for umfpack_dl_* and cholmod_l_* through Eigen 3.4's UmfPackLU / CholmodBase, which pick the
// SuiteSparse routine by the matrix's StorageIndex (Eigen/src/UmfPackSupport/UmfPackSupport.h,
// the SuiteSparse_long overloads; CholmodSupport.h, cm_*<SuiteSparse_long> → cholmod_l_*).
using SpMatL = Eigen::SparseMatrix<double, Eigen::ColMajor, SuiteSparse_long>;

// Eigen's UmfPackLU with UMFPACK's status (Info[UMFPACK_STATUS], UMFPACK User Guide §5.3): Eigen
// maps every failure of umfpack_*_numeric to NumericalIssue and of umfpack_*_symbolic to
// InvalidInput, but out of memory is not a singular matrix. Info is a protected member.
template <class Matrix>
class UmfPack : public Eigen::UmfPackLU<Matrix> {
 public:
  double status() const { return this->m_umfpackInfo[UMFPACK_STATUS]; }
};

std::string unknowns_text(Eigen::Index rows, Eigen::Index nnz, bool long_indices) {
  return "at " + std::to_string(rows) + " unknowns (" + std::to_string(nnz) + " non-zeros, " +
         (long_indices ? "64" : "32") + "-bit indices)";
}

[[noreturn]] void throw_lu_out_of_memory(Eigen::Index rows, Eigen::Index nnz, bool long_indices) {
  throw OutOfMemory("out of memory in the sparse LU (UMFPACK) " +
                    unknowns_text(rows, nnz, long_indices));
}

[[noreturn]] void throw_cholesky_out_of_memory(Eigen::Index rows, Eigen::Index nnz,
                                               bool long_indices, int status) {
  throw OutOfMemory(std::string(status == CHOLMOD_TOO_LARGE ? "the factor exceeds the index range"
                                                            : "out of memory") +
                    " in the sparse Cholesky factorization (CHOLMOD) " +
                    unknowns_text(rows, nnz, long_indices));
}

bool use_dense(const SpMat& A);

bool use_long(IndexWidth width, const SpMat& A) {
  return width == IndexWidth::int64 || (width == IndexWidth::automatic &&
                                        A.rows() >= static_cast<Eigen::Index>(kLongIndexUnknowns));
}

// Numeric LU of A (pattern analysed already) and the solution of A x = b.
template <class Matrix, class Rhs>
Rhs factorize_and_solve(UmfPack<Matrix>& lu, const Matrix& A, const Rhs& b) {
  constexpr bool long_indices = std::is_same_v<typename Matrix::StorageIndex, SuiteSparse_long>;
  try {
    lu.factorize(A);
  } catch (const std::bad_alloc&) {
    throw_lu_out_of_memory(A.rows(), A.nonZeros(), long_indices);
  }
  if (lu.info() != Eigen::Success) {
    if (lu.status() == UMFPACK_ERROR_out_of_memory)
      throw_lu_out_of_memory(A.rows(), A.nonZeros(), long_indices);
    throw std::runtime_error("singular Newton matrix (sparse LU)");
  }
  Rhs x = lu.solve(b);
  if (!x.allFinite()) throw std::runtime_error("singular Newton matrix");
  return x;
}

// Symbolic analysis by UMFPACK; out of memory there is reported as such.
template <class Matrix>
void analyze_lu(UmfPack<Matrix>& lu, const Matrix& A) {
  constexpr bool long_indices = std::is_same_v<typename Matrix::StorageIndex, SuiteSparse_long>;
  try {
    lu.analyzePattern(A);
  } catch (const std::bad_alloc&) {
    throw_lu_out_of_memory(A.rows(), A.nonZeros(), long_indices);
  }
  if (lu.info() != Eigen::Success && lu.status() == UMFPACK_ERROR_out_of_memory)
    throw_lu_out_of_memory(A.rows(), A.nonZeros(), long_indices);
}

// The 64-bit copy of A: the pattern when it changed, the values always.
void copy_long(const SpMat& A, bool new_pattern, SpMatL& L) {
  if (new_pattern || L.rows() != A.rows() || L.nonZeros() != A.nonZeros()) {
    L.resize(A.rows(), A.cols());
    L.resizeNonZeros(A.nonZeros());
    std::copy(A.outerIndexPtr(), A.outerIndexPtr() + A.outerSize() + 1, L.outerIndexPtr());
    std::copy(A.innerIndexPtr(), A.innerIndexPtr() + A.nonZeros(), L.innerIndexPtr());
  }
  std::copy(A.valuePtr(), A.valuePtr() + A.nonZeros(), L.valuePtr());
}
}  // namespace

namespace {
template <class Rhs>
Rhs solve_once(const SpMat& A, const Rhs& b) {
  if (use_dense(A)) {
    // Dense enough that a dense LU beats the sparse one.
    const MatX dense(A);
    const Eigen::PartialPivLU<MatX> lu(dense);
    Rhs x = lu.solve(b);
    if (!x.allFinite()) throw std::runtime_error("singular Newton matrix");
    return x;
  }
  if (use_long(IndexWidth::automatic, A)) {
    SpMatL L;
    copy_long(A, true, L);
    UmfPack<SpMatL> lu;
    analyze_lu(lu, L);
    return factorize_and_solve(lu, L, b);
  }
  UmfPack<SpMat> lu;
  analyze_lu(lu, A);
  return factorize_and_solve(lu, A, b);
}
}  // namespace

VecX solve(const SpMat& A, const VecX& b) {
  return solve_once(A, b);
}
MatX solve_columns(const SpMat& A, const MatX& B) {
  return solve_once(A, B);
}

namespace {
bool use_dense(const SpMat& A) {
  const double density = double(A.nonZeros()) / (double(A.rows()) * double(A.cols()));
  return A.rows() <= 64 || density > 0.15;
}

// The sparsity pattern a fixed-pattern factorization last analysed (outer and inner indices of
// the compressed matrix, and its rows), and how often a pattern was analysed.
struct KeptPattern {
  std::vector<int> outer, inner;
  int rows = -1, analyses = 0;
};

// Unless the compressed A has the kept pattern: runs analyze() (the solver's symbolic analysis,
// which may throw) and then keeps A's pattern. Returns whether it analysed.
template <class Analyze>
bool analyze_if_new_pattern(KeptPattern& kept, const SpMat& A, Analyze&& analyze) {
  const int* o = A.outerIndexPtr();
  const int* i = A.innerIndexPtr();
  const bool same = kept.rows == A.rows() &&
                    kept.outer.size() == static_cast<std::size_t>(A.outerSize() + 1) &&
                    kept.inner.size() == static_cast<std::size_t>(A.nonZeros()) &&
                    std::equal(kept.outer.begin(), kept.outer.end(), o) &&
                    std::equal(kept.inner.begin(), kept.inner.end(), i);
  if (same) return false;
  kept.rows = -1;  // no valid analysis until analyze() returns
  analyze();
  kept.outer.assign(o, o + A.outerSize() + 1);
  kept.inner.assign(i, i + A.nonZeros());
  kept.rows = static_cast<int>(A.rows());
  ++kept.analyses;
  return true;
}
}  // namespace

struct FixedPatternLU::Impl {
  IndexWidth width;
  UmfPack<SpMat> lu;
  KeptPattern pattern;
  // The 64-bit path: its own solver, pattern and copy of A (made on first use).
  std::unique_ptr<UmfPack<SpMatL>> lu64;
  KeptPattern pattern64;
  SpMatL A64;
  bool last_long = false;
};

FixedPatternLU::FixedPatternLU(IndexWidth width) : impl_(std::make_unique<Impl>()) {
  impl_->width = width;
}
FixedPatternLU::~FixedPatternLU() = default;
FixedPatternLU::FixedPatternLU(FixedPatternLU&&) noexcept = default;
FixedPatternLU& FixedPatternLU::operator=(FixedPatternLU&&) noexcept = default;
int FixedPatternLU::analyses() const {
  return impl_->pattern.analyses + impl_->pattern64.analyses;
}
bool FixedPatternLU::used_long_indices() const {
  return impl_->last_long;
}

template <class Rhs>
Rhs FixedPatternLU::solve_any(const SpMat& A, const Rhs& b) {
  if (!A.isCompressed()) throw std::logic_error("FixedPatternLU: matrix not compressed");
  if (use_dense(A)) return solve_once(A, b);
  Impl& m = *impl_;
  m.last_long = use_long(m.width, A);
  if (!m.last_long) {
    analyze_if_new_pattern(m.pattern, A, [&] { analyze_lu(m.lu, A); });
    return factorize_and_solve(m.lu, A, b);
  }
  if (!m.lu64) m.lu64 = std::make_unique<UmfPack<SpMatL>>();
  bool copied = false;
  analyze_if_new_pattern(m.pattern64, A, [&] {
    copy_long(A, true, m.A64);
    copied = true;
    analyze_lu(*m.lu64, m.A64);
  });
  if (!copied) copy_long(A, false, m.A64);
  return factorize_and_solve(*m.lu64, m.A64, b);
}
VecX FixedPatternLU::solve(const SpMat& A, const VecX& b) {
  return solve_any(A, b);
}
MatX FixedPatternLU::solve_columns(const SpMat& A, const MatX& B) {
  return solve_any(A, B);
}

struct FixedPatternLDLT::Impl {
  Eigen::SimplicialLDLT<SpMat, Eigen::Lower, Eigen::AMDOrdering<int>> ldlt;
  KeptPattern pattern;
};

FixedPatternLDLT::FixedPatternLDLT() : impl_(std::make_unique<Impl>()) {}
FixedPatternLDLT::~FixedPatternLDLT() = default;
FixedPatternLDLT::FixedPatternLDLT(FixedPatternLDLT&&) noexcept = default;
FixedPatternLDLT& FixedPatternLDLT::operator=(FixedPatternLDLT&&) noexcept = default;
int FixedPatternLDLT::analyses() const {
  return impl_->pattern.analyses;
}

VecX FixedPatternLDLT::solve(const SpMat& A, const VecX& b) {
  if (!A.isCompressed()) throw std::logic_error("FixedPatternLDLT: matrix not compressed");
  Impl& m = *impl_;
  analyze_if_new_pattern(m.pattern, A, [&] { m.ldlt.analyzePattern(A); });
  m.ldlt.factorize(A);
  if (m.ldlt.info() != Eigen::Success) throw std::runtime_error("matrix not positive definite");
  return m.ldlt.solve(b);
}

namespace {
template <class Matrix>
using Supernodal = Eigen::CholmodSupernodalLLT<Matrix, Eigen::Lower>;

// An indefinite matrix is reported by the exception (callers fall back to LU), not printed.
template <class Matrix>
void quiet(Supernodal<Matrix>& llt) {
  llt.cholmod().print = 0;
  llt.cholmod().quick_return_if_not_posdef = 1;
}

// CHOLMOD reports a failure in Common->status (CHOLMOD User Guide, cholmod_common: status < 0
// an error, CHOLMOD_NOT_POSDEF > 0 a warning); Eigen only looks at L->minor.
template <class Matrix>
void check_cholmod(const Supernodal<Matrix>& llt, const Matrix& A) {
  constexpr bool long_indices = std::is_same_v<typename Matrix::StorageIndex, SuiteSparse_long>;
  const int status = const_cast<Supernodal<Matrix>&>(llt).cholmod().status;
  if (status == CHOLMOD_OUT_OF_MEMORY || status == CHOLMOD_TOO_LARGE)
    throw_cholesky_out_of_memory(A.rows(), A.nonZeros(), long_indices, status);
}

template <class Matrix>
void cholesky_factorize(Supernodal<Matrix>& llt, const Matrix& A) {
  constexpr bool long_indices = std::is_same_v<typename Matrix::StorageIndex, SuiteSparse_long>;
  try {
    llt.factorize(A);
  } catch (const std::bad_alloc&) {
    throw_cholesky_out_of_memory(A.rows(), A.nonZeros(), long_indices, CHOLMOD_OUT_OF_MEMORY);
  }
  check_cholmod(llt, A);
  if (llt.info() != Eigen::Success) throw std::runtime_error("matrix not positive definite");
}

template <class Matrix, class Rhs>
Rhs cholesky_back_solve(const Supernodal<Matrix>& llt, const Rhs& b) {
  Rhs x = llt.solve(b);
  if (!x.allFinite()) throw std::runtime_error("matrix not positive definite");
  return x;
}

template <class Matrix>
void analyze_cholesky(Supernodal<Matrix>& llt, const Matrix& A) {
  constexpr bool long_indices = std::is_same_v<typename Matrix::StorageIndex, SuiteSparse_long>;
  try {
    llt.analyzePattern(A);
  } catch (const std::bad_alloc&) {
    throw_cholesky_out_of_memory(A.rows(), A.nonZeros(), long_indices, CHOLMOD_OUT_OF_MEMORY);
  }
  check_cholmod(llt, A);
}
}  // namespace

struct FixedPatternCholesky::Impl {
  IndexWidth width;
  Supernodal<SpMat> llt;
  KeptPattern pattern;
  std::unique_ptr<Supernodal<SpMatL>> llt64;  // the 64-bit path (cholmod_l_*), on first use
  KeptPattern pattern64;
  SpMatL A64;
  bool last_long = false;
  bool factorized = false;
};

FixedPatternCholesky::FixedPatternCholesky(IndexWidth width) : impl_(std::make_unique<Impl>()) {
  impl_->width = width;
  quiet(impl_->llt);
}
FixedPatternCholesky::~FixedPatternCholesky() = default;
FixedPatternCholesky::FixedPatternCholesky(FixedPatternCholesky&&) noexcept = default;
FixedPatternCholesky& FixedPatternCholesky::operator=(FixedPatternCholesky&&) noexcept = default;
int FixedPatternCholesky::analyses() const {
  return impl_->pattern.analyses + impl_->pattern64.analyses;
}
bool FixedPatternCholesky::used_long_indices() const {
  return impl_->last_long;
}

void FixedPatternCholesky::factorize(const SpMat& A) {
  if (!A.isCompressed()) throw std::logic_error("FixedPatternCholesky: matrix not compressed");
  Impl& m = *impl_;
  m.factorized = false;
  m.last_long = use_long(m.width, A);
  if (!m.last_long) {
    analyze_if_new_pattern(m.pattern, A, [&] { analyze_cholesky(m.llt, A); });
    cholesky_factorize(m.llt, A);
  } else {
    if (!m.llt64) {
      m.llt64 = std::make_unique<Supernodal<SpMatL>>();
      quiet(*m.llt64);
    }
    bool copied = false;
    analyze_if_new_pattern(m.pattern64, A, [&] {
      copy_long(A, true, m.A64);
      copied = true;
      analyze_cholesky(*m.llt64, m.A64);
    });
    if (!copied) copy_long(A, false, m.A64);
    cholesky_factorize(*m.llt64, m.A64);
  }
  m.factorized = true;
}
template <class Rhs>
Rhs FixedPatternCholesky::solve_any(const Rhs& b) const {
  const Impl& m = *impl_;
  if (!m.factorized) throw std::logic_error("FixedPatternCholesky: no factorization to solve with");
  return m.last_long ? cholesky_back_solve(*m.llt64, b) : cholesky_back_solve(m.llt, b);
}
VecX FixedPatternCholesky::solve(const SpMat& A, const VecX& b) {
  factorize(A);
  return solve_any(b);
}
MatX FixedPatternCholesky::solve_columns(const SpMat& A, const MatX& B) {
  factorize(A);
  return solve_any(B);
}
VecX FixedPatternCholesky::solve(const VecX& b) const {
  return solve_any(b);
}

// An empty G (no rows, or no columns: rows over a system without freedom, e.g. a locked loop) has
// rank 0; Eigen's rank-revealing decompositions assert on empty matrices, so these return early.
std::vector<int> independent_rows_lu(const MatX& G, double threshold) {
  if (G.rows() == 0 || G.cols() == 0) return {};
  Eigen::FullPivLU<MatX> lu(G);
  lu.setThreshold(threshold);
  const int r = static_cast<int>(lu.rank());
  // (P G Q) = L U: row i of G lands at position P.indices()(i); the first r positions are
  // the independent rows.
  std::vector<int> rows;
  const auto& p = lu.permutationP().indices();
  for (int i = 0; i < G.rows(); ++i)
    if (p(i) < r) rows.push_back(i);
  return rows;
}

std::vector<int> leading_rows_lu(const MatX& G, int count) {
  if (G.rows() == 0 || G.cols() == 0 || count <= 0) return {};
  const Eigen::FullPivLU<MatX> lu(G);
  std::vector<int> rows;
  const auto& p = lu.permutationP().indices();
  for (int i = 0; i < G.rows(); ++i)
    if (p(i) < count) rows.push_back(i);
  return rows;
}

std::vector<int> independent_rows_qr(const MatX& G, double threshold) {
  if (G.rows() == 0 || G.cols() == 0) return {};
  Eigen::ColPivHouseholderQR<MatX> qr(G.transpose());
  qr.setThreshold(threshold);
  const int r = static_cast<int>(qr.rank());
  const auto& p = qr.colsPermutation().indices();
  std::vector<int> rows(p.data(), p.data() + r);
  std::sort(rows.begin(), rows.end());
  return rows;
}

void qr_range_and_null_space(const MatX& G, MatX& W, MatX& U) {
  const int m = static_cast<int>(G.rows()), n = static_cast<int>(G.cols());
  if (m == 0 || n == 0) {  // no rows: all of Rⁿ is the null space
    W = MatX::Zero(n, m);
    U = MatX::Identity(n, n - m > 0 ? n - m : 0);
    return;
  }
  Eigen::HouseholderQR<MatX> qr(G.transpose());
  const MatX Q = qr.householderQ() * MatX::Identity(n, n);
  W = Q.leftCols(m);
  U = Q.rightCols(n - m);
}

double condition_number(const MatX& A) {
  if (A.size() == 0) return 1.0;  // the identity of nothing
  Eigen::BDCSVD<MatX> svd(A);
  const VecX& s = svd.singularValues();
  return s(0) / s(s.size() - 1);
}

VecX least_squares(const MatX& A, const VecX& b) {
  // No unknowns (a system without freedom) or no equations: the zero solution.
  if (A.rows() == 0 || A.cols() == 0) return VecX::Zero(A.cols());
  return A.colPivHouseholderQr().solve(b);
}

}  // namespace isoflex::solve
