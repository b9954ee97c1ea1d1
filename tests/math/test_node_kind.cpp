// The node-kind contract (math/node_kind.hpp), checked for every kind by one parametrized test:
// sizes, constraint Jacobian and Hessian against finite differences, G P_int = 0 off the manifold
// (the discrete null space), the update map on the manifold with the derivative of its twist
// form, material points, and the step extrapolation.
#include <gtest/gtest.h>

#include "isoflex/math/node_kind.hpp"
#include "isoflex/math/rotation.hpp"
#include "support/finite_difference.hpp"

using namespace isoflex;
using namespace isoflex::test;

namespace {

// A configuration on the manifold: orthonormal directors, a unit director.
VecX on_manifold(NodeKind kind, std::mt19937& g) {
  const VecX phi = random_vector(g, 3);
  VecX q(coordinate_count(kind));
  switch (kind) {
    case NodeKind::frame: {
      const Mat3 R = random_rotation(g);
      q << phi, R.col(0), R.col(1), R.col(2);
      break;
    }
    case NodeKind::director:
      q << phi, random_vector(g, 3).normalized();
      break;
    case NodeKind::point:
      q = phi;
      break;
  }
  return q;
}

// A velocity of the node at q: q̇ = P_int(q) t.
VecX velocity(const NodeType& type, const VecX& q, std::mt19937& g) {
  return type.twist_null_space(q) * random_vector(g, 6);
}

class NodeKindTest : public ::testing::TestWithParam<NodeKind> {
 protected:
  const NodeType& type() const { return node_type(GetParam()); }
};

TEST_P(NodeKindTest, SizesAreConsistent) {
  const NodeType& t = type();
  EXPECT_EQ(t.kind(), GetParam());
  std::mt19937 g(1);
  const VecX q = on_manifold(GetParam(), g);
  EXPECT_EQ(t.constraints(q).size(), t.internal_rows());
  EXPECT_EQ(t.jacobian(q).rows(), t.internal_rows());
  EXPECT_EQ(t.jacobian(q).cols(), t.coordinates());
  EXPECT_EQ(t.twist_null_space(q).rows(), t.coordinates());
  EXPECT_EQ(t.twist_null_space(q).cols(), 6);
  EXPECT_EQ(t.root_block(q).rows(), 6);
  EXPECT_EQ(t.root_block(q).cols(), t.free_velocities());
  // The free velocities are independent: P_int B has full column rank (the tangent dimension).
  const MatX PB = t.twist_null_space(q) * t.root_block(q);
  EXPECT_EQ(Eigen::FullPivLU<MatX>(PB).rank(), t.free_velocities());
  EXPECT_EQ(t.free_velocities(), t.coordinates() - t.internal_rows());
}

TEST_P(NodeKindTest, ConstraintDerivativesMatchFiniteDifferences) {
  const NodeType& t = type();
  if (t.internal_rows() == 0) {
    EXPECT_EQ(t.constraints(VecX::Zero(t.coordinates())).size(), 0);
    return;
  }
  std::mt19937 g(2);
  const VecX q = random_vector(g, t.coordinates());  // off the manifold
  auto g_of = [&](const VecX& x) -> VecX { return t.constraints(x); };
  EXPECT_LT(rel_diff(MatX(t.jacobian(q)), central_jacobian(g_of, q)), 1e-8);
  const VecX lambda = random_vector(g, t.internal_rows());
  NodeMat H = NodeMat::Zero(t.coordinates(), t.coordinates());
  t.add_constraint_hessian(lambda, H);
  auto grad = [&](const VecX& x) -> VecX { return MatX(t.jacobian(x)).transpose() * lambda; };
  EXPECT_LT(rel_diff(MatX(H), central_jacobian(grad, q)), 1e-8);
}

TEST_P(NodeKindTest, NullSpaceAnnihilatesTheJacobianEverywhere) {
  const NodeType& t = type();
  std::mt19937 g(3);
  for (int k = 0; k < 10; ++k) {
    // Off the manifold too, so P_int(q_{n+½}) is a discrete null space (DNSM-III Table 3).
    const VecX q = random_vector(g, t.coordinates());
    EXPECT_LT((MatX(t.jacobian(q)) * MatX(t.twist_null_space(q))).norm(), 1e-14);
  }
}

TEST_P(NodeKindTest, ForcesReduceByTheTransposedNullSpaces) {
  const NodeType& t = type();
  std::mt19937 g(8);
  const VecX q = on_manifold(GetParam(), g);
  const VecX r = random_vector(g, t.coordinates());
  const Vec<6> y = t.twist_force(q, r);
  EXPECT_LT((y - MatX(t.twist_null_space(q)).transpose() * r).norm(), 1e-14);
  EXPECT_LT((MatX(t.free_force(q, y)) - MatX(t.root_block(q)).transpose() * y).norm(), 1e-14);
}

TEST_P(NodeKindTest, UpdateStaysOnTheManifoldWithExactDerivative) {
  const NodeType& t = type();
  std::mt19937 g(4);
  for (double scale : {1.0, 1e-4}) {
    const VecX qn = on_manifold(GetParam(), g);
    const VecX u = random_vector(g, t.free_velocities(), scale);
    Mat3 step;
    const VecX q1 = t.root_update(qn, u, step);
    EXPECT_LT(MatX(t.constraints(q1)).lpNorm<Eigen::Infinity>() + 0.0, 1e-14);
    EXPECT_LT((step.transpose() * step - Mat3::Identity()).norm(), 1e-14);
    // ∂q_{n+1}/∂u = P_int(q_{n+1}) ∂t/∂u.
    auto F = [&](const VecX& x) -> VecX {
      Mat3 s;
      return t.root_update(qn, x, s);
    };
    const MatX dq = MatX(t.twist_null_space(q1)) * MatX(t.root_update_block(qn, u));
    EXPECT_LT(rel_diff(dq, central_jacobian(F, u)), 1e-8);
    // At u = 0 the update is the identity and its derivative the free node's null space.
    const VecX zero = VecX::Zero(t.free_velocities());
    EXPECT_LT((F(zero) - qn).norm(), 1e-15);
    EXPECT_LT((MatX(t.root_update_block(qn, zero)) - MatX(t.root_block(qn))).norm(), 1e-15);
  }
}

// root_increment is q_{n+1} − qₙ of root_update, without its cancellation: far from the origin
// (|φ| = 10⁶) the difference of the coordinates loses the position's increment's last ten digits,
// the increment keeps them.
TEST_P(NodeKindTest, IncrementIsTheUpdateLessTheStartWithoutCancellation) {
  const NodeType& t = type();
  std::mt19937 g(8);
  for (double scale : {1.0, 1e-3, 1e-7}) {
    const VecX qn = on_manifold(GetParam(), g);
    const VecX u = random_vector(g, t.free_velocities(), scale);
    Mat3 step;
    const VecX dq = t.root_increment(qn, u);
    EXPECT_LT((dq - (t.root_update(qn, u, step) - qn)).lpNorm<Eigen::Infinity>(), 4e-16)
        << "scale " << scale;
    VecX far = qn;
    far.head<3>() += Vec3(1e6, -1e6, 1e6);
    const VecX dfar = t.root_increment(far, u);
    EXPECT_TRUE(dfar.head<3>() == u.head<3>());
    EXPECT_TRUE(dfar.tail(dfar.size() - 3) == dq.tail(dq.size() - 3));
    EXPECT_GT((t.root_update(far, u, step) - far - dfar).head<3>().lpNorm<Eigen::Infinity>(),
              1e-13);
  }
}

TEST_P(NodeKindTest, RotationOverTheStepMovesTheFrame) {
  const NodeType& t = type();
  std::mt19937 g(5);
  const VecX qn = on_manifold(GetParam(), g);
  const VecX u = random_vector(g, t.free_velocities(), 0.5);
  Mat3 step;
  const VecX q1 = t.root_update(qn, u, step);
  // The frame's third axis (a director node's d, a frame node's d₃) turns with the step.
  EXPECT_LT((step * t.frame(qn).col(2) - t.frame(q1).col(2)).norm(), 1e-13);
}

TEST_P(NodeKindTest, MaterialPointsAndLocalCoordinates) {
  const NodeType& t = type();
  std::mt19937 g(6);
  const VecX q = on_manifold(GetParam(), g);
  EXPECT_LT((t.material_point(q, Vec3::Zero()) - Vec3(q.head<3>())).norm(), 1e-15);
  const Vec3 X = t.local_coordinates(q, t.material_point(q, Vec3(0.0, 0.0, 0.0)));
  EXPECT_LT((t.material_point(q, X) - Vec3(q.head<3>())).norm(), 1e-14);
  if (GetParam() == NodeKind::frame) {
    const Vec3 x = random_vector(g, 3);
    EXPECT_LT((t.material_point(q, t.local_coordinates(q, x)) - x).norm(), 1e-14);
  }
  // Material points are linear in q: their velocity is the same map applied to q̇.
  const VecX v = velocity(t, q, g);
  const Vec3 Y(0.1, -0.2, 0.3);
  const double h = 1e-6;
  const Vec3 fd = (t.material_point(q + h * v, Y) - t.material_point(q - h * v, Y)) / (2.0 * h);
  EXPECT_LT((t.material_point(v, Y) - fd).norm(), 1e-8);
}

TEST_P(NodeKindTest, ExtrapolationMovesThePositionAtConstantVelocity) {
  // A kind that extrapolates moves its position by Δt φ̇ and keeps the caller's other increments
  // (the last step's: a director turns as in the last step, docs/theory/schemes.md §6); one that
  // does not leaves them all.
  const NodeType& t = type();
  std::mt19937 g(7);
  const VecX q = on_manifold(GetParam(), g);
  const VecX v = velocity(t, q, g);
  VecX u = VecX::Constant(t.free_velocities(), 7.0);
  auto uref = u.segment(0, t.free_velocities());
  const double dt = 1e-4;
  if (!t.extrapolate(q, v, dt, uref)) {
    EXPECT_TRUE((u.array() == 7.0).all());  // untouched: the caller keeps its own guess
    return;
  }
  Mat3 step;
  const VecX q1 = t.root_update(q, u, step);
  EXPECT_LT((q1.head<3>() - q.head<3>() - dt * v.head<3>()).norm(), 1e-15 * (1.0 + q.norm()));
  EXPECT_TRUE((u.tail(t.free_velocities() - 3).array() == 7.0).all());
}

std::string kind_name(const ::testing::TestParamInfo<NodeKind>& info) {
  return node_type(info.param).name();
}

INSTANTIATE_TEST_SUITE_P(AllKinds, NodeKindTest,
                         ::testing::Values(NodeKind::frame, NodeKind::director, NodeKind::point),
                         kind_name);

}  // namespace
