#include <gtest/gtest.h>

#include <string>

#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/io/model_reader.hpp"
#include "support/models.hpp"

using namespace isoflex;
using integrate::EnergyMomentumIntegrator;
using integrate::ReducedSolve;

namespace {

model::Model slider_crank() {
  return io::read_model(std::string(ISOFLEX_SOURCE_DIR) +
                        "/examples/slider_crank_flexible/model.yaml");
}

// Max |A − B| relative to max |A|.
double relative_difference(const MatX& A, const MatX& B) {
  return (A - B).lpNorm<Eigen::Infinity>() / std::max(1e-300, A.lpNorm<Eigen::Infinity>());
}

// The block-assembled residual and Newton matrix equal the explicit 𝖯ᵀ r₀ and 𝖯ᵀ K̂ F′ at random
// unknowns, at the first step and after a few steps (nonzero velocities).
void expect_same_newton_matrix(const model::Model& m, int steps_before, double scale) {
  const auto sys = system::System::compile(m);
  EnergyMomentumIntegrator a(sys, m.solver, ReducedSolve::explicit_null_space);
  EnergyMomentumIntegrator b(sys, m.solver, ReducedSolve::blocks);
  ASSERT_FALSE(a.block_assembly());
  ASSERT_TRUE(b.block_assembly());
  auto s = b.initial_state();
  for (int i = 0; i < steps_before; ++i) b.step(s);
  std::srand(7);
  for (int trial = 0; trial < 3; ++trial) {
    const VecX x = b.start_unknowns(s) + scale * VecX::Random(sys.k());
    MatX Ja, Jb;
    const VecX Ra = a.residual(s, x, &Ja), Rb = b.residual(s, x, &Jb);
    ASSERT_EQ(Ja.rows(), Jb.rows());
    ASSERT_EQ(Ja.cols(), Jb.cols());
    EXPECT_LT(relative_difference(Ja, Jb), 1e-12) << m.name << " trial " << trial;
    EXPECT_LT((Ra - Rb).lpNorm<Eigen::Infinity>(),
              1e-12 * std::max(1.0, Ra.lpNorm<Eigen::Infinity>()))
        << m.name << " trial " << trial;
  }
}

struct Trajectory {
  VecX q, v;
};

Trajectory run(const system::System& sys, const model::Model& m, ReducedSolve how, int steps) {
  EnergyMomentumIntegrator integ(sys, m.solver, how);
  auto s = integ.initial_state();
  for (int i = 0; i < steps; ++i) integ.step(s);
  return {s.q, s.v};
}

}  // namespace

TEST(ReducedNewtonMatrix, UsedAutomaticallyWhereItApplies) {
  const auto m = slider_crank();
  const auto sys = system::System::compile(m);
  EXPECT_TRUE(integrate::ReducedNewtonMatrix::applicable(sys));
  EnergyMomentumIntegrator integ(sys, m.solver);
  EXPECT_TRUE(integ.block_assembly());
  EXPECT_FALSE(integ.bordered());
  EXPECT_FALSE(integ.tree_recursion());
  // Loop-closing rows: not applicable, the explicit path stays.
  const auto fb = system::System::compile(test::four_bar());
  EXPECT_FALSE(integrate::ReducedNewtonMatrix::applicable(fb));
  EXPECT_FALSE(EnergyMomentumIntegrator(fb, test::four_bar().solver).block_assembly());
  EXPECT_THROW(EnergyMomentumIntegrator(fb, test::four_bar().solver, ReducedSolve::blocks),
               std::invalid_argument);
  // Other formulations keep their paths.
  auto c = m;
  c.solver.formulation = model::Formulation::nullspace;
  EXPECT_FALSE(EnergyMomentumIntegrator(sys, c.solver).block_assembly());
}

TEST(ReducedNewtonMatrix, EqualsExplicitOnSliderCrank) {
  const auto m = slider_crank();
  expect_same_newton_matrix(m, 0, 1e-3);
  expect_same_newton_matrix(m, 5, 1e-2);
}

TEST(ReducedNewtonMatrix, EqualsExplicitOnDeeperTrees) {
  expect_same_newton_matrix(test::chain(6), 3, 1e-2);
  expect_same_newton_matrix(test::heavy_top(), 3, 1e-2);
  expect_same_newton_matrix(test::free_body_flip(), 3, 1e-2);
}

// Every entry of the explicit matrix lies in the pattern computed once, along a trajectory, and
// the sparse LU analyses that pattern once.
TEST(ReducedNewtonMatrix, PatternIsFixed) {
  const auto m = slider_crank();
  const auto sys = system::System::compile(m);
  EnergyMomentumIntegrator a(sys, m.solver, ReducedSolve::explicit_null_space);
  integrate::ReducedNewtonMatrix rn(sys);
  MatX mask = MatX::Zero(sys.k(), sys.k());
  for (int c = 0; c < rn.pattern().outerSize(); ++c)
    for (system::SpMat::InnerIterator it(rn.pattern(), c); it; ++it) mask(it.row(), it.col()) = 1;
  auto s = a.initial_state();
  solve::NormalEquations normal;
  system::SpMat J;
  std::srand(11);
  for (int i = 0; i < 10; ++i) {
    const VecX x = a.start_unknowns(s) + 1e-3 * VecX::Random(sys.k());
    MatX Ja;
    a.residual(s, x, &Ja);
    const double t_mid = s.t + 0.5 * m.solver.dt;
    rn.evaluate(s.q, s.v, x, m.solver.dt, t_mid, normal, &J);
    EXPECT_EQ(J.nonZeros(), rn.pattern().nonZeros());
    for (int c = 0; c < Ja.cols(); ++c)
      for (int r = 0; r < Ja.rows(); ++r)
        if (Ja(r, c) != 0.0) {
          ASSERT_EQ(mask(r, c), 1.0) << r << ", " << c;
        }
    const VecX R = rn.evaluate(s.q, s.v, x, m.solver.dt, t_mid, normal, nullptr);
    const VecX dx = rn.solve(J, -R);
    EXPECT_LT((MatX(J) * dx + R).norm(), 1e-8 * std::max(1.0, R.norm()));
    a.step(s);
  }
  EXPECT_EQ(rn.fallbacks(), 0);  // every solve by the block LU
  EXPECT_LE(rn.analyses(), 1);
}

// A solve without refactorization (the chord corrections of newton_loop) uses the factors of the
// last matrix: the same solution as refactorizing it, one factorization fewer, also after
// residual-only evaluations elsewhere.
TEST(ReducedNewtonMatrix, AChordSolveReusesTheFactorization) {
  const auto m = slider_crank();
  const auto sys = system::System::compile(m);
  EnergyMomentumIntegrator a(sys, m.solver);
  integrate::ReducedNewtonMatrix rn(sys);
  auto s = a.initial_state();
  for (int i = 0; i < 3; ++i) a.step(s);
  solve::NormalEquations normal;
  system::SpMat J;
  const double t_mid = s.t + 0.5 * m.solver.dt;
  std::srand(5);
  const VecX x = a.start_unknowns(s) + 1e-3 * VecX::Random(sys.k());
  const VecX R = rn.evaluate(s.q, s.v, x, m.solver.dt, t_mid, normal, &J);
  const VecX dx = rn.solve(J, -R);
  EXPECT_EQ(rn.factorizations(), 1);
  const VecX R2 = rn.evaluate(s.q, s.v, x + dx, m.solver.dt, t_mid, normal, nullptr);
  const VecX chord = rn.solve(J, -R2, false);
  EXPECT_EQ(rn.factorizations(), 1);
  const VecX fresh = rn.solve(J, -R2, true);
  EXPECT_EQ(rn.factorizations(), 2);
  EXPECT_LT((chord - fresh).lpNorm<Eigen::Infinity>(), 1e-12 * fresh.lpNorm<Eigen::Infinity>());
  EXPECT_LT((MatX(J) * chord + R2).lpNorm<Eigen::Infinity>(), 1e-10 * R2.lpNorm<Eigen::Infinity>());
}

// Block LU in minimum-degree order equals a dense LU on a random block-sparse matrix (a block
// tridiagonal chain of groups of widths 1…6 with an arrow to the last group), and its blocks'
// product equals the dense one.
TEST(ReducedNewtonMatrix, BlockLUSolvesBlockSparseSystems) {
  const int n = 12;
  std::vector<int> offset, width;
  int size = 0;
  for (int g = 0; g < n; ++g) {
    offset.push_back(size);
    width.push_back(1 + g % 6);
    size += width.back();
  }
  std::vector<std::pair<int, int>> blocks;
  for (int g = 0; g < n; ++g) {
    blocks.push_back({g, g});
    if (g + 1 < n) {
      blocks.push_back({g, g + 1});
      blocks.push_back({g + 1, g});
    }
    if (g + 2 < n) {
      blocks.push_back({g, n - 1});
      blocks.push_back({n - 1, g});
    }
  }
  std::srand(3);
  using Block6 = integrate::BlockLU::Block6;
  std::vector<Block6> values;
  MatX A = MatX::Zero(size, size);
  for (const auto& [g, h] : blocks) {
    Block6 B = Block6::Zero();
    B.topLeftCorner(width[g], width[h]).setRandom();
    if (g == h) B.topLeftCorner(width[g], width[g]).diagonal().array() += 8.0;
    A.block(offset[g], offset[h], width[g], width[h]) += B.topLeftCorner(width[g], width[h]);
    values.push_back(B);
  }
  integrate::BlockLU lu(offset, width, blocks);
  ASSERT_TRUE(lu.factorize(values));
  const VecX b = VecX::Random(size);
  EXPECT_LT((A * lu.solve(b) - b).lpNorm<Eigen::Infinity>(), 1e-12);
  VecX Ab;
  lu.multiply(values, b, Ab);
  EXPECT_LT((Ab - A * b).lpNorm<Eigen::Infinity>(), 1e-13);
  // Pivot blocks that need row exchanges (a zero leading entry, 8 off the diagonal).
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    const auto [g, h] = blocks[k];
    if (g != h || width[g] < 2) continue;
    Block6 P = Block6::Zero();
    for (int r = 0; r < width[g]; ++r) P(r, (r + 1) % width[g]) = 8.0;
    A.block(offset[g], offset[g], width[g], width[g]) +=
        (P - values[k]).topLeftCorner(width[g], width[g]);
    values[k] = P;
  }
  ASSERT_TRUE(lu.factorize(values));
  EXPECT_LT((A * lu.solve(b) - b).lpNorm<Eigen::Infinity>(), 1e-12);
  // A singular pivot block is reported, not used.
  values[0].setZero();
  for (std::size_t k = 0; k < blocks.size(); ++k)
    if (blocks[k].first == 0 || blocks[k].second == 0) values[k].setZero();
  EXPECT_FALSE(lu.factorize(values));
}

TEST(ReducedNewtonMatrix, TrajectoriesAgreeWithExplicitPath) {
  const int steps = 50;
  for (const auto& m : {slider_crank(), test::chain(6), test::heavy_top()}) {
    const auto sys = system::System::compile(m);
    const auto a = run(sys, m, ReducedSolve::explicit_null_space, steps);
    const auto b = run(sys, m, ReducedSolve::blocks, steps);
    EXPECT_LT((a.q - b.q).lpNorm<Eigen::Infinity>(), 1e-10) << m.name;
    EXPECT_LT((a.v - b.v).lpNorm<Eigen::Infinity>(),
              1e-10 * std::max(1.0, a.v.lpNorm<Eigen::Infinity>()) / m.solver.dt)
        << m.name;
  }
}

// A λ̂ from the caller (at a Newton start, the last step's multipliers) takes the place of the
// least squares from r₀: the multipliers of the iterate's own configuration give the matrix the
// least squares gives, twice them another one; the residual does not depend on λ̂.
TEST(ReducedNewtonMatrix, AGivenLambdaHatTakesThePlaceOfTheLeastSquares) {
  const auto m = slider_crank();
  const auto sys = system::System::compile(m);
  EnergyMomentumIntegrator a(sys, m.solver);
  integrate::ReducedNewtonMatrix rn(sys);
  auto s = a.initial_state();
  for (int i = 0; i < 3; ++i) a.step(s);
  solve::NormalEquations normal;
  const double dt = m.solver.dt, t_mid = s.t + 0.5 * dt;
  std::srand(9);
  const VecX x = a.start_unknowns(s) + 1e-3 * VecX::Random(sys.k());
  system::SpMat J0, J1, J2;
  const VecX R0 = rn.evaluate(s.q, s.v, x, dt, t_mid, normal, &J0);
  VecX q1, dq;
  std::vector<Mat3> steps;
  sys.update(s.q, x, q1, steps, &dq);
  VecX lambda;
  double mismatch = 0.0;
  ASSERT_TRUE(rn.multipliers(s.q, s.v, q1, dq, dt, t_mid, normal, lambda, mismatch));
  ASSERT_EQ(lambda.size(), sys.m_selected());
  const VecX R1 = rn.evaluate(s.q, s.v, x, dt, t_mid, normal, &J1, &lambda);
  EXPECT_LT(relative_difference(MatX(J0), MatX(J1)), 1e-10);
  EXPECT_EQ(R1, R0);
  const VecX twice = 2.0 * lambda;
  rn.evaluate(s.q, s.v, x, dt, t_mid, normal, &J2, &twice);
  EXPECT_GT(relative_difference(MatX(J0), MatX(J2)), 1e-8);
}

// The configuration of the last evaluation is kept for the caller (the converged step's
// q_{n+1}), and only for its arguments.
TEST(ReducedNewtonMatrix, KeepsTheConfigurationOfItsLastEvaluation) {
  const auto m = slider_crank();
  const auto sys = system::System::compile(m);
  EnergyMomentumIntegrator a(sys, m.solver);
  integrate::ReducedNewtonMatrix rn(sys);
  auto s = a.initial_state();
  for (int i = 0; i < 2; ++i) a.step(s);
  solve::NormalEquations normal;
  std::srand(4);
  const VecX x = a.start_unknowns(s) + 1e-3 * VecX::Random(sys.k());
  EXPECT_EQ(rn.configuration(s.q, x), nullptr);
  rn.evaluate(s.q, s.v, x, m.solver.dt, s.t + 0.5 * m.solver.dt, normal, nullptr);
  const VecX* q1 = rn.configuration(s.q, x);
  ASSERT_NE(q1, nullptr);
  EXPECT_EQ(*q1, sys.update(s.q, x));
  VecX y = x;
  y(0) += 1e-9;
  EXPECT_EQ(rn.configuration(s.q, y), nullptr);
  EXPECT_EQ(rn.configuration(s.v, x), nullptr);
}
