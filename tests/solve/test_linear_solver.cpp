#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <random>
#include <string>

#include "isoflex/solve/linear_solver.hpp"
#include "support/finite_difference.hpp"

using namespace isoflex;

// AddressSanitizer reserves terabytes of shadow address space: no address-space limit under it
// (GCC defines __SANITIZE_ADDRESS__, clang has __has_feature(address_sanitizer)).
#include "support/sanitizers.hpp"
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

// The 64-bit interfaces (umfpack_dl_*, cholmod_l_*) give the numbers of the 32-bit ones: the
// same orderings and the same floating-point operations, only the index type differs.
TEST(FixedPatternLU, LongIndicesGiveTheSameSolution) {
  std::mt19937 g(5);
  solve::FixedPatternLU lu32(solve::IndexWidth::int32), lu64(solve::IndexWidth::int64);
  for (double skew : {0.3, -0.2}) {
    const SpMat A = grid_matrix(40, 0.1, skew);
    const VecX b = test::random_vector(g, A.rows());
    const VecX x32 = lu32.solve(A, b), x64 = lu64.solve(A, b);
    EXPECT_FALSE(lu32.used_long_indices());
    EXPECT_TRUE(lu64.used_long_indices());
    EXPECT_LE((x64 - x32).norm(), 1e-15 * x32.norm()) << "skew " << skew;
    EXPECT_LT(relative_error(A, x64, b), 1e-13);
  }
  EXPECT_EQ(lu64.analyses(), 1);  // the 64-bit path keeps its analysis too
  // automatic: 64-bit from kLongIndexUnknowns unknowns on, 32-bit below.
  solve::FixedPatternLU lu;
  lu.solve(grid_matrix(40, 0.1, 0.3), VecX::Ones(1600));
  EXPECT_FALSE(lu.used_long_indices());
  const SpMat big = grid_matrix(150, 0.1, 0.3);
  ASSERT_GE(big.rows(), solve::kLongIndexUnknowns);
  const VecX b = VecX::Ones(big.rows());
  const VecX x = lu.solve(big, b);
  EXPECT_TRUE(lu.used_long_indices());
  EXPECT_LT((big * x - b).norm(), 1e-12 * b.norm());
}

TEST(FixedPatternCholesky, LongIndicesGiveTheSameSolution) {
  std::mt19937 g(6);
  solve::FixedPatternCholesky c32(solve::IndexWidth::int32), c64(solve::IndexWidth::int64);
  const SpMat A = grid_matrix(40, 0.1, 0.0);
  const VecX b = test::random_vector(g, A.rows());
  const VecX x32 = c32.solve(A, b), x64 = c64.solve(A, b);
  EXPECT_TRUE(c64.used_long_indices());
  EXPECT_LE((x64 - x32).norm(), 1e-15 * x32.norm());
  EXPECT_LT(relative_error(A, x64, b), 1e-13);
  EXPECT_THROW(c64.solve(grid_matrix(40, -8.5, 0.0), b), std::runtime_error);  // indefinite
}

namespace {
// In a child process whose address space is limited to what it uses now plus `headroom` bytes:
// factorizes the 300 × 300 grid (90 000 unknowns, an LU of ~300 MB) and exits 0 if that threw
// solve::OutOfMemory with `expected` in its message, 1 for another exception, 2 if it solved.
template <class Solver>
int factorize_with_little_memory(double shift, const std::string& expected) {
  const SpMat A = grid_matrix(300, shift, 0.0);
  const VecX b = VecX::Ones(A.rows());
  const pid_t pid = fork();
  if (pid == 0) {
    std::ifstream statm("/proc/self/statm");
    long pages = 0;
    statm >> pages;
    const rlim_t limit = static_cast<rlim_t>(pages) * sysconf(_SC_PAGESIZE) + (40 << 20);
    const rlimit r{limit, limit};
    setrlimit(RLIMIT_AS, &r);
    try {
      Solver s;
      s.solve(A, b);
      _exit(2);
    } catch (const solve::OutOfMemory& e) {
      _exit(std::string(e.what()).find(expected) != std::string::npos ? 0 : 1);
    } catch (...) {
      _exit(1);
    }
  }
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}
}  // namespace

// UMFPACK_ERROR_out_of_memory (or a std::bad_alloc inside the factorization) is reported as out
// of memory, with the unknowns — it was "singular Newton matrix (sparse LU)" (issue #15).
TEST(FixedPatternLU, OutOfMemoryIsReportedAsSuch) {
#if defined(ISOFLEX_TEST_ASAN)
  GTEST_SKIP() << "RLIMIT_AS and AddressSanitizer do not mix";
#endif
  EXPECT_EQ(factorize_with_little_memory<solve::FixedPatternLU>(
                0.1, "out of memory in the sparse LU (UMFPACK) at 90000 unknowns"),
            0);
  EXPECT_EQ(factorize_with_little_memory<solve::FixedPatternCholesky>(
                0.1, "in the sparse Cholesky factorization (CHOLMOD) at 90000 unknowns"),
            0);
}

// leading_rows_lu: the rows of the largest pivots, as many as asked, whatever their rank — a row
// that is small (a pivot far below the others) goes first when fewer are asked for.
TEST(LinearSolver, LeadingRowsAreThoseOfTheLargestPivots) {
  MatX G(4, 3);
  G << 1, 0, 0,    // large
      1e-9, 1, 0,  // large after elimination
      0, 0, 1e-6,  // small pivot
      2, 0, 0;     // the largest entry, dependent on row 0
  EXPECT_EQ(solve::leading_rows_lu(G, 2), (std::vector<int>{1, 3}));
  EXPECT_EQ(solve::leading_rows_lu(G, 3), (std::vector<int>{1, 2, 3}));
  EXPECT_EQ(solve::leading_rows_lu(G, 9).size(), 4u);
  EXPECT_TRUE(solve::leading_rows_lu(G, 0).empty());
  EXPECT_TRUE(solve::leading_rows_lu(MatX(5, 0), 2).empty());
}
