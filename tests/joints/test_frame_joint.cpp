#include <gtest/gtest.h>

#include "isoflex/joints/frame_joint.hpp"
#include "isoflex/math/rotation.hpp"
#include "support/finite_difference.hpp"
#include "support/joint_increments.hpp"

using namespace isoflex;
using namespace isoflex::test;
using joints::FrameJoint;
using joints::Kind;
namespace fn = isoflex::frame_node;

namespace {
const Kind kKinds[] = {Kind::spherical, Kind::revolute,  Kind::prismatic, Kind::cylindrical,
                       Kind::planar,    Kind::universal, Kind::rigid,     Kind::point_on_line};
const int kM[] = {3, 5, 5, 4, 3, 4, 6, 2};

struct Setup {
  FrameJoint joint;
  fn::Q qa0, qb0;
};

// A joint between two randomly placed bodies, assembled at t = 0 with a random joint frame.
Setup make_setup(Kind kind, std::mt19937& g) {
  const fn::Q qa0 = fn::make(random_vector(g, 3), random_rotation(g));
  const fn::Q qb0 = fn::make(random_vector(g, 3), random_rotation(g));
  const Vec3 p = random_vector(g, 3);
  const Mat3 E = random_rotation(g);
  return {FrameJoint(kind, joints::geometry_from_global(qa0, qb0, p, E)), qa0, qb0};
}

// q̇ = (P_int(q_A) t_A, P_int(q_B)(A t_A + B τ)).
MatX joint_null_space(const FrameJoint& j, const fn::Q& qa, const fn::Q& qb) {
  const int r = j.freedom_count();
  MatX P = MatX::Zero(24, 6 + r);
  P.block<12, 6>(0, 0) = fn::null_space(qa);
  MatX AB(6, 6 + r);
  AB << j.parent_block(qa, qb), j.freedom_block(qa, qb);
  P.bottomRows<12>() = fn::null_space(qb) * AB;
  return P;
}
}  // namespace

class FrameJointTest : public ::testing::TestWithParam<int> {};

TEST_P(FrameJointTest, HoldsAtAssemblyAndCountsRows) {
  std::mt19937 g(10 + GetParam());
  const auto s = make_setup(kKinds[GetParam()], g);
  EXPECT_EQ(s.joint.constraint_count(), kM[GetParam()]);
  EXPECT_EQ(s.joint.constraint_count() + s.joint.freedom_count(), 6);
  EXPECT_LT(s.joint.constraints(s.qa0, s.qb0).norm(), 1e-14);
}

TEST_P(FrameJointTest, JacobianAndHessianMatchFiniteDifferences) {
  std::mt19937 g(20 + GetParam());
  const auto s = make_setup(kKinds[GetParam()], g);
  const VecX q = random_vector(g, 24, 2.0);
  auto phi = [&](const VecX& x) -> VecX { return s.joint.constraints(x.head<12>(), x.tail<12>()); };
  const MatX G = s.joint.jacobian(q.head<12>(), q.tail<12>());
  EXPECT_LT(rel_diff(G, central_jacobian(phi, q)), 1e-9);
  const VecX l = random_vector(g, s.joint.constraint_count());
  Mat<24, 24> H = Mat<24, 24>::Zero();
  s.joint.add_constraint_hessian(l, H);
  auto gl = [&](const VecX& x) -> VecX {
    return s.joint.jacobian(x.head<12>(), x.tail<12>()).transpose() * l;
  };
  EXPECT_LT(rel_diff(H, central_jacobian(gl, q)), 1e-9);
}

// G(q) P(q) = 0 for every q ∈ R²⁴ (not only on the manifold), so the midpoint evaluation is a
// discrete null space: 𝖦(qₙ, qₙ₊₁) 𝖯(qₙ, qₙ₊₁) = G(q_{n+½}) P(q_{n+½}) = 0.
TEST_P(FrameJointTest, NullSpaceAnnihilatesJacobianEverywhere) {
  std::mt19937 g(30 + GetParam());
  const auto s = make_setup(kKinds[GetParam()], g);
  for (int k = 0; k < 10; ++k) {
    const VecX q = random_vector(g, 24, 2.0);
    const MatX G = s.joint.jacobian(q.head<12>(), q.tail<12>());
    const MatX P = joint_null_space(s.joint, q.head<12>(), q.tail<12>());
    EXPECT_LT((G * P).norm(), 1e-12 * G.norm() * P.norm());
  }
  // Full rank at the assembled configuration: joint and internal rows independent.
  const MatX P = joint_null_space(s.joint, s.qa0, s.qb0);
  EXPECT_EQ(Eigen::FullPivLU<MatX>(P).rank(), 6 + s.joint.freedom_count());
  MatX Gall(12 + s.joint.constraint_count(), 24);
  Gall.setZero();
  Gall.block<6, 12>(0, 0) = fn::jacobian(s.qa0);
  Gall.block<6, 12>(6, 12) = fn::jacobian(s.qb0);
  Gall.bottomRows(s.joint.constraint_count()) = s.joint.jacobian(s.qa0, s.qb0);
  EXPECT_EQ(Eigen::FullPivLU<MatX>(Gall).rank(), 12 + s.joint.constraint_count());
}

TEST_P(FrameJointTest, UpdateMapKeepsConstraintsAndMatchesNullSpace) {
  std::mt19937 g(40 + GetParam());
  const auto s = make_setup(kKinds[GetParam()], g);
  const int r = s.joint.freedom_count();
  fn::Q qa_n = s.qa0, qb_n = s.qb0;
  for (int step = 0; step < 3; ++step) {
    const VecX ua = random_vector(g, 6, 0.8);
    const fn::Q qa_n1 = fn::update(qa_n, ua);
    const Mat3 QA = rodrigues(Vec3(ua.tail<3>()));
    const VecX tau = random_vector(g, r, 0.8);
    const fn::Q qb_n1 = s.joint.update(qa_n, qa_n1, QA, qb_n, tau);
    EXPECT_LT(s.joint.constraints(qa_n1, qb_n1).norm(), 1e-13) << "step " << step;
    EXPECT_LT(fn::constraints(qb_n1).norm(), 1e-13);
    // ∂q_B,n+1/∂(t_A, τ) = P_int(q_B)[A B] diag(I, T(θ)) at t_{n+1}, the parent varied through
    // its own update map.
    auto f = [&](const VecX& x) -> VecX {
      const fn::Q qa = fn::update(qa_n1, x.head<6>());
      return s.joint.update(qa_n, qa, rodrigues(Vec3(x.segment<3>(3))) * QA, qb_n, tau + x.tail(r));
    };
    const MatX J = central_jacobian(f, VecX::Zero(6 + r));
    MatX AB(6, 6 + r);
    AB << s.joint.parent_block(qa_n1, qb_n1), s.joint.freedom_block(qa_n1, qb_n1);
    const int o = s.joint.rotation_vector_offset();
    if (o >= 0) {
      // τ-increments are perturbed additively at θ = τ: tangent T(θ).
      AB.block(0, 6 + o, 6, 3) = AB.block(0, 6 + o, 6, 3) * rodrigues_tangent(tau.segment<3>(o));
    }
    EXPECT_LT(rel_diff(fn::null_space(qb_n1) * AB, J), 1e-8) << "step " << step;
    qa_n = qa_n1;
    qb_n = qb_n1;
  }
}

// The child turns by Q_A, the parent's exact step rotation, not by R_A,n+1 R_A,nᵀ: a parent whose
// directors are off orthonormal by ε (round-off, here 10⁻¹⁰ to be seen) then leaves the child as
// it was, instead of adding ε to it at every step (after 200 steps: 2·10⁻⁸ before).
TEST_P(FrameJointTest, ParentOrthonormalityErrorDoesNotAccumulateInTheChild) {
  std::mt19937 g(70 + GetParam());
  const auto s = make_setup(kKinds[GetParam()], g);
  const int r = s.joint.freedom_count();
  fn::Q qa_n = s.qa0, qb_n = s.qb0;
  qa_n.segment<3>(3) *= 1.0 + 1e-10;
  for (int step = 0; step < 200; ++step) {
    const VecX ua = random_vector(g, 6, 0.3);
    const fn::Q qa_n1 = fn::update(qa_n, ua);
    const fn::Q qb_n1 =
        s.joint.update(qa_n, qa_n1, rodrigues(Vec3(ua.tail<3>())), qb_n, random_vector(g, r, 0.3));
    qa_n = qa_n1;
    qb_n = qb_n1;
  }
  // Locked rotation: R_B = R_A C_A C_Bᵀ copies the parent's ε once.
  EXPECT_LT(fn::constraints(qb_n).lpNorm<Eigen::Infinity>(), 3e-10);
}

// The child's increment over a step (StepIncrement, from which the step's velocities come): the
// update less the start, and the same 10⁶ m from the origin, where the difference of the rounded
// coordinates is off by ~10⁻¹⁰ (docs/theory/schemes.md §7). The sliding joints' rₙ = x_B − x_A
// is itself a difference of coordinates; it enters multiplied by Q_A − I (~0.02 here).
TEST_P(FrameJointTest, IncrementIsTheUpdateLessTheStartWithoutCancellation) {
  std::mt19937 g(90 + GetParam());
  const auto s = make_setup(kKinds[GetParam()], g);
  expect_increments_without_cancellation(s.joint, s.qa0, s.qb0, false, 1e-11, g);
}

INSTANTIATE_TEST_SUITE_P(AllKinds, FrameJointTest, ::testing::Range(0, 8));
