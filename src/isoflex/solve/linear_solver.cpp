#include "isoflex/solve/linear_solver.hpp"

#include <Eigen/CholmodSupport>
#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <Eigen/UmfPackSupport>
#include <algorithm>
#include <stdexcept>

namespace isoflex::solve {

namespace {
bool use_dense(const SpMat& A);

// Numeric LU of A (pattern analysed already) and the solution of A x = b.
VecX factorize_and_solve(Eigen::UmfPackLU<SpMat>& lu, const SpMat& A, const VecX& b) {
  lu.factorize(A);
  if (lu.info() != Eigen::Success) throw std::runtime_error("singular Newton matrix (sparse LU)");
  VecX x = lu.solve(b);
  if (!x.allFinite()) throw std::runtime_error("singular Newton matrix");
  return x;
}
}  // namespace

VecX solve(const SpMat& A, const VecX& b) {
  if (use_dense(A)) {
    // Dense enough that a dense LU beats the sparse one.
    const MatX dense(A);
    const Eigen::PartialPivLU<MatX> lu(dense);
    VecX x = lu.solve(b);
    if (!x.allFinite()) throw std::runtime_error("singular Newton matrix");
    return x;
  }
  Eigen::UmfPackLU<SpMat> lu;
  lu.analyzePattern(A);
  return factorize_and_solve(lu, A, b);
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

// Runs solver.analyzePattern(A) unless the compressed A has the kept pattern, and then keeps
// A's pattern.
template <class Solver>
void analyze_if_new_pattern(Solver& solver, KeptPattern& kept, const SpMat& A) {
  const int* o = A.outerIndexPtr();
  const int* i = A.innerIndexPtr();
  const bool same = kept.rows == A.rows() &&
                    kept.outer.size() == static_cast<std::size_t>(A.outerSize() + 1) &&
                    kept.inner.size() == static_cast<std::size_t>(A.nonZeros()) &&
                    std::equal(kept.outer.begin(), kept.outer.end(), o) &&
                    std::equal(kept.inner.begin(), kept.inner.end(), i);
  if (same) return;
  solver.analyzePattern(A);
  kept.outer.assign(o, o + A.outerSize() + 1);
  kept.inner.assign(i, i + A.nonZeros());
  kept.rows = static_cast<int>(A.rows());
  ++kept.analyses;
}
}  // namespace

struct FixedPatternLU::Impl {
  Eigen::UmfPackLU<SpMat> lu;
  KeptPattern pattern;
};

FixedPatternLU::FixedPatternLU() : impl_(std::make_unique<Impl>()) {}
FixedPatternLU::~FixedPatternLU() = default;
FixedPatternLU::FixedPatternLU(FixedPatternLU&&) noexcept = default;
FixedPatternLU& FixedPatternLU::operator=(FixedPatternLU&&) noexcept = default;
int FixedPatternLU::analyses() const {
  return impl_->pattern.analyses;
}

VecX FixedPatternLU::solve(const SpMat& A, const VecX& b) {
  if (!A.isCompressed()) throw std::logic_error("FixedPatternLU: matrix not compressed");
  if (use_dense(A)) return solve::solve(A, b);
  Impl& m = *impl_;
  analyze_if_new_pattern(m.lu, m.pattern, A);
  return factorize_and_solve(m.lu, A, b);
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
  analyze_if_new_pattern(m.ldlt, m.pattern, A);
  m.ldlt.factorize(A);
  if (m.ldlt.info() != Eigen::Success) throw std::runtime_error("matrix not positive definite");
  return m.ldlt.solve(b);
}

struct FixedPatternCholesky::Impl {
  Eigen::CholmodSupernodalLLT<SpMat, Eigen::Lower> llt;
  KeptPattern pattern;
};

FixedPatternCholesky::FixedPatternCholesky() : impl_(std::make_unique<Impl>()) {
  // An indefinite matrix is reported by the exception (callers fall back to LU), not printed.
  impl_->llt.cholmod().print = 0;
  impl_->llt.cholmod().quick_return_if_not_posdef = 1;
}
FixedPatternCholesky::~FixedPatternCholesky() = default;
FixedPatternCholesky::FixedPatternCholesky(FixedPatternCholesky&&) noexcept = default;
FixedPatternCholesky& FixedPatternCholesky::operator=(FixedPatternCholesky&&) noexcept = default;
int FixedPatternCholesky::analyses() const {
  return impl_->pattern.analyses;
}

VecX FixedPatternCholesky::solve(const SpMat& A, const VecX& b) {
  if (!A.isCompressed()) throw std::logic_error("FixedPatternCholesky: matrix not compressed");
  Impl& m = *impl_;
  analyze_if_new_pattern(m.llt, m.pattern, A);
  m.llt.factorize(A);
  if (m.llt.info() != Eigen::Success) throw std::runtime_error("matrix not positive definite");
  VecX x = m.llt.solve(b);
  if (!x.allFinite()) throw std::runtime_error("matrix not positive definite");
  return x;
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
