// The sparse-pattern helpers (math/sparse_pattern.hpp): a pattern built column by column is the
// one setFromTriplets gives, a structure copy keeps the structure, and the fingerprint tells
// patterns apart.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "isoflex/math/sparse_pattern.hpp"

using SpMat = Eigen::SparseMatrix<double>;

namespace {

// A random 40 × 30 pattern with repeated entries; its columns' rows as lists, in random order.
std::vector<std::vector<int>> random_columns() {
  std::mt19937 g(5);
  std::uniform_int_distribution<int> row(0, 39), count(0, 12);
  std::vector<std::vector<int>> columns(30);
  for (auto& c : columns)
    for (int k = count(g); k > 0; --k) c.push_back(row(g));
  return columns;
}

SpMat by_triplets(const std::vector<std::vector<int>>& columns) {
  std::vector<Eigen::Triplet<double>> t;
  for (int j = 0; j < static_cast<int>(columns.size()); ++j)
    for (int i : columns[static_cast<std::size_t>(j)]) t.emplace_back(i, j, 1.0);
  SpMat P(40, static_cast<Eigen::Index>(columns.size()));
  P.setFromTriplets(t.begin(), t.end());
  P.makeCompressed();
  return P;
}

bool same_structure(const SpMat& a, const SpMat& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() && isoflex::has_pattern(a, b) &&
         std::equal(a.innerIndexPtr(), a.innerIndexPtr() + a.nonZeros(), b.innerIndexPtr());
}

}  // namespace

TEST(SparsePattern, ByColumnsIsTheTripletsPatternWithZeroValues) {
  const auto columns = random_columns();
  const SpMat expected = by_triplets(columns);
  SpMat P(3, 3);  // storage to be replaced
  P.insert(1, 1) = 7.0;
  isoflex::pattern_by_columns(
      40, 30,
      [&](int c, std::vector<int>& out) {
        const auto& rows = columns[static_cast<std::size_t>(c)];
        out.insert(out.end(), rows.begin(), rows.end());
      },
      P);
  EXPECT_TRUE(same_structure(P, expected));
  EXPECT_GT(P.nonZeros(), 100);
  for (Eigen::Index k = 0; k < P.nonZeros(); ++k) EXPECT_EQ(P.valuePtr()[k], 0.0);
}

TEST(SparsePattern, CopyStructureKeepsIndicesAndSize) {
  const SpMat P = by_triplets(random_columns());
  SpMat K(2, 5);
  isoflex::copy_structure(P, K);
  EXPECT_TRUE(same_structure(K, P));
}

TEST(SparsePattern, FingerprintTellsPatternsApart) {
  const auto columns = random_columns();
  const SpMat P = by_triplets(columns);
  SpMat same = P;
  for (Eigen::Index k = 0; k < same.nonZeros(); ++k) same.valuePtr()[k] = 3.0 * k;  // values only
  EXPECT_EQ(isoflex::pattern_fingerprint(same), isoflex::pattern_fingerprint(P));
  // One entry moved within its column (its first row to row 0, free above it): the same outer
  // index and count, another pattern.
  SpMat moved = P;
  int column = 0;
  while (column < P.cols() && (P.outerIndexPtr()[column + 1] == P.outerIndexPtr()[column] ||
                               P.innerIndexPtr()[P.outerIndexPtr()[column]] == 0))
    ++column;
  ASSERT_LT(column, P.cols());
  moved.innerIndexPtr()[moved.outerIndexPtr()[column]] = 0;
  EXPECT_NE(isoflex::pattern_fingerprint(moved), isoflex::pattern_fingerprint(P));
  // Another size with the same indices.
  SpMat taller = P;
  taller.conservativeResize(41, P.cols());
  EXPECT_NE(isoflex::pattern_fingerprint(taller), isoflex::pattern_fingerprint(P));
}
