// The augmented-Lagrangian saddle-point solver (solve/saddle_point.hpp) against a dense LU of the
// same matrix: hard rows, compliant rows, rows with the equation λ_i = b_i, a primal block that is
// indefinite but positive definite on the rows' null space, the kept analysis, and the failures
// the static solver falls back from.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <random>
#include <stdexcept>
#include <vector>

#include "isoflex/solve/saddle_point.hpp"

namespace isoflex::solve {
namespace {

struct Saddle {
  MatX dense;
  int p = 0;
  SpMat sparse() const {
    SpMat S = dense.sparseView();
    S.makeCompressed();
    return S;
  }
};

// A (p × p): a stiffness matrix (SPD, entries over four orders of magnitude), plus
// `shift` times its smallest eigenvalue on its diagonal (below −1: indefinite); B: `hard` rows on a
// few neighbouring columns, then `compliant` rows with Z = −c, then `fixed` rows with B = 0 and Z
// = 1.
Saddle make_saddle(int p, int hard, int compliant, int fixed, double shift, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  MatX A = MatX::Zero(p, p);
  for (int i = 0; i < p; ++i) {  // a chain of springs, each dof also on a spring to the ground
    const double k = i % 2 == 0 ? 1e4 : 1.0;  // membrane-like and bending-like stiffness
    A(i, i) += 0.1 * k;
    if (i + 1 == p) continue;
    A(i, i) += k;
    A(i + 1, i + 1) += k;
    A(i, i + 1) -= k;
    A(i + 1, i) -= k;
  }
  A.diagonal().array() += shift * Eigen::SelfAdjointEigenSolver<MatX>(A).eigenvalues().minCoeff();
  const int m = hard + compliant + fixed;
  MatX M = MatX::Zero(p + m, p + m);
  M.topLeftCorner(p, p) = A;
  for (int i = 0; i < hard + compliant; ++i) {
    const double scale = i % 3 == 0 ? 1e3 : 1.0;  // rows in different units
    for (int c = 0; c < 4; ++c) {
      const int j = (3 * i + c) % p;
      M(p + i, j) = M(j, p + i) = scale * u(gen);
    }
  }
  for (int i = hard; i < hard + compliant; ++i) M(p + i, p + i) = -1e-3 * (1.0 + 0.5 * u(gen));
  for (int i = hard + compliant; i < m; ++i) M(p + i, p + i) = 1.0;
  return {M, p};
}

VecX random_rhs(int n, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  VecX b(n);
  for (int i = 0; i < n; ++i) b(i) = u(gen);
  return b;
}

double relative_difference(const VecX& a, const VecX& b) {
  return (a - b).lpNorm<Eigen::Infinity>() / b.lpNorm<Eigen::Infinity>();
}

TEST(SaddlePointSolver, EqualsTheLuSolutionWithHardCompliantAndFixedRows) {
  const Saddle s = make_saddle(60, 12, 5, 3, 0.0, 1);
  const SpMat M = s.sparse();
  const VecX b = random_rhs(static_cast<int>(M.rows()), 2);
  const VecX expected = s.dense.fullPivLu().solve(b);
  SaddlePointSolver solver;
  solver.factorize(M, s.p);
  const VecX z = solver.solve(b);
  EXPECT_LT(relative_difference(z, expected), 1e-10);
  EXPECT_EQ(solver.last().hard_rows, 12);
  EXPECT_GT(solver.last().iterations, 0);
  EXPECT_LE(solver.last().backward_error, SaddlePointOptions{}.backward_error);
  // The fixed rows' equation λ_i = b_i, the compliant rows' B x − c λ = b.
  for (int i = 17; i < 20; ++i) EXPECT_NEAR(z(s.p + i), b(s.p + i), 1e-14);
  const double norm_M = s.dense.cwiseAbs().rowwise().sum().maxCoeff();
  EXPECT_LE((s.dense * z - b).lpNorm<Eigen::Infinity>() /
                (norm_M * z.lpNorm<Eigen::Infinity>() + b.lpNorm<Eigen::Infinity>()),
            SaddlePointOptions{}.backward_error);
}

TEST(SaddlePointSolver, SolvesAnIndefinitePrimalBlockThatTheRowsMakeDefinite) {
  // A has negative eigenvalues (the shift): the augmentation must make Â definite. 20 rows on 24
  // columns leave a null space on which A is definite here (checked below).
  const Saddle s = make_saddle(24, 20, 0, 0, -1.2, 3);
  Eigen::SelfAdjointEigenSolver<MatX> eig(s.dense.topLeftCorner(s.p, s.p));
  ASSERT_LT(eig.eigenvalues().minCoeff(), 0.0);
  const MatX Bh = s.dense.bottomLeftCorner(20, s.p);
  const MatX N = Eigen::FullPivLU<MatX>(Bh).kernel();
  ASSERT_GT(Eigen::SelfAdjointEigenSolver<MatX>(N.transpose() * s.dense.topLeftCorner(s.p, s.p) * N)
                .eigenvalues()
                .minCoeff(),
            0.0);
  const SpMat M = s.sparse();
  const VecX b = random_rhs(static_cast<int>(M.rows()), 4);
  SaddlePointSolver solver;
  solver.factorize(M, s.p);
  EXPECT_LT(relative_difference(solver.solve(b), s.dense.fullPivLu().solve(b)), 1e-10);
}

TEST(SaddlePointSolver, KeepsTheAnalysisForNewValuesOnTheSamePattern) {
  const Saddle s1 = make_saddle(40, 8, 2, 1, 0.0, 5);
  Saddle s2 = s1;
  s2.dense.topLeftCorner(s2.p, s2.p) *= 1.7;  // same pattern, new values
  SaddlePointSolver solver;
  for (const Saddle* s : {&s1, static_cast<const Saddle*>(&s2)}) {
    const SpMat M = s->sparse();
    const VecX b = random_rhs(static_cast<int>(M.rows()), 6);
    solver.factorize(M, s->p);
    EXPECT_LT(relative_difference(solver.solve(b), s->dense.fullPivLu().solve(b)), 1e-10);
  }
  EXPECT_EQ(solver.analyses(), 1);
}

// Â = A + Bᵀ W B (w_i = −1/Z_ii on the compliant and fixed rows, ρ_i on the hard ones), its
// pattern A's and every pair of columns of a row of B (whatever the values: a zero of B keeps
// its place), merged column by column without a map of A's values; new values on the same
// pattern go into the same arrays (PETSc keeps them, docs/theory/solvers.md §5).
TEST(SaddlePointSolver, AugmentedMatrixIsAPlusBtWBOnAFixedPattern) {
  Saddle s = make_saddle(30, 6, 3, 2, 0.0, 11);
  const int p = s.p, m = static_cast<int>(s.dense.rows()) - p;
  s.dense(p + 1, 3) = s.dense(3, p + 1) = 0.0;  // a zero of B: Â keeps its pairs
  SpMat M = s.sparse();
  M.coeffRef(p + 1, 3) = 0.0;  // stored zeros
  M.coeffRef(3, p + 1) = 0.0;
  M.makeCompressed();
  const auto expected = [&](const MatX& dense, const VecX& hard_w) {
    MatX A = dense.topLeftCorner(p, p);
    for (int i = 0, h = 0; i < m; ++i) {
      const double z = dense(p + i, p + i);
      const double w = z != 0.0 ? -1.0 / z : hard_w(h++);
      A += w * dense.row(p + i).head(p).transpose() * dense.row(p + i).head(p);
    }
    return A;
  };
  SaddlePointSolver solver;
  solver.augment(M, p);
  const SpMat& Ahat = solver.augmented_matrix();
  ASSERT_EQ(solver.hard_weights().size(), 6);
  const MatX A1 = expected(s.dense, solver.hard_weights());
  EXPECT_LT((MatX(Ahat) - A1).cwiseAbs().maxCoeff(), 1e-12 * A1.cwiseAbs().maxCoeff());
  // The pattern: A's entries, and the pairs of columns of each row of B, stored zeros included.
  MatX pattern = MatX::Zero(p, p);
  for (int j = 0; j < p; ++j)
    for (SpMat::InnerIterator it(M, j); it; ++it)
      if (it.row() < p) pattern(it.row(), j) = 1.0;
  for (int i = p; i < p + m; ++i) {
    std::vector<int> cols;
    for (int j = 0; j < p; ++j)
      if (M.coeff(i, j) != 0.0 || (i == p + 1 && j == 3)) cols.push_back(j);
    for (int a : cols)
      for (int b : cols) pattern(a, b) = 1.0;
  }
  EXPECT_EQ(Ahat.nonZeros(), static_cast<Eigen::Index>(pattern.sum()));
  for (int j = 0; j < p; ++j)
    for (SpMat::InnerIterator it(Ahat, j); it; ++it) EXPECT_EQ(pattern(it.row(), j), 1.0);
  // New values, the same pattern: the same arrays, the new Â.
  const double* values = Ahat.valuePtr();
  const int* inner = Ahat.innerIndexPtr();
  Saddle s2 = s;
  s2.dense.topLeftCorner(p, p) *= 2.5;
  SpMat M2 = M;
  for (int j = 0; j < p; ++j)
    for (SpMat::InnerIterator it(M2, j); it; ++it)
      if (it.row() < p) it.valueRef() *= 2.5;
  solver.augment(M2, p);
  EXPECT_EQ(solver.augmented_matrix().valuePtr(), values);
  EXPECT_EQ(solver.augmented_matrix().innerIndexPtr(), inner);
  const MatX A2 = expected(s2.dense, solver.hard_weights());
  EXPECT_LT((MatX(solver.augmented_matrix()) - A2).cwiseAbs().maxCoeff(),
            1e-12 * A2.cwiseAbs().maxCoeff());
}

// A caller that names M's patterns (the static solver's pattern version): the same key takes
// the pattern as it is (no copy of it kept) and fills the new values; a new key, a new pattern.
TEST(SaddlePointSolver, AugmentsByThePatternKeyOfTheCaller) {
  const Saddle s1 = make_saddle(30, 6, 3, 2, 0.0, 13);
  Saddle s2 = s1;
  s2.dense.topLeftCorner(s2.p, s2.p) *= 0.5;  // new values, the same pattern
  Saddle s3 = make_saddle(30, 6, 3, 2, 0.0, 14);
  s3.dense(s3.p + 2, 17) = s3.dense(17, s3.p + 2) = 0.25;  // another pattern
  SaddlePointSolver keyed, compared;
  const std::vector<std::pair<const Saddle*, long>> calls{{&s1, 1}, {&s2, 1}, {&s3, 2}};
  const double* first_values = nullptr;
  for (const auto& [s, key] : calls) {
    const SpMat M = s->sparse();
    keyed.augment(M, s->p, key);
    compared.augment(M, s->p);
    const SpMat& A = keyed.augmented_matrix();
    const SpMat& B = compared.augmented_matrix();
    ASSERT_EQ(A.nonZeros(), B.nonZeros()) << key;
    EXPECT_TRUE(std::equal(A.innerIndexPtr(), A.innerIndexPtr() + A.nonZeros(), B.innerIndexPtr()));
    EXPECT_TRUE(std::equal(A.valuePtr(), A.valuePtr() + A.nonZeros(), B.valuePtr()));
    if (s == &s1) first_values = A.valuePtr();
    if (s == &s2) {
      EXPECT_EQ(A.valuePtr(), first_values);  // the same arrays
    }
  }
}

TEST(SaddlePointSolver, RefusesWhatTheStaticSolverMustSolveOtherwise) {
  SaddlePointSolver solver;
  Saddle coupled = make_saddle(20, 4, 0, 0, 0.0, 7);
  coupled.dense(20, 21) = coupled.dense(21, 20) = 1.0;  // multiplier block not diagonal
  const SpMat C = coupled.sparse();
  EXPECT_THROW(solver.factorize(C, coupled.p), std::runtime_error);
  // A indefinite on the rows' null space: no augmentation makes Â definite.
  const Saddle unstable = make_saddle(20, 2, 0, 0, -3.0, 8);
  const SpMat U = unstable.sparse();
  EXPECT_THROW(solver.factorize(U, unstable.p), std::runtime_error);
  // A row on no stiffness: a zero row with no equation of its own.
  Saddle empty = make_saddle(20, 3, 0, 0, 0.0, 9);
  empty.dense.row(22).setZero();
  empty.dense.col(22).setZero();
  const SpMat E = empty.sparse();
  EXPECT_THROW(solver.factorize(E, empty.p), std::runtime_error);
}

}  // namespace
}  // namespace isoflex::solve
