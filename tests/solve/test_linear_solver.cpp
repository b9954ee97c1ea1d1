#include <gtest/gtest.h>

#include <random>

#include "isoflex/solve/linear_solver.hpp"
#include "support/finite_difference.hpp"

using namespace isoflex;
using solve::SpMat;

namespace {
// The 5-point Laplacian of an N × N grid plus `shift` on the diagonal (SPD for shift ≥ 0) and,
// if `skew` ≠ 0, an antisymmetric part on the off-diagonals (structurally symmetric, unsymmetric
// values, like an energy–momentum Newton matrix). Large enough (N² > 64) for the sparse path.
SpMat grid_matrix(int N, double shift, double skew) {
  std::vector<Eigen::Triplet<double>> t;
  auto id = [N](int i, int j) { return i + N * j; };
  for (int j = 0; j < N; ++j)
    for (int i = 0; i < N; ++i) {
      t.emplace_back(id(i, j), id(i, j), 4.0 + shift);
      if (i + 1 < N) {
        t.emplace_back(id(i, j), id(i + 1, j), -1.0 + skew);
        t.emplace_back(id(i + 1, j), id(i, j), -1.0 - skew);
      }
      if (j + 1 < N) {
        t.emplace_back(id(i, j), id(i, j + 1), -1.0 - skew);
        t.emplace_back(id(i, j + 1), id(i, j), -1.0 + skew);
      }
    }
  SpMat A(N * N, N * N);
  A.setFromTriplets(t.begin(), t.end());
  return A;
}

double relative_error(const SpMat& A, const VecX& x, const VecX& b) {
  const VecX expected = MatX(A).partialPivLu().solve(b);
  return (x - expected).norm() / expected.norm();
}
}  // namespace

TEST(FixedPatternLU, MatchesDenseSolveAndKeepsTheAnalysis) {
  std::mt19937 g(3);
  solve::FixedPatternLU lu;
  for (double skew : {0.3, -0.2, 0.7}) {
    const SpMat A = grid_matrix(12, 0.1, skew);
    const VecX b = test::random_vector(g, A.rows());
    EXPECT_LT(relative_error(A, lu.solve(A, b), b), 1e-13) << "skew " << skew;
  }
  EXPECT_EQ(lu.analyses(), 1);
  EXPECT_LT(
      relative_error(grid_matrix(13, 0.1, 0.3),
                     solve::solve(grid_matrix(13, 0.1, 0.3), VecX::Ones(169)), VecX::Ones(169)),
      1e-13);
  const SpMat other = grid_matrix(11, 0.0, 0.1);
  lu.solve(other, VecX::Ones(other.rows()));
  EXPECT_EQ(lu.analyses(), 2);
}

TEST(FixedPatternLU, SingularMatrixThrows) {
  SpMat A = grid_matrix(10, 0.0, 0.0);
  // Row and column 5 zero: singular.
  for (int k = 0; k < A.outerSize(); ++k)
    for (SpMat::InnerIterator it(A, k); it; ++it)
      if (it.row() == 5 || it.col() == 5) it.valueRef() = 0.0;
  solve::FixedPatternLU lu;
  EXPECT_THROW(lu.solve(A, VecX::Ones(A.rows())), std::runtime_error);
}

TEST(FixedPatternCholesky, MatchesDenseSolveAndRejectsIndefinite) {
  std::mt19937 g(4);
  solve::FixedPatternCholesky llt;
  for (double shift : {0.0, 0.5, 2.0}) {
    const SpMat A = grid_matrix(15, shift, 0.0);
    const VecX b = test::random_vector(g, A.rows());
    EXPECT_LT(relative_error(A, llt.solve(A, b), b), 1e-13) << "shift " << shift;
  }
  EXPECT_EQ(llt.analyses(), 1);
  EXPECT_THROW(llt.solve(grid_matrix(15, -4.5, 0.0), VecX::Ones(225)), std::runtime_error);
}

// Empty problems (a system without freedom: no tree coordinates, or no null space left) give
// empty answers; Eigen's decompositions assert on empty matrices (#15).
TEST(LinearSolver, EmptyMatricesGiveEmptyAnswers) {
  EXPECT_EQ(solve::least_squares(MatX(6, 0), VecX::Ones(6)).size(), 0);
  EXPECT_EQ(solve::least_squares(MatX(0, 3), VecX(0)), VecX::Zero(3));
  EXPECT_TRUE(solve::independent_rows_lu(MatX(5, 0)).empty());
  EXPECT_TRUE(solve::independent_rows_qr(MatX(5, 0)).empty());
  MatX W, U;
  solve::qr_range_and_null_space(MatX(0, 4), W, U);
  EXPECT_EQ(W.rows(), 4);
  EXPECT_EQ(W.cols(), 0);
  EXPECT_EQ(U, MatX::Identity(4, 4));
}
