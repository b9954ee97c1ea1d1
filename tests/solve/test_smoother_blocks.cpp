// The smoother's blocks (solve/smoother_blocks.hpp): about the block size each, every row in one,
// and no cut through a band of stiff coupling (a bending strip), which a block border would leave
// unrelaxed.
#include <gtest/gtest.h>

#include <numeric>
#include <vector>

#include "isoflex/solve/smoother_blocks.hpp"

using isoflex::solve::CsrView;
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
