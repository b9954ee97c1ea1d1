// Cuts of a matrix's rows (solve/row_cuts.hpp): the smoother's blocks, about the block size each,
// and the MPI ranks' rows, equal shares; every row in one, and no cut through a band of stiff
// coupling (a bending strip, AF-D's interface), which a block or rank border would leave
// unrelaxed.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <vector>

#include "isoflex/solve/row_cuts.hpp"

using isoflex::solve::CsrView;
using isoflex::solve::CutWeights;
using isoflex::solve::rank_borders;
using isoflex::solve::smoother_blocks;

namespace {

// A symmetric band matrix in CSR (both triangles): rows i, i ± 1 … i ± reach coupled with weight
// 1, and with `stiff` where both rows lie in [from, to).
struct Band {
  std::vector<int> row_start{0}, columns;
  std::vector<double> values;
  CsrView view() const {
    return {static_cast<int>(row_start.size()) - 1, 0, row_start.data(), columns.data(),
            values.data()};
  }
};

Band band(int n, int reach, int from, int to, double stiff) {
  Band b;
  for (int i = 0; i < n; ++i) {
    for (int j = std::max(0, i - reach); j <= std::min(n - 1, i + reach); ++j) {
      b.columns.push_back(j);
      const bool in = i >= from && i < to && j >= from && j < to;
      b.values.push_back(i == j ? 10.0 * reach : (in ? -stiff : -1.0));
    }
    b.row_start.push_back(static_cast<int>(b.columns.size()));
  }
  return b;
}

std::vector<double> weights(const Band& b) {
  CutWeights w(static_cast<int>(b.row_start.size()) - 1);
  w.add(b.view());
  return w.weights();
}

std::vector<int> cuts(const std::vector<int>& lengths) {
  std::vector<int> c;
  int at = 0;
  for (std::size_t k = 0; k + 1 < lengths.size(); ++k) c.push_back(at += lengths[k]);
  return c;
}

}  // namespace

// Without a heavy cut the blocks are PETSc's equal ones (the empty answer).
TEST(SmootherBlocks, LeaveEqualBlocksWhereNoCutIsHeavy) {
  EXPECT_TRUE(smoother_blocks(band(10000, 3, 0, 0, 1.0).view(), 1000).empty());
  EXPECT_TRUE(smoother_blocks(band(10000, 3, 2000, 2100, 1000.0).view(), 1000).empty());
  EXPECT_TRUE(smoother_blocks(band(1900, 3, 900, 1100, 1000.0).view(), 1000).empty());  // 1 block
}

// A stiff band narrower than a block where equal blocks would cut it (at 1000), and one wider than
// a block: no cut falls inside either.
TEST(SmootherBlocks, DoNotCutAStiffBand) {
  for (const auto& [from, to] : {std::pair{950, 1100}, std::pair{4700, 6300}}) {
    const Band b = band(10000, 3, from, to, 1000.0);
    const std::vector<int> lengths = smoother_blocks(b.view(), 1000);
    ASSERT_FALSE(lengths.empty());
    EXPECT_EQ(std::accumulate(lengths.begin(), lengths.end(), 0), 10000);
    for (int l : lengths) EXPECT_GT(l, 0);
    for (int c : cuts(lengths)) EXPECT_TRUE(c <= from || c >= to) << "cut at " << c;
  }
}

// The weight of a cut is the sum of |A_ij| across it: on a band of reach 3 with unit entries off
// the diagonal, 1 + 2 + 3 = 6 entries above the diagonal cross each inner cut (both triangles
// given, the upper one counted).
TEST(RowCuts, WeighTheEntriesAcrossTheCut) {
  const std::vector<double> w = weights(band(100, 3, 0, 0, 1.0));
  EXPECT_EQ(w.size(), 101u);
  EXPECT_EQ(w[0], 0.0);
  EXPECT_EQ(w[1], 3.0);
  EXPECT_EQ(w[50], 6.0);
  EXPECT_EQ(w[100], 0.0);
  const std::vector<double> stiff = weights(band(100, 3, 40, 60, 1000.0));
  EXPECT_EQ(stiff[50], 6000.0);
  EXPECT_EQ(stiff[40], 6.0);
}

// Without heavy coupling at a border the ranks own equal shares, the first ones the shorter (as
// the rows were shared before the borders followed the matrix).
TEST(RankBorders, AreEqualSharesWhereNoBorderIsHeavy) {
  const std::vector<double> w = weights(band(10001, 3, 2000, 2100, 1000.0));
  EXPECT_EQ(rank_borders(w, 1), (std::vector<int>{0, 10001}));
  EXPECT_EQ(rank_borders(w, 2), (std::vector<int>{0, 5000, 10001}));
  EXPECT_EQ(rank_borders(w, 3), (std::vector<int>{0, 3333, 6667, 10001}));
}

// A stiff band where the equal border of two (of four) ranks falls lies within one rank; a band
// wider than the reach (a quarter of a share) leaves the shares equal.
TEST(RankBorders, KeepAStiffBandWithinOneRank) {
  for (const int ranks : {2, 4}) {
    const Band b = band(10000, 3, 4900, 5200, 1000.0);
    const std::vector<int> borders = rank_borders(weights(b), ranks);
    ASSERT_EQ(borders.size(), static_cast<std::size_t>(ranks) + 1);
    EXPECT_EQ(borders.front(), 0);
    EXPECT_EQ(borders.back(), 10000);
    for (int r = 0; r < ranks; ++r) EXPECT_LT(borders[r], borders[r + 1]);
    for (int c : borders) EXPECT_TRUE(c <= 4900 || c >= 5200) << "border at " << c;
    EXPECT_NE(std::find(borders.begin(), borders.end(), 4900), borders.end());
  }
  const std::vector<int> wide = rank_borders(weights(band(10000, 3, 3000, 7000, 1000.0)), 2);
  EXPECT_EQ(wide, (std::vector<int>{0, 5000, 10000}));
}

// A cut is heavy from 3 × the median cut: in a band whose entries are 4 × the others' the cuts
// weigh 24 against a median of 6 (4 ×, as AF-D's interface at 3.5 ×), and the border of two ranks
// and a block's end move to light cuts (at most 18); in a band of 2.5 × (cuts of 15) they stay.
TEST(RankBorders, MoveOffABandOfThreeTimesTheMedianCut) {
  const Band mild = band(10000, 3, 4950, 5100, 4.0);
  const std::vector<double> w = weights(mild);
  ASSERT_EQ(w[5000], 24.0);
  const std::vector<int> borders = rank_borders(w, 2);
  EXPECT_NE(borders[1], 5000);
  EXPECT_LE(w[static_cast<std::size_t>(borders[1])], 18.0) << "border at " << borders[1];
  const std::vector<int> lengths = smoother_blocks(mild.view(), 1000);
  ASSERT_FALSE(lengths.empty());
  for (int c : cuts(lengths)) EXPECT_LE(w[static_cast<std::size_t>(c)], 18.0) << "cut at " << c;
  const Band milder = band(10000, 3, 4950, 5100, 2.5);
  EXPECT_EQ(rank_borders(weights(milder), 2), (std::vector<int>{0, 5000, 10000}));
  EXPECT_TRUE(smoother_blocks(milder.view(), 1000).empty());
}
