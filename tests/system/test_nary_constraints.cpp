// N-ary constraints (joints/constraint.hpp) in System: a Kirchhoff–Love plate in a dynamic run
// held by supports that are not rigid attachments — one component of an edge (`fixed: [z]`) and
// a symmetry edge — which become homogeneous linear rows over the control points they touch
// (joints::LinearRows), loop-closing rows of every formulation. Checked: the assembled Jacobian
// is the derivative of the rows, the corner row that both supports fix is found redundant by the
// full-pivot LU and dropped, and after a load pulse the motion keeps the rows to round-off,
// conserves energy to round-off, and is the same in the three formulations. And a spherical joint
// at a point of a free patch found by point projection (a body hinged to the plate, three linear
// rows over the body's frame node and the control points there): energy, linear and angular
// momentum conserved after a pulse, the two material points kept together, the formulations
// equal; a joint type that is not spherical is a located error.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "isoflex/io/model_reader.hpp"
#include "isoflex/math/skew.hpp"
#include "support/finite_difference.hpp"
#include "support/trajectory.hpp"

using namespace isoflex;

namespace {

// A free bicubic plate 1 × 0.5 (2 × 1 elements), the part both models share.
constexpr const char* kFreePlate = R"yaml(solver: {dt: 0.01, t_end: 0.6}
surfaces:
  - name: sheet
    builtin: {type: rectangle, size: [1, 0.5]}
    refine: {elevate: [2, 2], knots_per_span: [1, 0]}
kl_shells:
  - {name: plate, surface: sheet, material: {E: 1.0e4, nu: 0.3, thickness: 0.05, density: 1000}}
)yaml";

constexpr const char* kPlate = R"yaml(kl_supports:
  - {shell: plate, edge: u0, fixed: [z]}
  - {shell: plate, edge: v0, symmetry: [0, 1, 0]}
kl_loads:
  - {shell: plate, edge: u1, force_per_length: [0, 0, "40*sin(5*pi*t)^2*(t<=0.2)"]}
probes:
  - {name: tip, shell: plate, point: [1, 0.5, 0]}
)yaml";

model::Model plate() {
  return io::read_model_string(std::string(kFreePlate) + kPlate, "plate.yaml");
}

}  // namespace

TEST(NaryConstraints, SupportRowsAreCountedAndTheCornerRowIsRedundant) {
  const auto sys = system::System::compile(plate());
  ASSERT_EQ(sys.nary_constraints().size(), 2u);
  // u0 (4 control points): 4 z rows. v0 (5 control points): n·u = u_y on row 0 (5) and the
  // in-plane slope across the edge, two tangents × 5 pairs (10).
  EXPECT_EQ(sys.nary_constraints()[0].constraint->constraint_count(), 4);
  EXPECT_EQ(sys.nary_constraints()[1].constraint->constraint_count(), 15);
  EXPECT_EQ(sys.m_all(), 19);
  // At the corner both fix the slope's z part: one row is dependent.
  ASSERT_EQ(sys.redundant_rows().size(), 1u);
  EXPECT_EQ(sys.cut_rank(), 18);
  EXPECT_EQ(sys.cut_rank_qr(), 18);
}

TEST(NaryConstraints, JacobianIsTheDerivativeOfTheRows) {
  const auto sys = system::System::compile(plate());
  std::mt19937 g(5);
  const VecX q = sys.q0() + test::random_vector(g, sys.n(), 0.1);
  std::vector<int> all(static_cast<std::size_t>(sys.m_all()));
  for (int i = 0; i < sys.m_all(); ++i) all[static_cast<std::size_t>(i)] = i;
  const MatX G = MatX(sys.jacobian_rows(q, all));
  const MatX G_fd =
      test::central_jacobian([&](const VecX& x) { return sys.constraints(x, 0.0); }, q);
  EXPECT_LT(test::rel_diff(G, G_fd), 1e-9);
  EXPECT_LT(sys.constraints(sys.q0(), 0.0).lpNorm<Eigen::Infinity>(), 1e-15);
}

TEST(NaryConstraints, PulsedPlateKeepsTheRowsConservesEnergyInEveryFormulation) {
  using F = model::Formulation;
  std::vector<Vec3> tips;
  for (const F f : {F::reparametrized, F::constrained, F::nullspace}) {
    const test::Trajectory r = test::simulate(plate(), f);
    const std::size_t free = r.first_at(0.2);  // the pulse is over
    const double E0 = r.snapshots[free].total_energy;
    double drift = 0.0, phi = 0.0;
    for (std::size_t i = free; i < r.snapshots.size(); ++i)
      drift = std::max(drift, std::abs(r.snapshots[i].total_energy - E0) / E0);
    for (const auto& s : r.snapshots) phi = std::max(phi, s.constraint_violation);
    std::printf("  [nary] %s: energy drift after the pulse %.2e, max |Phi| %.2e\n",
                model::to_string(f), drift, phi);
    EXPECT_GT(E0, 0.1);
    EXPECT_LT(drift, 1e-11);
    EXPECT_LT(phi, 1e-12);
    tips.push_back(r.probe("tip").back());
  }
  EXPECT_GT(std::abs(tips[0].z()), 1e-3);  // it moved
  EXPECT_LT((tips[1] - tips[0]).norm(), 1e-8);
  EXPECT_LT((tips[2] - tips[0]).norm(), 1e-8);
}

namespace {

constexpr const char* kBall = R"yaml(bodies:
  - {name: ball, mass: 5, inertia: [0.02, 0.02, 0.02], position: [1.1, 0.3, 0.05]}
joints:
  - {name: hinge, type: TYPE, body_a: ball, body_b: plate, point: [0.7, 0.3, 0]}
loads:
  - {body: ball, force: [0, "20*sin(5*pi*t)^2*(t<=0.2)", "40*sin(5*pi*t)^2*(t<=0.2)"],
     moment: ["2*sin(5*pi*t)^2*(t<=0.2)", 0, 0]}
probes:
  - {name: hinge_on_plate, shell: plate, point: [0.7, 0.3, 0]}
  - {name: hinge_on_ball, body: ball, point: [0.7, 0.3, 0]}
)yaml";

std::string ball(const std::string& type) {
  std::string text = std::string(kFreePlate) + kBall;
  text.replace(text.find("TYPE"), 4, type);
  return text;
}

}  // namespace

TEST(NaryConstraints, SphericalJointAtAShellPointConservesEnergyAndMomenta) {
  const model::Model m = io::read_model_string(ball("spherical"), "ball.yaml");
  ASSERT_TRUE(m.joints.empty());
  ASSERT_EQ(m.kl_surface_joints.size(), 1u);
  const auto sys = system::System::compile(m);
  ASSERT_EQ(sys.nary_constraints().size(), 1u);
  EXPECT_EQ(sys.nary_constraints()[0].constraint->constraint_count(), 3);
  // The body's frame node and the 4 × 4 control points of the span the point lies in.
  EXPECT_EQ(sys.nary_constraints()[0].constraint->nodes().size(), 17u);
  using F = model::Formulation;
  std::vector<Vec3> tips;
  for (const F f : {F::reparametrized, F::constrained, F::nullspace}) {
    const test::Trajectory r = test::simulate(m, f);
    const std::size_t free = r.first_at(0.2);
    const auto& s0 = r.snapshots[free];
    double dE = 0.0, dp = 0.0, dL = 0.0, gap = 0.0;
    for (std::size_t i = free; i < r.snapshots.size(); ++i) {
      const auto& s = r.snapshots[i];
      dE = std::max(dE, std::abs(s.total_energy - s0.total_energy) / s0.total_energy);
      dp =
          std::max(dp, (s.linear_momentum - s0.linear_momentum).norm() / s0.linear_momentum.norm());
      dL = std::max(dL,
                    (s.angular_momentum - s0.angular_momentum).norm() / s0.angular_momentum.norm());
    }
    const auto on_plate = r.probe("hinge_on_plate"), on_ball = r.probe("hinge_on_ball");
    for (std::size_t i = 0; i < on_plate.size(); ++i)
      gap = std::max(gap, (on_plate[i] - on_ball[i]).norm());
    std::printf("  [nary] hinge, %s: after the pulse drift E %.2e, p %.2e, L %.2e; gap %.2e\n",
                model::to_string(f), dE, dp, dL, gap);
    EXPECT_LT(dE, 1e-11);
    EXPECT_LT(dp, 1e-11);
    EXPECT_LT(dL, 1e-11);
    EXPECT_LT(gap, 1e-12);
    tips.push_back(on_plate.back());
  }
  EXPECT_GT((tips[0] - Vec3(0.7, 0.3, 0.0)).norm(), 1e-2);  // it moved
  EXPECT_LT((tips[1] - tips[0]).norm(), 1e-8);
  EXPECT_LT((tips[2] - tips[0]).norm(), 1e-8);
}

TEST(NaryConstraints, AJointAtAShellPointIsSphericalOrRevoluteWithANormalOrTangentAxis) {
  const auto error = [](const std::string& text) -> std::string {
    try {
      io::read_model_string(text, "ball.yaml");
    } catch (const std::exception& e) {
      return e.what();
    }
    return "no error";
  };
  EXPECT_EQ(error(ball("prismatic, axis: [0, 0, 1]")),
            "ball.yaml:11: joints[0].type: \"plate\" is a Kirchhoff–Love shell: a joint at a "
            "point of its surface is spherical or revolute (name a control point \"plate[A]\" for "
            "a rigid attachment)");
  EXPECT_EQ(error(ball("revolute")),
            "ball.yaml:11: joints[0]: a revolute joint at a shell point requires `axis` (or "
            "`axis_a`)");
  EXPECT_EQ(error(ball("spherical, axis: [0, 0, 1]")),
            "ball.yaml:11: joints[0].axis: not allowed for a spherical joint");
  try {
    system::System::compile(io::read_model_string(ball("revolute, axis: [0, 1, 1]"), "ball.yaml"));
    FAIL() << "no error";
  } catch (const std::exception& e) {
    EXPECT_EQ(std::string(e.what()),
              "ball.yaml:11: hinge.axis: the axis makes 45° with the normal of 'plate' at the "
              "joint point: a revolute joint at a shell point takes an axis normal or tangent to "
              "the surface there (within 1e-9)");
  }
}

namespace {

// The rigid velocities of a system's coordinates at q (translations, rotations about the
// origin): every position moves, every director turns.
MatX rigid_velocities(const system::System& sys, const VecX& q) {
  MatX P = MatX::Zero(sys.n(), 6);
  for (int i = 0; i < sys.node_count(); ++i) {
    const int o = sys.q_offset(i);
    P.block<3, 3>(o, 0) = Mat3::Identity();
    for (int k = 0; k < sys.coordinate_count(i) / 3; ++k)
      P.block<3, 3>(o + 3 * k, 3) = -skew(Vec3(q.segment<3>(o + 3 * k)));
    if (sys.node_kind(i) == NodeKind::frame)
      for (int k = 1; k < 4; ++k) P.block<3, 3>(o + 3 * k, 0).setZero();  // directors
  }
  return P;
}

}  // namespace

// The revolute joint at a shell point (joints/quadratic_rows.hpp): with the axis normal to the
// plate (a_α · Y_I d_I) and tangent to it ((c^α a_α) · Z^k_I d_I), through System: the Jacobian
// against central differences, the midpoint Jacobian an exact discrete derivative, the rows
// invariant under a rigid motion of everything and G P = 0 for the rigid velocities.
TEST(NaryConstraints, RevoluteAtAShellPointRowsAreExactAndInvariant) {
  for (const char* axis : {"[0, 0, 1]", "[1, 0, 0]", "[0.6, 0.8, 0]"}) {
    SCOPED_TRACE(axis);
    const auto sys = system::System::compile(
        io::read_model_string(ball(std::string("revolute, axis: ") + axis), "ball.yaml"));
    ASSERT_EQ(sys.nary_constraints().size(), 1u);
    EXPECT_EQ(sys.nary_constraints()[0].type, "revolute_at_shell_point");
    EXPECT_EQ(sys.nary_constraints()[0].constraint->constraint_count(), 5);
    std::mt19937 g(11);
    std::vector<int> all(static_cast<std::size_t>(sys.m_all()));
    for (int i = 0; i < sys.m_all(); ++i) all[static_cast<std::size_t>(i)] = i;
    EXPECT_LT(sys.constraints(sys.q0(), 0.0).lpNorm<Eigen::Infinity>(), 1e-15);
    const VecX qa = sys.q0() + test::random_vector(g, sys.n(), 0.1);
    const VecX qb = sys.q0() + test::random_vector(g, sys.n(), 0.1);
    const MatX G = MatX(sys.jacobian_rows(qa, all));
    const MatX G_fd =
        test::central_jacobian([&](const VecX& x) { return sys.constraints(x, 0.0); }, qa);
    EXPECT_LT(test::rel_diff(G, G_fd), 1e-9);
    const VecX dphi = sys.constraints(qb, 0.0) - sys.constraints(qa, 0.0);
    const VecX Gt_dq = MatX(sys.discrete_jacobian_rows(qa, qb, all)) * (qb - qa);
    EXPECT_LT((Gt_dq - dphi).lpNorm<Eigen::Infinity>(), 1e-14 * dphi.lpNorm<Eigen::Infinity>());
    // Rigid motions: every row is invariant under translation; the axis rows under rotation
    // too, while the point rows turn with it (a vector); on the manifold, e.g. at a rigid motion
    // of the reference, G annihilates the rigid velocities (no constraint force or moment).
    const int r0 = sys.nary_constraints()[0].row_offset;
    const Mat3 R = Eigen::AngleAxisd(0.7, Vec3(1, 2, -0.5).normalized()).toRotationMatrix();
    const Vec3 c(0.3, -1.0, 2.0);
    const auto rigidly = [&](const VecX& q, const Mat3& Q, const Vec3& shift) {
      VecX out = q;
      for (int i = 0; i < sys.node_count(); ++i) {
        const int o = sys.q_offset(i);
        for (int k = 0; k < sys.coordinate_count(i) / 3; ++k)
          out.segment<3>(o + 3 * k) = Q * q.segment<3>(o + 3 * k);
        out.segment<3>(o) += shift;
      }
      return out;
    };
    const VecX phi = sys.constraints(qa, 0.0);
    EXPECT_LT((sys.constraints(rigidly(qa, Mat3::Identity(), c), 0.0) - phi).norm(), 1e-13);
    EXPECT_LT((sys.constraints(rigidly(qa, R, c), 0.0).segment<2>(r0 + 3) - phi.segment<2>(r0 + 3))
                  .norm(),
              1e-13);
    EXPECT_LT((G * rigid_velocities(sys, qa)).leftCols<3>().lpNorm<Eigen::Infinity>(), 1e-13);
    EXPECT_LT((G * rigid_velocities(sys, qa)).middleRows<2>(r0 + 3).lpNorm<Eigen::Infinity>(),
              1e-13);
    const VecX on = rigidly(sys.q0(), R, c);
    EXPECT_LT(sys.constraints(on, 0.0).lpNorm<Eigen::Infinity>(), 1e-14);
    EXPECT_LT(
        (MatX(sys.jacobian_rows(on, all)) * rigid_velocities(sys, on)).lpNorm<Eigen::Infinity>(),
        1e-13);
  }
}

// A ball hinged to the free plate by a revolute joint, pushed and twisted: after the pulse
// energy and both momenta are conserved, the points stay together and the axis in place (the
// rows, in |Φ|), the three formulations agree, and the motion is not the spherical joint's.
TEST(NaryConstraints, RevoluteJointAtAShellPointConservesEnergyAndMomenta) {
  using F = model::Formulation;
  const model::Model spherical = io::read_model_string(ball("spherical"), "ball.yaml");
  const Vec3 free_tip = test::simulate(spherical, F::reparametrized).probe("hinge_on_plate").back();
  for (const char* axis : {"[0, 0, 1]", "[1, 0, 0]"}) {
    const model::Model m =
        io::read_model_string(ball(std::string("revolute, axis: ") + axis), "ball.yaml");
    std::vector<Vec3> tips;
    for (const F f : {F::reparametrized, F::constrained, F::nullspace}) {
      const test::Trajectory r = test::simulate(m, f);
      const test::Drift d = test::drift_after(r, 0.2);
      double phi = 0.0;
      for (const auto& s : r.snapshots) phi = std::max(phi, s.constraint_violation);
      std::printf(
          "  [nary] revolute %s, %s: after the pulse drift E %.2e, p %.2e, L %.2e; "
          "|Phi| %.2e\n",
          axis, model::to_string(f), d.energy, d.p, d.L, phi);
      EXPECT_LT(d.energy, 1e-11);
      EXPECT_LT(d.p, 1e-11);
      EXPECT_LT(d.L, 1e-11);
      EXPECT_LT(phi, 1e-12);
      tips.push_back(r.probe("hinge_on_plate").back());
    }
    EXPECT_GT((tips[0] - Vec3(0.7, 0.3, 0.0)).norm(), 1e-2);  // it moved
    EXPECT_GT((tips[0] - free_tip).norm(), 1e-3);             // not as with a ball joint
    EXPECT_LT((tips[1] - tips[0]).norm(), 1e-8);
    EXPECT_LT((tips[2] - tips[0]).norm(), 1e-8);
  }
}
