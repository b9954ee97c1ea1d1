// A joint instance's rows through the constraint contract (joints/joint_rows.hpp), between two
// bodies and between the ground and a body: the rows are the joint's, the Jacobian matches
// central differences of the rows, and the Hessian term Σ λᵢ ∂²Φᵢ/∂q² matches central
// differences of Gᵀλ — over the child alone when the parent is the ground.
#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "isoflex/joints/frame_joint.hpp"
#include "isoflex/joints/joint_rows.hpp"
#include "isoflex/math/frame_node.hpp"
#include "support/finite_difference.hpp"

using namespace isoflex;
using namespace isoflex::test;
using joints::FrameJoint;
using joints::JointRows;
using joints::Kind;
namespace fn = isoflex::frame_node;

namespace {

// Checks the contract at a configuration q_c off the constraint manifold.
// quadratic: whether the rows are quadratic in q_c (between two bodies; from the fixed ground a
// frame joint's rows are linear in the child).
void check_contract(const JointRows& rows, const VecX& q_c, std::mt19937& g, bool quadratic) {
  const int m = rows.constraint_count();
  ASSERT_EQ(rows.constraints(q_c).size(), m);
  const MatX G = rows.jacobian(q_c);
  ASSERT_EQ(G.rows(), m);
  ASSERT_EQ(G.cols(), q_c.size());
  const MatX G_fd = central_jacobian([&](const VecX& y) { return rows.constraints(y); }, q_c);
  EXPECT_LT(rel_diff(G, G_fd), 1e-8);
  const VecX lambda = random_vector(g, m);
  MatX H = MatX::Zero(q_c.size(), q_c.size());
  rows.add_constraint_hessian(q_c, lambda, H);
  const MatX H_fd = central_jacobian(
      [&](const VecX& y) { return VecX(rows.jacobian(y).transpose() * lambda); }, q_c);
  if (quadratic) {
    EXPECT_GT(H_fd.norm(), 1e-3);
  }
  EXPECT_LT(rel_diff(H, H_fd), 1e-7);
}

}  // namespace

TEST(JointRows, BetweenTwoBodiesTheRowsAreTheJointsOverBothNodes) {
  std::mt19937 g(3);
  const fn::Q qa = fn::make(random_vector(g, 3), random_rotation(g));
  const fn::Q qb = fn::make(random_vector(g, 3), random_rotation(g));
  auto joint = std::make_shared<FrameJoint>(
      Kind::revolute,
      joints::geometry_from_global(qa, qb, random_vector(g, 3), random_rotation(g)));
  const JointRows rows(joint, 4, 7, fn::make(Vec3::Zero(), Mat3::Identity()));
  EXPECT_EQ(rows.nodes(), (std::vector<int>{4, 7}));
  VecX q(24);
  q << qa + 0.1 * random_vector(g, 12), qb + 0.1 * random_vector(g, 12);
  EXPECT_EQ(rows.constraints(q), joint->constraints(q.head(12), q.tail(12)));
  EXPECT_EQ(rows.jacobian(q), joint->jacobian(q.head(12), q.tail(12)));
  check_contract(rows, q, g, true);
}

TEST(JointRows, FromTheGroundTheRowsActOnTheChildAlone) {
  std::mt19937 g(5);
  const fn::Q ground = fn::make(Vec3::Zero(), Mat3::Identity());
  const fn::Q qb = fn::make(random_vector(g, 3), random_rotation(g));
  auto joint = std::make_shared<FrameJoint>(
      Kind::cylindrical,
      joints::geometry_from_global(ground, qb, random_vector(g, 3), random_rotation(g)));
  const JointRows rows(joint, -1, 2, ground);
  EXPECT_EQ(rows.nodes(), std::vector<int>{2});
  const VecX q = qb + 0.1 * random_vector(g, 12);
  EXPECT_EQ(rows.constraints(q), joint->constraints(ground, q));
  EXPECT_EQ(rows.jacobian(q), joint->jacobian(ground, q).rightCols(12));
  check_contract(rows, q, g, false);
  EXPECT_EQ(rows.constraint_count(), 4);
}
