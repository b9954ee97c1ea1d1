#include <gtest/gtest.h>

#include <Eigen/LU>

#include "isoflex/math/frame_node.hpp"
#include "support/finite_difference.hpp"

using namespace isoflex;
using namespace isoflex::test;
namespace fn = isoflex::frame_node;

namespace {
fn::Q random_q(std::mt19937& g) {
  return random_vector(g, 12, 2.0);
}
fn::Q random_manifold_q(std::mt19937& g) {
  return fn::make(random_vector(g, 3), random_rotation(g));
}
}  // namespace

TEST(FrameNode, JacobianAndHessianMatchFiniteDifferences) {
  std::mt19937 g(3);
  const VecX q = random_q(g);
  auto c = [](const VecX& x) -> VecX { return fn::constraints(x); };
  EXPECT_LT(rel_diff(fn::jacobian(q), central_jacobian(c, q)), 1e-9);
  const Vec<6> l = random_vector(g, 6);
  Mat<12, 12> H = Mat<12, 12>::Zero();
  fn::add_constraint_hessian(l, H);
  auto gl = [&](const VecX& x) -> VecX { return fn::jacobian(x).transpose() * l; };
  EXPECT_LT(rel_diff(H, central_jacobian(gl, q)), 1e-9);
}

// G(q) P(q) = 0 for every q ∈ R¹², hence the discrete null space 𝖯 = P(q_{n+½}) with the discrete
// derivative 𝖦 = G(q_{n+½}) (DNSM-III (23), (32)).
TEST(FrameNode, NullSpaceAnnihilatesJacobianEverywhere) {
  std::mt19937 g(4);
  for (int k = 0; k < 20; ++k) {
    const fn::Q qn = random_manifold_q(g), qn1 = random_manifold_q(g);
    const fn::Q qm = 0.5 * (qn + qn1);
    EXPECT_LT((fn::jacobian(qm) * fn::null_space(qm)).norm(), 1e-13);
    const fn::Q q = random_q(g);
    EXPECT_LT((fn::jacobian(q) * fn::null_space(q)).norm(), 1e-13);
  }
  const fn::Q q = random_manifold_q(g);
  Eigen::FullPivLU<Mat<12, 6>> lu(fn::null_space(q));
  EXPECT_EQ(lu.rank(), 6);
}

TEST(FrameNode, UpdateKeepsConstraintsAndHasExactDerivative) {
  std::mt19937 g(5);
  for (int k = 0; k < 10; ++k) {
    const fn::Q qn = random_manifold_q(g);
    const VecX u = random_vector(g, 6, 1.5);
    EXPECT_LT(fn::constraints(fn::update(qn, u)).norm(), 1e-14);
    auto f = [&](const VecX& x) -> VecX { return fn::update(qn, x); };
    EXPECT_LT(rel_diff(fn::update_derivative(qn, u), central_jacobian(f, u)), 1e-8);
  }
  const fn::Q qn = random_manifold_q(g);
  EXPECT_EQ(fn::update(qn, Vec<6>::Zero()), qn);
}
