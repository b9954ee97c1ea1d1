#include <gtest/gtest.h>

#include <random>

#include "isoflex/solve/normal_equations.hpp"
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

// G of full rank whose G Gᵀ is singular in floating point (1 + 1e18 rounds to 1e18): a joint 1e9
// from its body. Solved through a QR of Gᵀ (it threw "rank deficient" before, #15).
TEST(NormalEquations, FullRankGWithSingularGGtIsSolved) {
  MatX Gd(2, 2);
  Gd << 1.0, 1e9, 0.0, 1e9;
  const SpMat G = Gd.sparseView();
  const VecX y = VecX::Ones(2);
  solve::NormalEquations ne;
  const VecX lambda = ne.solve(G, G * y);
  EXPECT_TRUE(lambda.allFinite());
  EXPECT_EQ(ne.fallbacks(), 1);
  // G y = G Gᵀ λ has the solution λ = G⁻ᵀ y (G square and invertible): λ = (1, -1 + 1e-9).
  EXPECT_NEAR(lambda(0), 1.0, 1e-6);
  EXPECT_NEAR(lambda(1), -1.0 + 1e-9, 1e-6);
}
