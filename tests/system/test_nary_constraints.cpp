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

TEST(NaryConstraints, AJointAtAShellPointIsSpherical) {
  try {
    io::read_model_string(ball("revolute"), "ball.yaml");
    FAIL() << "no error";
  } catch (const std::exception& e) {
    EXPECT_EQ(std::string(e.what()),
              "ball.yaml:11: joints[0].type: \"plate\" is a Kirchhoff–Love shell: a joint at a "
              "point of its surface is spherical (name a control point \"plate[A]\" for a rigid "
              "attachment)");
  }
}
