#include <gtest/gtest.h>

#include <random>

#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/system/tree_newton_solver.hpp"
#include "support/finite_difference.hpp"
#include "support/models.hpp"

using namespace isoflex;
using model::JointType;

namespace {
// A tree with every kind of link: joints with 1–5 freedoms and none (rigid), a joint to the
// ground, a free root body, and joints whose Hessians couple parent and child.
model::Model mixed_tree() {
  model::Model m;
  m.name = "mixed tree";
  m.gravity = Vec3(0, 0, -9.81);
  for (int i = 0; i < 6; ++i)
    m.bodies.push_back(
        test::rod("b" + std::to_string(i), Vec3(i, 0.1 * i, 0), Vec3(i + 1, 0.1 * (i + 1), 0)));
  m.bodies.push_back(test::rod("free", Vec3(0, 2, 0), Vec3(1, 2.5, 0)));
  m.bodies.back().angular_velocity = Vec3(0.3, -1.0, 2.0);
  m.bodies.back().velocity = Vec3(0.1, 0.2, 0.3);
  m.bodies[0].angular_velocity = Vec3(0, 0, 0.5);
  m.bodies[0].velocity = Vec3(0, 0.25, 0);
  m.joints.push_back(
      test::joint(JointType::revolute, "ground", "b0", Vec3(0, 0, 0), Vec3(0, 0.6, 0.8)));
  auto u = test::joint(JointType::universal, "b0", "b1", Vec3(1, 0.1, 0), Vec3(0, 0, 1));
  u.axis2 = Vec3(0, 1, 0);
  m.joints.push_back(u);
  m.joints.push_back(
      test::joint(JointType::cylindrical, "b1", "b2", Vec3(2, 0.2, 0), Vec3(1, 0.1, 0)));
  m.joints.push_back(test::joint(JointType::rigid, "b2", "b3", Vec3(3, 0.3, 0)));
  m.joints.push_back(test::joint(JointType::spherical, "b3", "b4", Vec3(4, 0.4, 0)));
  m.joints.push_back(
      test::joint(JointType::prismatic, "b4", "b5", Vec3(5, 0.5, 0), Vec3(1, 0.1, 0)));
  m.solver.dt = 0.01;
  return m;
}

system::SpMat random_tree_matrix(const system::System& sys, std::mt19937& g) {
  system::Triplets t;
  auto block = [&](int a, int b) {
    const MatX B = test::random_vector(g, 144).reshaped(12, 12);
    for (int i = 0; i < 12; ++i)
      for (int j = 0; j < 12; ++j) t.emplace_back(12 * a + i, 12 * b + j, B(i, j));
  };
  for (int i = 0; i < sys.node_count(); ++i) {
    block(i, i);
    for (int i2 = 0; i2 < 12; ++i2) t.emplace_back(12 * i + i2, 12 * i + i2, 20.0);
  }
  for (const auto& J : sys.joints())
    if (J.parent >= 0) {
      block(J.parent, J.child);
      block(J.child, J.parent);
    }
  system::SpMat K(sys.n(), sys.n());
  K.setFromTriplets(t.begin(), t.end());
  return K;
}
}  // namespace

TEST(TreeNewtonSolver, SolvesTheReducedSystemOfAnyTree) {
  const auto m = mixed_tree();
  const auto sys = system::System::compile(m);
  const system::TreeNewtonSolver solver(sys);
  ASSERT_TRUE(solver.applicable());
  std::mt19937 g(7);
  const VecX qn = sys.q0();
  for (int trial = 0; trial < 5; ++trial) {
    const VecX u = test::random_vector(g, sys.k(), 0.3);
    const VecX q1 = sys.update(qn, u);
    const VecX qm = 0.5 * (qn + q1);
    const system::SpMat K = random_tree_matrix(sys, g);
    const VecX b = test::random_vector(g, sys.k());
    // J = 𝖯(q_{n+½})ᵀ K P_tree(q_{n+1}) D(u), formed explicitly.
    const MatX J = MatX(system::SpMat(sys.tree_null_space(qm).transpose()) * K *
                        sys.update_derivative(qn, q1, u));
    const VecX expected = J.fullPivLu().solve(b);
    const auto du = solver.solve(qm, q1, u, K, b);
    ASSERT_TRUE(du.has_value());
    EXPECT_LT((*du - expected).norm() / expected.norm(), 1e-12) << "trial " << trial;
    EXPECT_LT((J * *du - b).norm() / b.norm(), 1e-12) << "trial " << trial;
  }
}

TEST(TreeNewtonSolver, RefusesCouplingsOutsideTheTree) {
  const auto sys = system::System::compile(mixed_tree());
  const system::TreeNewtonSolver solver(sys);
  std::mt19937 g(3);
  system::SpMat K = random_tree_matrix(sys, g);
  K.coeffRef(0, 12 * 3) = 1.0;  // b0–b3 are not neighbours
  const VecX u = VecX::Zero(sys.k());
  EXPECT_FALSE(solver.solve(sys.q0(), sys.q0(), u, K, VecX::Ones(sys.k())).has_value());
  // A closed loop cannot use the recursion.
  const auto loop = system::System::compile(test::four_bar());
  EXPECT_FALSE(system::TreeNewtonSolver(loop).applicable());
}

TEST(TreeNewtonSolver, IntegratorGivesTheSameTrajectoryAsTheExplicitNullSpace) {
  auto m = mixed_tree();
  m.solver.increment_tolerance = 1e-14;
  const auto sys = system::System::compile(m);
  using integrate::EnergyMomentumIntegrator;
  using integrate::ReducedSolve;
  EnergyMomentumIntegrator a(sys, m.solver, ReducedSolve::explicit_null_space);
  EnergyMomentumIntegrator b(sys, m.solver, ReducedSolve::tree);
  EXPECT_TRUE(b.tree_recursion());
  EXPECT_FALSE(a.tree_recursion());
  // Round-off differences grow fast in this spinning mechanism (1e-16 → 2e-10 in 100 steps
  // between the bordered and the explicit solve as well), so compare over 40 steps.
  auto sa = a.initial_state(), sb = b.initial_state();
  for (int i = 0; i < 40; ++i) {
    const auto ia = a.step(sa), ib = b.step(sb);
    ASSERT_LE(std::abs(ia.iterations - ib.iterations), 1) << "step " << i;
  }
  EXPECT_LT((sa.q - sb.q).lpNorm<Eigen::Infinity>(), 1e-11);
  EXPECT_LT((sa.v - sb.v).lpNorm<Eigen::Infinity>(), 1e-9);
  const auto e0 = b.snapshot(b.initial_state(), {}, {}), e1 = b.snapshot(sb, {}, {});
  EXPECT_LT(std::abs(e1.total_energy - e0.total_energy) /
                std::max(std::abs(e1.kinetic_energy), std::abs(e1.potential_energy)),
            1e-12);
  // Only the reparametrized formulation has the recursion.
  auto ns = m;
  ns.solver.formulation = model::Formulation::nullspace;
  const auto sys_ns = system::System::compile(ns);
  EXPECT_THROW(EnergyMomentumIntegrator(sys_ns, ns.solver, ReducedSolve::tree),
               std::invalid_argument);
}
