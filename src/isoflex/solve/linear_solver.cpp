#include "isoflex/solve/linear_solver.hpp"

#include <Eigen/Dense>
#include <Eigen/SparseLU>
#include <algorithm>
#include <stdexcept>

namespace isoflex::solve {

VecX solve(const SpMat& A, const VecX& b) {
  const double density = double(A.nonZeros()) / (double(A.rows()) * double(A.cols()));
  if (A.rows() <= 64 || density > 0.15) {
    // Dense enough that a dense LU beats the sparse one.
    const MatX dense(A);
    const Eigen::PartialPivLU<MatX> lu(dense);
    VecX x = lu.solve(b);
    if (!x.allFinite()) throw std::runtime_error("singular Newton matrix");
    return x;
  }
  Eigen::SparseLU<SpMat, Eigen::COLAMDOrdering<int>> lu;
  lu.analyzePattern(A);
  lu.factorize(A);
  if (lu.info() != Eigen::Success) throw std::runtime_error("singular Newton matrix (sparse LU)");
  VecX x = lu.solve(b);
  if (!x.allFinite()) throw std::runtime_error("singular Newton matrix");
  return x;
}

std::vector<int> independent_rows_lu(const MatX& G, double threshold) {
  if (G.rows() == 0) return {};
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
  if (G.rows() == 0) return {};
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
  Eigen::HouseholderQR<MatX> qr(G.transpose());
  const MatX Q = qr.householderQ() * MatX::Identity(n, n);
  W = Q.leftCols(m);
  U = Q.rightCols(n - m);
}

double condition_number(const MatX& A) {
  Eigen::BDCSVD<MatX> svd(A);
  const VecX& s = svd.singularValues();
  return s(0) / s(s.size() - 1);
}

VecX least_squares(const MatX& A, const VecX& b) {
  return A.colPivHouseholderQr().solve(b);
}

}  // namespace isoflex::solve
