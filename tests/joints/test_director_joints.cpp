#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

#include "isoflex/joints/director_joints.hpp"
#include "isoflex/math/rotation.hpp"
#include "support/finite_difference.hpp"
#include "support/joint_increments.hpp"

using namespace isoflex;
using namespace isoflex::test;
using joints::DirectorCondition;
using joints::DirectorSupportSpec;
using joints::NodeKind;
namespace dn = isoflex::director_node;
namespace fn = isoflex::frame_node;

namespace {
// --- Node kinds as the tree sees them ------------------------------------------------------------
int coords(NodeKind k) {
  return joints::coordinate_count(k);
}
int velocities(NodeKind k) {  // tangent dimension: 6 (R³ × SO(3)), 5 (R³ × S²)
  return k == NodeKind::frame ? fn::kTwist : dn::kTwist;
}
int internal_rows(NodeKind k) {
  return k == NodeKind::frame ? fn::kConstraints : dn::kConstraints;
}
MatX internal_null_space(NodeKind k, const VecX& q) {  // P_int in twist form, n × 6
  return k == NodeKind::frame ? MatX(fn::null_space(q)) : MatX(dn::twist_null_space(q));
}
MatX internal_jacobian(NodeKind k, const VecX& q) {
  return k == NodeKind::frame ? MatX(fn::jacobian(q)) : MatX(dn::jacobian(q));
}
double internal_residual(NodeKind k, const VecX& q) {
  return k == NodeKind::frame ? fn::constraints(q).norm() : std::abs(dn::constraint(q));
}
// The node rigidly moved: φ + δφ, every director turned by E (about the node's own point).
VecX moved(const VecX& q, const Vec3& dphi, const Mat3& E) {
  VecX out = q;
  out.head<3>() += dphi;
  for (int i = 3; i < q.size(); i += 3) out.segment<3>(i) = E * q.segment<3>(i);
  return out;
}
// The orientation the child's step rotation acts on: R_B (frame) or d_B (director).
MatX orientation(NodeKind k, const VecX& q) {
  return k == NodeKind::frame ? MatX(fn::directors(q)) : MatX(q.tail<3>());
}

VecX random_director(std::mt19937& g) {
  dn::Q q;
  q << random_vector(g, 3), random_vector(g, 3).normalized();
  return q;
}
VecX random_frame(std::mt19937& g) {
  return fn::make(random_vector(g, 3), random_rotation(g));
}
VecX ground() {
  return fn::make(Vec3::Zero(), Mat3::Identity());
}

// --- The joints under test, at random t = 0 configurations ---------------------------------------
struct Case {
  std::shared_ptr<const joints::Joint> joint;
  VecX qa0, qb0;
  bool ground_parent = false;
};

const char* const kNames[] = {"ShellIntersection",    "DirectorOnBody", "DirectorOnGround",
                              "FrameOnDirector",      "SupportPinned",  "SupportRollerClamped",
                              "SupportSymmetryPlane", "SupportFreeAxis"};
const int kM[] = {4, 5, 5, 5, 3, 4, 2, 1};
constexpr int kCases = 8;

Case make_case(int id, std::mt19937& g) {
  Case c;
  auto support = [&](std::array<bool, 3> fix, DirectorCondition d, const Vec3& n) {
    c.qa0 = ground();
    c.qb0 = random_director(g);
    c.ground_parent = true;
    c.joint = std::make_shared<joints::DirectorSupport>(c.qb0, DirectorSupportSpec{fix, d, n});
  };
  switch (id) {
    case 0:  // one point, random directors: a random intersection angle β₀
      c.qa0 = random_director(g);
      c.qb0 = random_director(g);
      c.qb0.head<3>() = c.qa0.head<3>();
      c.joint = std::make_shared<joints::ShellIntersection>(c.qa0, c.qb0);
      break;
    case 1:
      c.qa0 = random_frame(g);
      c.qb0 = random_director(g);
      c.joint = std::make_shared<joints::DirectorOnFrame>(c.qa0, c.qb0);
      break;
    case 2:  // clamped shell node
      c.qa0 = ground();
      c.qb0 = random_director(g);
      c.ground_parent = true;
      c.joint = std::make_shared<joints::DirectorOnFrame>(c.qa0, c.qb0);
      break;
    case 3:
      c.qa0 = random_director(g);
      c.qb0 = random_frame(g);
      c.joint = std::make_shared<joints::FrameOnDirector>(c.qa0, c.qb0);
      break;
    case 4:
      support({true, true, true}, DirectorCondition::free, Vec3::Zero());
      break;
    case 5:
      support({true, false, true}, DirectorCondition::fixed, Vec3::Zero());
      break;
    case 6:
      support({true, false, false}, DirectorCondition::about_axis, Vec3::UnitX());
      break;
    default:  // a random (unnormalized) axis, no translation fixed
      support({false, false, false}, DirectorCondition::about_axis, random_vector(g, 3));
      break;
  }
  return c;
}

// q̇ = (P_int(q_A) t_A, P_int(q_B)(A t_A + B τ)), (n_A + n_B) × (6 + r).
MatX joint_null_space(const joints::Joint& j, const VecX& qa, const VecX& qb) {
  const int na = qa.size(), nb = qb.size(), r = j.freedom_count();
  MatX P = MatX::Zero(na + nb, 6 + r);
  P.topLeftCorner(na, 6) = internal_null_space(j.parent_kind(), qa);
  MatX AB(6, 6 + r);
  AB << j.parent_block(qa, qb), j.freedom_block(qa, qb);
  P.bottomRows(nb) = internal_null_space(j.child_kind(), qb) * AB;
  return P;
}

// Measured residuals go to the XML report (--gtest_output=xml) in scientific notation.
void record(const std::string& key, double value) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2e", value);
  ::testing::Test::RecordProperty(key, buf);
}

int rank(const MatX& M) {
  if (M.size() == 0) return 0;
  Eigen::FullPivLU<MatX> lu(M);
  lu.setThreshold(1e-10);
  return static_cast<int>(lu.rank());
}
}  // namespace

class DirectorJointTest : public ::testing::TestWithParam<int> {};

TEST_P(DirectorJointTest, HoldsAtAssemblyAndCountsRows) {
  std::mt19937 g(110 + GetParam());
  const Case c = make_case(GetParam(), g);
  const joints::Joint& j = *c.joint;
  EXPECT_EQ(c.qa0.size(), coords(j.parent_kind()));
  EXPECT_EQ(c.qb0.size(), coords(j.child_kind()));
  EXPECT_EQ(j.constraint_count(), kM[GetParam()]);
  // The rows and τ account for the child's velocities: 5 for a director child, 6 for a frame
  // child (the drilling ω ∥ d of a director child is not a velocity of its own).
  EXPECT_EQ(j.constraint_count() + j.freedom_count(), velocities(j.child_kind()));
  const VecX phi = j.constraints(c.qa0, c.qb0);
  EXPECT_EQ(phi.size(), j.constraint_count());
  record("phi_t0", phi.norm());
  EXPECT_LT(phi.norm(), 1e-14);
  const MatX B = j.freedom_block(c.qa0, c.qb0);
  EXPECT_EQ(B.rows(), 6);
  EXPECT_EQ(B.cols(), j.freedom_count());
}

TEST_P(DirectorJointTest, JacobianAndHessianMatchFiniteDifferences) {
  std::mt19937 g(120 + GetParam());
  const Case c = make_case(GetParam(), g);
  const joints::Joint& j = *c.joint;
  const int na = c.qa0.size(), nb = c.qb0.size(), n = na + nb;
  const VecX q = random_vector(g, n, 2.0);
  auto phi = [&](const VecX& x) -> VecX { return j.constraints(x.head(na), x.tail(nb)); };
  const MatX G = j.jacobian(q.head(na), q.tail(nb));
  ASSERT_EQ(G.rows(), j.constraint_count());
  ASSERT_EQ(G.cols(), n);
  const double dG = rel_diff(G, central_jacobian(phi, q));
  record("rel_G_fd", dG);
  EXPECT_LT(dG, 1e-9);
  const VecX l = random_vector(g, j.constraint_count());
  MatX H = MatX::Zero(n, n);
  j.add_constraint_hessian(l, H);
  auto gl = [&](const VecX& x) -> VecX {
    return j.jacobian(x.head(na), x.tail(nb)).transpose() * l;
  };
  const double dH = rel_diff(H, central_jacobian(gl, q));
  record("rel_H_fd", dH);
  EXPECT_LT(dH, 1e-9);
}

// G(q) P(q) = 0 for every q ∈ R^{n_A + n_B} (not only on the manifold): the midpoint evaluation is
// then a discrete null space, 𝖦 P(q_{n+½}) = G(q_{n+½}) P(q_{n+½}) = 0 (DNSM-III Table 3, iii.1).
TEST_P(DirectorJointTest, NullSpaceAnnihilatesJacobianEverywhere) {
  std::mt19937 g(130 + GetParam());
  const Case c = make_case(GetParam(), g);
  const joints::Joint& j = *c.joint;
  const int na = c.qa0.size(), nb = c.qb0.size(), n = na + nb;
  double worst = 0.0;
  for (int k = 0; k < 10; ++k) {
    const VecX q = random_vector(g, n, 2.0);
    const MatX G = j.jacobian(q.head(na), q.tail(nb));
    const MatX P = joint_null_space(j, q.head(na), q.tail(nb));
    const double rel = (G * P).norm() / (G.norm() * P.norm());
    worst = std::max(worst, rel);
    EXPECT_LT(rel, 1e-12);
  }
  record("max_rel_GP", worst);
  // At assembly: internal and joint rows independent, and range P = null G (of dimension
  // n − m_int − m: a director parent's drilling and τ may move the child alike, so P can have
  // more columns than its rank).
  const int m_all =
      internal_rows(j.parent_kind()) + internal_rows(j.child_kind()) + j.constraint_count();
  MatX Gall = MatX::Zero(m_all, n);
  Gall.topLeftCorner(internal_rows(j.parent_kind()), na) =
      internal_jacobian(j.parent_kind(), c.qa0);
  Gall.block(internal_rows(j.parent_kind()), na, internal_rows(j.child_kind()), nb) =
      internal_jacobian(j.child_kind(), c.qb0);
  Gall.bottomRows(j.constraint_count()) = j.jacobian(c.qa0, c.qb0);
  const MatX P0 = joint_null_space(j, c.qa0, c.qb0);
  EXPECT_EQ(rank(Gall), m_all);
  EXPECT_EQ(rank(P0), n - m_all);
  EXPECT_LT((Gall * P0).norm(), 1e-13 * Gall.norm() * P0.norm());
  // Each joint velocity moves the child.
  const MatX PB = internal_null_space(j.child_kind(), c.qb0) * j.freedom_block(c.qa0, c.qb0);
  EXPECT_EQ(rank(PB), j.freedom_count());
}

// From a consistent configuration at t_n (the parent moved by random rigid steps, the child by
// the joint's own update map), over three steps:
//   - the rows and the child's internal constraints hold at t_{n+1};
//   - ∂q_B,n+1/∂τ = P_int(q_B,n+1) B̃ (B̃ = update_freedom_block);
//   - the derivative w.r.t. the parent's motion at t_{n+1} (δφ_A, δQ_A = δω̂ Q_A, the parent
//     turned about φ_A,n+1) is P_int(q_B,n+1) A(q_n+1) (δφ_A, δω_A) (joint.hpp);
//   - step_b carries the child's orientation from t_n to t_{n+1}.
TEST_P(DirectorJointTest, UpdateMapKeepsConstraintsAndMatchesVelocityAnalysis) {
  std::mt19937 g(140 + GetParam());
  const Case c = make_case(GetParam(), g);
  const joints::Joint& j = *c.joint;
  const int r = j.freedom_count();
  const NodeKind kb = j.child_kind();
  VecX qa_n = c.qa0, qb_n = c.qb0;
  double worst_phi = 0.0, worst_int = 0.0, worst_step = 0.0, worst_tau = 0.0, worst_parent = 0.0;
  for (int step = 0; step < 3; ++step) {
    SCOPED_TRACE("step " + std::to_string(step));
    Mat3 QA = Mat3::Identity();
    Vec3 dphi = Vec3::Zero();
    if (!c.ground_parent) {
      QA = rodrigues(random_vector(g, 3, 0.8));
      dphi = random_vector(g, 3, 0.8);
    }
    const VecX qa_n1 = moved(qa_n, dphi, QA);
    const VecX tau = random_vector(g, r, 0.8);
    Mat3 step_b = Mat3::Zero();
    const VecX qb_n1 = j.update(qa_n, qa_n1, QA, qb_n, tau, &step_b);
    ASSERT_EQ(qb_n1.size(), coords(kb));

    VecX q_n1(qa_n1.size() + qb_n1.size());
    q_n1 << qa_n1, qb_n1;
    const double rel_phi = j.constraints(qa_n1, qb_n1).norm() / std::max(1.0, q_n1.norm());
    worst_phi = std::max(worst_phi, rel_phi);
    EXPECT_LT(rel_phi, 1e-14);
    worst_int = std::max(worst_int, internal_residual(kb, qb_n1));
    EXPECT_LT(internal_residual(kb, qb_n1), 1e-14);

    const double ds = (step_b * orientation(kb, qb_n) - orientation(kb, qb_n1)).norm();
    worst_step = std::max(worst_step, ds);
    EXPECT_LT(ds, 1e-14);
    EXPECT_LT((step_b.transpose() * step_b - Mat3::Identity()).norm(), 1e-14);

    const MatX Pb = internal_null_space(kb, qb_n1);
    if (r > 0) {
      auto f = [&](const VecX& x) -> VecX {
        return j.update(qa_n, qa_n1, QA, qb_n, tau + x, nullptr);
      };
      const MatX Bt = j.update_freedom_block(qa_n1, qb_n, qb_n1, tau);
      ASSERT_EQ(Bt.rows(), 6);
      ASSERT_EQ(Bt.cols(), r);
      const double d = rel_diff(Pb * Bt, central_jacobian(f, VecX::Zero(r)));
      worst_tau = std::max(worst_tau, d);
      EXPECT_LT(d, 1e-8);
    }
    auto fa = [&](const VecX& x) -> VecX {
      const Mat3 E = rodrigues(x.tail<3>());
      return j.update(qa_n, moved(qa_n1, x.head<3>(), E), E * QA, qb_n, tau, nullptr);
    };
    const double d =
        rel_diff(Pb * j.parent_block(qa_n1, qb_n1), central_jacobian(fa, VecX::Zero(6)));
    worst_parent = std::max(worst_parent, d);
    EXPECT_LT(d, 1e-7);

    qa_n = qa_n1;
    qb_n = qb_n1;
  }
  record("max_rel_phi_n1", worst_phi);
  record("max_internal_n1", worst_int);
  record("max_step_b", worst_step);
  record("max_rel_dtau", worst_tau);
  record("max_rel_dparent", worst_parent);
}

// A zero step (parent at rest, τ = 0) leaves the child where it is, and the velocity analysis is
// the update map's derivative there:
// ∂q_B/∂τ = P_int(q_B) B(q), which ties freedom_block's columns (signs, order, tangent basis) to
// the τ the update map consumes — G·P = 0 alone cannot see a column's sign.
TEST_P(DirectorJointTest, FreedomBlockIsTheUpdateDerivativeAtZeroStep) {
  std::mt19937 g(160 + GetParam());
  const Case c = make_case(GetParam(), g);
  const joints::Joint& j = *c.joint;
  const int r = j.freedom_count();
  // A consistent configuration away from t = 0: the parent moved by E, the child updated.
  const Mat3 E = c.ground_parent ? Mat3::Identity() : random_rotation(g);
  const Vec3 dphi = c.ground_parent ? Vec3::Zero() : Vec3(random_vector(g, 3));
  const VecX qa = moved(c.qa0, dphi, E);
  const VecX qb = j.update(c.qa0, qa, E, c.qb0, random_vector(g, r, 0.8), nullptr);
  auto f = [&](const VecX& x) -> VecX {
    return j.update(qa, qa, Mat3::Identity(), qb, x, nullptr);
  };
  // A zero step is the identity.
  EXPECT_LT((f(VecX::Zero(r)) - qb).norm(), 1e-15 * std::max(1.0, qb.norm()));
  const MatX J = central_jacobian(f, VecX::Zero(r));
  ASSERT_EQ(J.cols(), r);
  const MatX PB = internal_null_space(j.child_kind(), qb) * j.freedom_block(qa, qb);
  const double d = rel_diff(PB, J);
  record("rel_B_fd", d);
  EXPECT_LT(d, 1e-8);
}

// The child's increment over a step (StepIncrement, from which the step's velocities come): the
// update less the start, and the same 10⁶ m from the origin (the ground stays), where the
// difference of the rounded coordinates is off by ~10⁻¹⁰ (docs/theory/schemes.md §7).
TEST_P(DirectorJointTest, IncrementIsTheUpdateLessTheStartWithoutCancellation) {
  std::mt19937 g(190 + GetParam());
  const Case c = make_case(GetParam(), g);
  expect_increments_without_cancellation(*c.joint, c.qa0, c.qb0, c.ground_parent, 1e-15, g);
}

INSTANTIATE_TEST_SUITE_P(AllJoints, DirectorJointTest, ::testing::Range(0, kCases),
                         [](const ::testing::TestParamInfo<int>& info) {
                           return std::string(kNames[info.param]);
                         });

// DNSM-III (65)–(68): the shared node of an intersection has one twist (φ̇, ω), and each node's
// velocity is P_int applied to it, [I 0; 0 −d̂_κ]. The joint's parametrization (t_A, τ) is that
// twist with ω = ω_A + τ d_A: P_J = P_paper [A B], and both span the same 6-dimensional space.
TEST(ShellIntersection, SpansThePapersSharedNodeVelocities) {
  std::mt19937 g(150);
  for (int k = 0; k < 5; ++k) {
    const VecX qa = random_director(g);
    VecX qb = random_director(g);
    qb.head<3>() = qa.head<3>();
    const joints::ShellIntersection j(qa, qb);
    EXPECT_DOUBLE_EQ(j.eta(), qa.tail<3>().dot(qb.tail<3>()));
    // The rows report nodes that do not coincide at t = 0 (System::compile rejects them) rather
    // than absorbing the gap: the update map puts φ_B on φ_A.
    VecX qb_apart = qb;
    qb_apart(0) += 0.5;
    EXPECT_DOUBLE_EQ(joints::ShellIntersection(qa, qb_apart).constraints(qa, qb_apart)(0), 0.5);
    MatX P_paper(12, 6);
    P_paper << dn::twist_null_space(qa), dn::twist_null_space(qb);  // (68) for κ = 1, 2
    MatX AB(6, 7);
    AB << j.parent_block(qa, qb), j.freedom_block(qa, qb);
    const MatX P = joint_null_space(j, qa, qb);
    EXPECT_LT((P - P_paper * AB).norm(), 1e-15);
    EXPECT_LT((j.jacobian(qa, qb) * P_paper).norm(), 1e-14);
    MatX both(12, 13);
    both << P, P_paper;
    EXPECT_EQ(rank(P_paper), 6);
    EXPECT_EQ(rank(P), 6);
    EXPECT_EQ(rank(both), 6);
  }
}

TEST(DirectorJoints, RejectDegenerateGeometry) {
  dn::Q qa, qb;
  qa << 0, 0, 0, 0, 0, 1;
  qb << 0, 0, 0, 0, 0, -1;
  EXPECT_THROW((void)joints::ShellIntersection(qa, qa), std::invalid_argument);
  EXPECT_THROW((void)joints::ShellIntersection(qa, qb), std::invalid_argument);
  qb.tail<3>() = Vec3(1, 0, 1).normalized();
  EXPECT_NO_THROW((void)joints::ShellIntersection(qa, qb));

  const double nan = std::numeric_limits<double>::quiet_NaN();
  auto about = [&](const Vec3& n) {
    return joints::DirectorSupport(qa, {{true, true, true}, DirectorCondition::about_axis, n});
  };
  EXPECT_THROW((void)about(Vec3::Zero()), std::invalid_argument);
  EXPECT_THROW((void)about(Vec3(nan, 0, 0)), std::invalid_argument);
  EXPECT_THROW((void)about(Vec3(0, 0, 2)), std::invalid_argument);  // n ∥ d: ω = τ n moves nothing
  EXPECT_NO_THROW((void)about(Vec3(2, 0, 0)));
}

// A body and a shell node fixed to each other are one constraint whichever is the tree's parent:
// configurations produced by one direction's update map satisfy the other direction's rows.
TEST(DirectorJoints, AttachmentIsTheSameConstraintInBothDirections) {
  std::mt19937 g(170);
  const VecX body0 = random_frame(g), node0 = random_director(g);
  const joints::DirectorOnFrame node_on_body(body0, node0);
  const joints::FrameOnDirector body_on_node(node0, body0);
  VecX body = body0, node = node0;
  for (int step = 0; step < 3; ++step) {  // the body leads
    const Mat3 E = random_rotation(g);
    const VecX body1 = moved(body, random_vector(g, 3), E);
    node = node_on_body.update(body, body1, E, node, VecX(0), nullptr);
    body = body1;
    EXPECT_LT(body_on_node.constraints(node, body).norm(), 1e-14);
  }
  body = body0, node = node0;
  for (int step = 0; step < 3; ++step) {  // the node leads; the body spins about d freely
    const Mat3 E = random_rotation(g);
    const VecX node1 = moved(node, random_vector(g, 3), E);
    body = body_on_node.update(node, node1, E, body, random_vector(g, 1), nullptr);
    node = node1;
    EXPECT_LT(node_on_body.constraints(body, node).norm(), 1e-14);
  }
}
