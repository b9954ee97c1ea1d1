#include "isoflex/solve/normal_equations.hpp"

#include <gtest/gtest.h>

#include <random>

#include "support/finite_difference.hpp"

using namespace isoflex;
using SpMat = solve::NormalEquations::SpMat;

namespace {
// A banded m × n matrix (m < n) of full row rank with random entries; `drop` zeroes one entry.
SpMat banded(int m, int n, std::mt19937& g, bool drop = false) {
  std::vector<Eigen::Triplet<double>> t;
  std::uniform_real_distribution<double> u(0.5, 1.5);
  for (int i = 0; i < m; ++i)
    for (int j = i; j < std::min(n, i + 3); ++j)
      if (!(drop && i == 2 && j == 4)) t.emplace_back(i, j, j == i ? 4.0 + u(g) : u(g));
  SpMat G(m, n);
  G.setFromTriplets(t.begin(), t.end());
  return G;
}
}  // namespace

TEST(NormalEquations, MatchesDenseSolveAndReusesTheOrdering) {
  std::mt19937 g(1);
  solve::NormalEquations ne;
  for (int trial = 0; trial < 3; ++trial) {
    const SpMat G = banded(20, 30, g);
    const VecX rhs = test::random_vector(g, 20);
    const MatX D(G);
    const VecX expected = (D * D.transpose()).ldlt().solve(rhs);
    EXPECT_LT((ne.solve(G, rhs) - expected).norm() / expected.norm(), 1e-13);
  }
  EXPECT_EQ(ne.analyses(), 1);
  // A changed pattern is analysed again.
  const SpMat G = banded(20, 30, g, true);
  const VecX rhs = test::random_vector(g, 20);
  const MatX D(G);
  EXPECT_LT((ne.solve(G, rhs) - (D * D.transpose()).ldlt().solve(rhs)).norm(), 1e-12);
  EXPECT_EQ(ne.analyses(), 2);
}

TEST(NormalEquations, RankDeficientJacobianThrows) {
  SpMat G(2, 3);
  G.insert(0, 0) = 1.0;
  G.insert(1, 0) = 2.0;
  solve::NormalEquations ne;
  EXPECT_THROW(ne.solve(G, VecX::Ones(2)), std::runtime_error);
}
