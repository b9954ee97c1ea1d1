#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

#include "isoflex/joints/point_joints.hpp"
#include "isoflex/math/node_kind.hpp"
#include "isoflex/math/rotation.hpp"
#include "isoflex/math/skew.hpp"
#include "support/finite_difference.hpp"
#include "support/joint_increments.hpp"

using namespace isoflex;
using namespace isoflex::test;
using joints::PointOnFrame;
namespace fn = isoflex::frame_node;

namespace {
constexpr int kNa = 12, kNb = 3, kN = kNa + kNb;

VecX random_frame(std::mt19937& g) {
  return fn::make(random_vector(g, 3), random_rotation(g));
}
VecX ground() {
  return fn::make(Vec3::Zero(), Mat3::Identity());
}
VecX stacked(const VecX& qa, const VecX& qb) {
  VecX q(qa.size() + qb.size());
  q << qa, qb;
  return q;
}
MatX twist_null_space(NodeKind k, const VecX& q) {  // P_int(q), n × 6
  return MatX(node_type(k).twist_null_space(q));
}

// q̇ = (P_int(q_A) t_A, P_int(q_B) A t_A), 15 × 6 (r = 0).
MatX joint_null_space(const joints::Joint& j, const VecX& qa, const VecX& qb) {
  MatX P(kN, 6);
  P.topRows(kNa) = twist_null_space(NodeKind::frame, qa);
  P.bottomRows(kNb) = twist_null_space(NodeKind::point, qb) * j.parent_block(qa, qb);
  return P;
}

// A joint from a random frame node and a random point at t = 0.
struct Case {
  VecX qa0, qb0;
  PointOnFrame joint;
};
Case make_case(std::mt19937& g) {
  const VecX qa0 = random_frame(g);
  const VecX qb0 = random_vector(g, 3, 2.0);
  return {qa0, qb0, PointOnFrame(qa0, qb0)};
}

// Measured residuals go to the XML report (--gtest_output=xml) in scientific notation.
void record(const std::string& key, double value) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2e", value);
  ::testing::Test::RecordProperty(key, buf);
}

int rank(const MatX& M) {
  Eigen::FullPivLU<MatX> lu(M);
  lu.setThreshold(1e-10);
  return static_cast<int>(lu.rank());
}
}  // namespace

TEST(PointOnFrame, CountsRowsAndHoldsAtAssembly) {
  std::mt19937 g(210);
  const Case c = make_case(g);
  const PointOnFrame& j = c.joint;
  EXPECT_EQ(j.parent_kind(), NodeKind::frame);
  EXPECT_EQ(j.child_kind(), NodeKind::point);
  EXPECT_EQ(joints::coordinate_count(j.parent_kind()), kNa);
  EXPECT_EQ(joints::coordinate_count(j.child_kind()), kNb);
  // Rows and τ account for the point's three velocities.
  EXPECT_EQ(j.constraint_count(), 3);
  EXPECT_EQ(j.freedom_count(), 0);
  EXPECT_EQ(j.constraint_count() + j.freedom_count(), node_type(NodeKind::point).free_velocities());
  const MatX B = j.freedom_block(c.qa0, c.qb0);
  EXPECT_EQ(B.rows(), 6);
  EXPECT_EQ(B.cols(), 0);
  const MatX Bt = j.update_freedom_block(c.qa0, c.qb0, c.qb0, VecX(0));
  EXPECT_EQ(Bt.rows(), 6);
  EXPECT_EQ(Bt.cols(), 0);
  // X = D_A0ᵀ(φ_B0 − φ_A0): the material point of A at φ_B0.
  const Vec3 X_expected = fn::directors(c.qa0).transpose() * (c.qb0 - c.qa0.head<3>());
  EXPECT_LT((j.body_point() - X_expected).norm(), 1e-15 * X_expected.norm());
  const VecX phi = j.constraints(c.qa0, c.qb0);
  ASSERT_EQ(phi.size(), 3);
  const double rel = phi.norm() / stacked(c.qa0, c.qb0).norm();
  record("rel_phi_t0", rel);
  EXPECT_LT(rel, 1e-14);
}

// A = [I −ρ̂_A; 0 I] with ρ_A = X_I d_I^A taken from the parent's coordinates (for any q, with
// φ_B anywhere): ω_B = ω_A is passed on although P_int(q_B) = [I 0] ignores it, so the twist a
// point node reports is the parent's rigid motion at that point, as for every other child kind.
TEST(PointOnFrame, ParentBlockIsTheRigidMotionOfTheParent) {
  std::mt19937 g(215);
  const Case c = make_case(g);
  const VecX q = random_vector(g, kN, 2.0);
  const VecX qa = q.head(kNa), qb = q.tail(kNb);
  Vec3 rho = Vec3::Zero();
  for (int I = 0; I < 3; ++I) rho += c.joint.body_point()(I) * qa.segment<3>(3 + 3 * I);
  Mat<6, 6> A = Mat<6, 6>::Identity();
  A.block<3, 3>(0, 3) = -skew(rho);
  const double d = (c.joint.parent_block(qa, qb) - A).norm() / A.norm();
  record("rel_parent_block", d);
  EXPECT_LT(d, 1e-15);
}

// Jacobian against central differences at random q ∈ R¹⁵ (off the manifold: the directors are
// random vectors); the rows are linear, so add_constraint_hessian adds nothing and the FD of the
// Jacobian (applied to λ) vanishes.
TEST(PointOnFrame, JacobianAndHessianMatchFiniteDifferences) {
  std::mt19937 g(220);
  double worst_G = 0.0, worst_H = 0.0;
  for (int k = 0; k < 5; ++k) {
    const Case c = make_case(g);
    const PointOnFrame& j = c.joint;
    const VecX q = random_vector(g, kN, 2.0);
    auto phi = [&](const VecX& x) -> VecX { return j.constraints(x.head(kNa), x.tail(kNb)); };
    const MatX G = j.jacobian(q.head(kNa), q.tail(kNb));
    ASSERT_EQ(G.rows(), 3);
    ASSERT_EQ(G.cols(), kN);
    const double dG = rel_diff(G, central_jacobian(phi, q));
    worst_G = std::max(worst_G, dG);
    EXPECT_LT(dG, 1e-9);

    const VecX l = random_vector(g, 3);
    const MatX H0 = random_vector(g, kN * kN).reshaped(kN, kN);
    MatX H = H0;
    j.add_constraint_hessian(l, H);
    EXPECT_EQ(H, H0);  // bit for bit: nothing added
    auto gl = [&](const VecX& x) -> VecX {
      return j.jacobian(x.head(kNa), x.tail(kNb)).transpose() * l;
    };
    const double dH = rel_diff(H - H0, central_jacobian(gl, q));
    worst_H = std::max(worst_H, dH);
    EXPECT_LT(dH, 1e-9);
  }
  record("max_rel_G_fd", worst_G);
  record("max_rel_H_fd", worst_H);
}

// G(q)·[P_int(q_A) t_A; P_int(q_B) A t_A] = 0 for every q ∈ R¹⁵, not only on the manifold; hence
// at q_{n+½} of any two configurations, 𝖦 = G(q_{n+½}) (DNSM-III (23), checked as the discrete
// derivative identity) is annihilated by P(q_{n+½}) (DNSM-III Table 3, iii.1).
TEST(PointOnFrame, NullSpaceAnnihilatesJacobianOffTheManifold) {
  std::mt19937 g(230);
  double worst = 0.0, worst_mid = 0.0, worst_dd = 0.0;
  for (int k = 0; k < 10; ++k) {
    const Case c = make_case(g);
    const PointOnFrame& j = c.joint;
    // Continuous: random q and t_A.
    const VecX q = random_vector(g, kN, 2.0);
    const VecX qa = q.head(kNa), qb = q.tail(kNb);
    const VecX tA = random_vector(g, 6);
    VecX qdot(kN);
    qdot << twist_null_space(NodeKind::frame, qa) * tA,
        twist_null_space(NodeKind::point, qb) * (j.parent_block(qa, qb) * tA);
    const MatX G = j.jacobian(qa, qb);
    const double rel = (G * qdot).norm() / (G.norm() * qdot.norm());
    worst = std::max(worst, rel);
    EXPECT_LT(rel, 1e-14);

    // Discrete: two random configurations q_n, q_{n+1} (the rows need not hold at either).
    const VecX qn = random_vector(g, kN, 2.0), qn1 = random_vector(g, kN, 2.0);
    const VecX qm = 0.5 * (qn + qn1);
    const MatX Gm = j.jacobian(qm.head(kNa), qm.tail(kNb));
    const VecX dphi =
        j.constraints(qn1.head(kNa), qn1.tail(kNb)) - j.constraints(qn.head(kNa), qn.tail(kNb));
    const double dd = (dphi - Gm * (qn1 - qn)).norm() / (Gm.norm() * (qn1 - qn).norm());
    worst_dd = std::max(worst_dd, dd);
    EXPECT_LT(dd, 1e-14);
    const MatX Pm = joint_null_space(j, qm.head(kNa), qm.tail(kNb));
    const double rel_m = (Gm * Pm).norm() / (Gm.norm() * Pm.norm());
    worst_mid = std::max(worst_mid, rel_m);
    EXPECT_LT(rel_m, 1e-14);
  }
  record("max_rel_GP", worst);
  record("max_rel_discrete_derivative", worst_dd);
  record("max_rel_GP_midpoint", worst_mid);

  // At assembly: the frame's internal rows and the joint rows are independent (6 + 3), and
  // range P = null G (rank 15 − 9 = 6).
  const Case c = make_case(g);
  MatX Gall = MatX::Zero(9, kN);
  Gall.topLeftCorner(6, kNa) = node_type(NodeKind::frame).jacobian(c.qa0);
  Gall.bottomRows(3) = c.joint.jacobian(c.qa0, c.qb0);
  const MatX P0 = joint_null_space(c.joint, c.qa0, c.qb0);
  EXPECT_EQ(rank(Gall), 9);
  EXPECT_EQ(rank(P0), 6);
  EXPECT_LT((Gall * P0).norm(), 1e-14 * Gall.norm() * P0.norm());
}

// Φ = 0 at construction, and the update map keeps it to round-off after random parent motions
// (three steps): q_A,n+1 = frame_node::update(q_A,n, u), step_a = exp(θ̂), θ = u₄…₆.
TEST(PointOnFrame, UpdateKeepsConstraints) {
  std::mt19937 g(240);
  double worst = 0.0;
  for (int k = 0; k < 5; ++k) {
    const Case c = make_case(g);
    const PointOnFrame& j = c.joint;
    const double scale0 = stacked(c.qa0, c.qb0).norm();
    EXPECT_LT(j.constraints(c.qa0, c.qb0).norm(), 1e-14 * scale0);
    // The parent at rest: the point stays (to round-off of φ_A + D_A D_Aᵀ(φ_B − φ_A)).
    Mat3 step_b = Mat3::Zero();
    const VecX qb_rest = j.update(c.qa0, c.qa0, Mat3::Identity(), c.qb0, VecX(0), &step_b);
    EXPECT_LT((qb_rest - c.qb0).norm(), 1e-14 * scale0);
    EXPECT_EQ(step_b, Mat3::Identity());

    VecX qa_n = c.qa0, qb_n = c.qb0;
    for (int step = 0; step < 3; ++step) {
      const Vec<6> u = random_vector(g, 6, 1.5);
      const VecX qa_n1 = fn::update(qa_n, u);
      const Mat3 step_a = rodrigues(u.tail<3>());
      const VecX qb_n1 = j.update(qa_n, qa_n1, step_a, qb_n, VecX(0), &step_b);
      ASSERT_EQ(qb_n1.size(), kNb);
      const double rel = j.constraints(qa_n1, qb_n1).norm() / stacked(qa_n1, qb_n1).norm();
      worst = std::max(worst, rel);
      EXPECT_LT(rel, 1e-14);
      EXPECT_EQ(step_b, step_a);
      qa_n = qa_n1;
      qb_n = qb_n1;
    }
  }
  record("max_rel_phi_n1", worst);
}

// The point's increment over a step (StepIncrement, from which the step's velocities come): the
// update less the start, and the same 10⁶ m from the origin, where the difference of the rounded
// coordinates is off by ~10⁻¹⁰ (docs/theory/schemes.md §7).
TEST(PointOnFrame, IncrementIsTheUpdateLessTheStartWithoutCancellation) {
  std::mt19937 g(245);
  for (int k = 0; k < 3; ++k) {
    const Case c = make_case(g);
    expect_increments_without_cancellation(c.joint, c.qa0, c.qb0, false, 1e-15, g);
  }
}

// The update map's derivative is the velocity analysis at t_{n+1}: with q_A,n+1 = F(q_A,n, u),
// ∂φ_B,n+1/∂u = P_int(q_B,n+1) A(q_{n+1}) ∂t_A/∂u, ∂t_A/∂u = diag(I, T(θ)) (the frame node's
// root_update_block, DNSM-III (37)).
TEST(PointOnFrame, UpdateDerivativeIsTheVelocityAnalysis) {
  std::mt19937 g(250);
  const NodeType& frame = node_type(NodeKind::frame);
  double worst = 0.0;
  for (int k = 0; k < 5; ++k) {
    const Case c = make_case(g);
    const PointOnFrame& j = c.joint;
    // A consistent configuration at t_n away from t = 0.
    const Vec<6> u0 = random_vector(g, 6, 1.5);
    const VecX qa_n = fn::update(c.qa0, u0);
    const VecX qb_n = j.update(c.qa0, qa_n, rodrigues(u0.tail<3>()), c.qb0, VecX(0), nullptr);
    const Vec<6> u = random_vector(g, 6, 1.5);
    auto f = [&](const VecX& x) -> VecX {
      const Vec<6> v = x;
      return j.update(qa_n, fn::update(qa_n, v), rodrigues(v.tail<3>()), qb_n, VecX(0), nullptr);
    };
    const VecX qa_n1 = fn::update(qa_n, u);
    const VecX qb_n1 = f(u);
    const MatX expected = twist_null_space(NodeKind::point, qb_n1) * j.parent_block(qa_n1, qb_n1) *
                          MatX(frame.root_update_block(qa_n, u));
    const double d = rel_diff(expected, central_jacobian(f, u));
    worst = std::max(worst, d);
    EXPECT_LT(d, 1e-8);
  }
  record("max_rel_dparent", worst);
}

// The ground as parent (the frame at the origin, identity directors): X = φ_B0 and the point
// cannot move.
TEST(PointOnFrame, GroundParentFixesThePoint) {
  std::mt19937 g(260);
  const VecX qa = ground();
  const Vec3 p = random_vector(g, 3, 2.0);
  const PointOnFrame j(qa, p);
  EXPECT_EQ(j.body_point(), p);
  EXPECT_EQ(j.constraints(qa, p), VecX(Vec3::Zero()));
  const Vec3 moved = p + random_vector(g, 3);
  EXPECT_LT((j.constraints(qa, moved) - (moved - p)).norm(), 1e-15);
  // The rows fix all three coordinates of the point.
  EXPECT_EQ(MatX(j.jacobian(qa, p).rightCols(kNb)), MatX(Mat3::Identity()));
  // The ground does not move (t_A = 0), so neither does the point; the update returns it exactly.
  EXPECT_EQ(j.parent_block(qa, p) * Vec<6>::Zero(), Vec<6>::Zero());
  Mat3 step_b = Mat3::Zero();
  const VecX qb1 = j.update(qa, qa, Mat3::Identity(), moved, VecX(0), &step_b);
  EXPECT_EQ(qb1, VecX(p));
  EXPECT_EQ(step_b, Mat3::Identity());
}

// A rigid motion of the whole system (φ ↦ Eφ + c, d_I ↦ E d_I for both nodes) maps the rows to
// E Φ (for every q), keeps Φ = 0 on the manifold, and leaves the body coordinates X unchanged.
TEST(PointOnFrame, RigidMotionInvariance) {
  std::mt19937 g(270);
  double worst_phi = 0.0, worst_X = 0.0, worst_eq = 0.0;
  for (int k = 0; k < 5; ++k) {
    const Case c = make_case(g);
    const Mat3 E = random_rotation(g);
    const Vec3 t = random_vector(g, 3, 3.0);
    auto move_a = [&](const VecX& qa) -> VecX {
      VecX out(kNa);
      out.head<3>() = E * qa.head<3>() + t;
      for (int I = 0; I < 3; ++I) out.segment<3>(3 + 3 * I) = E * qa.segment<3>(3 + 3 * I);
      return out;
    };
    auto move_b = [&](const VecX& qb) -> VecX { return E * Vec3(qb) + t; };
    const VecX qa1 = move_a(c.qa0), qb1 = move_b(c.qb0);
    const double rel_phi = c.joint.constraints(qa1, qb1).norm() / stacked(qa1, qb1).norm();
    worst_phi = std::max(worst_phi, rel_phi);
    EXPECT_LT(rel_phi, 1e-14);
    const PointOnFrame moved(qa1, qb1);
    const double dX =
        (moved.body_point() - c.joint.body_point()).norm() / c.joint.body_point().norm();
    worst_X = std::max(worst_X, dX);
    EXPECT_LT(dX, 1e-14);
    // Off the manifold: Φ(g·q) = E Φ(q).
    const VecX q = random_vector(g, kN, 2.0);
    const VecX phi = c.joint.constraints(q.head(kNa), q.tail(kNb));
    const VecX phi_moved = c.joint.constraints(move_a(q.head(kNa)), move_b(q.tail(kNb)));
    const double eq = (phi_moved - E * Vec3(phi)).norm() / std::max(1.0, phi.norm());
    worst_eq = std::max(worst_eq, eq);
    EXPECT_LT(eq, 1e-14);
  }
  record("max_rel_phi_moved", worst_phi);
  record("max_rel_dX", worst_X);
  record("max_rel_equivariance", worst_eq);
}

TEST(PointOnFrame, RejectsNonFiniteInput) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const fn::Q qa = fn::make(Vec3(1, 2, 3), Mat3::Identity());
  EXPECT_NO_THROW((void)PointOnFrame(qa, Vec3(0, 1, 0)));
  EXPECT_THROW((void)PointOnFrame(qa, Vec3(nan, 1, 0)), std::invalid_argument);
  EXPECT_THROW((void)PointOnFrame(qa, Vec3(0, -inf, 0)), std::invalid_argument);
  fn::Q bad = qa;
  bad(7) = nan;  // a director entry
  EXPECT_THROW((void)PointOnFrame(bad, Vec3(0, 1, 0)), std::invalid_argument);
  bad = qa;
  bad(0) = inf;  // φ_A
  EXPECT_THROW((void)PointOnFrame(bad, Vec3(0, 1, 0)), std::invalid_argument);
}
