// Joint reactions (system/joint_reactions.hpp, reactions.csv) from the multipliers: a clamped
// cantilever's clamp carries the tip force and its moment (linear statics); in the rigid
// slider-crank (examples/slider_crank_rigid) the ground joints' forces with gravity balance the
// change of the total momentum at every step, the three formulations give the same reactions, and
// the constrained formulation's own multipliers are the recovered ones.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/integrate/static_equilibrium.hpp"
#include "isoflex/io/model_reader.hpp"
#include "isoflex/system/joint_reactions.hpp"
#include "support/examples.hpp"
#include "support/models.hpp"
#include "support/trajectory.hpp"

using namespace isoflex;
using F = model::Formulation;

namespace {

model::Model slider_crank(double t_end) {
  model::Model m =
      io::read_model_string(test::example_text("slider_crank_rigid", "model.yaml"), "model.yaml");
  m.solver.t_end = t_end;
  return m;
}

const integrate::ReactionValue& reaction(const integrate::Snapshot& s, const std::string& joint) {
  const auto it = std::find_if(s.reactions.begin(), s.reactions.end(),
                               [&](const integrate::ReactionValue& r) { return r.joint == joint; });
  EXPECT_NE(it, s.reactions.end()) << joint;
  return *it;
}

}  // namespace

TEST(JointReactions, ClampOfACantileverCarriesTheTipForceAndItsMoment) {
  const std::string text = test::cantilever_yaml(16, "[0.3, -0.2, \"t\"]");
  const model::Model m = io::read_model_string(text, "m.yaml");
  const auto sys = system::System::compile(m);
  integrate::StaticEquilibrium eq(sys, m.solver);
  const VecX x = eq.solve().x;
  const auto r =
      system::joint_reactions(sys, x.head(sys.n()), x.segment(sys.n(), sys.m_selected()));
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].joint, "clamp");
  const Vec3 P(0.3, -0.2, 1.0), arm(12.0, 0.0, 0.0);  // linear: the reference geometry
  EXPECT_LT((r[0].point - Vec3::Zero()).norm(), 1e-14);
  EXPECT_LT((r[0].force + P).norm(), 1e-10 * P.norm());
  EXPECT_LT((r[0].moment + arm.cross(P)).norm(), 1e-10 * arm.cross(P).norm());
  // The joint frame of a joint given without axis is the global frame at t = 0 (here the beam
  // does not turn it: linear analysis).
  EXPECT_LT((r[0].force_local - r[0].force).norm(), 1e-14);
  EXPECT_LT((r[0].moment_local - r[0].moment).norm(), 1e-13);
}

TEST(JointReactions, GroundReactionsBalanceTheMomentumInEveryFormulation) {
  const model::Model m = slider_crank(0.5);
  const double dt = m.solver.dt, mass = 3.0;
  const Vec3 g(0.0, -9.81, 0.0);
  std::vector<test::Trajectory> runs;
  for (F f : {F::reparametrized, F::constrained, F::nullspace}) {
    runs.push_back(test::simulate(m, f));
    const auto& s = runs.back().snapshots;
    EXPECT_TRUE(s.front().reactions.empty());
    double worst = 0.0, scale = 0.0;
    for (std::size_t i = 1; i < s.size(); ++i) {
      ASSERT_EQ(s[i].reactions.size(), 4u);
      const Vec3 ground =
          reaction(s[i], "crank_bearing").force + reaction(s[i], "slider_guide").force;
      const Vec3 dp = (s[i].linear_momentum - s[i - 1].linear_momentum) / dt;
      worst = std::max(worst, (dp - mass * g - ground).norm());
      scale = std::max(scale, ground.norm());
    }
    EXPECT_GT(scale, 10.0);
    EXPECT_LT(worst, 1e-9 * scale) << static_cast<int>(f);
  }
  for (std::size_t k = 1; k < runs.size(); ++k)
    for (std::size_t i = 1; i < runs[0].snapshots.size(); ++i)
      for (std::size_t j = 0; j < 4; ++j) {
        const auto &a = runs[0].snapshots[i].reactions[j], &b = runs[k].snapshots[i].reactions[j];
        EXPECT_LT((a.force - b.force).norm() + (a.moment - b.moment).norm(), 1e-6) << k << i << j;
      }
}

TEST(JointReactions, RecoveredMultipliersAreTheConstrainedFormulations) {
  model::Model m = slider_crank(0.05);
  m.solver.formulation = F::constrained;
  const auto sys = system::System::compile(m);
  const integrate::EnergyMomentumIntegrator integ(sys, m.solver);
  auto s = integ.initial_state();
  for (int i = 0; i < 10; ++i) {
    integ.step(s);
    const VecX own = s.last_unknowns.tail(sys.m_selected());
    ASSERT_EQ(s.lambda.size(), own.size());
    EXPECT_LT((s.lambda - own).norm(), 1e-9 * own.norm()) << i;
  }
}

// Joints with a director-shell node (system/joint_reactions.hpp, node reactions): a plate whose
// edge is attached to a hub (rigid joints "p[i]-hub", director node to frame node), the hub
// clamped to the ground, a force P at the plate's far corner, linear statics. The attachments
// hold the plate's nodes with −P together (on body_b, the shell nodes), and the clamp the hub
// with −P.
TEST(JointReactions, DirectorNodeJointsCarryTheLoadToTheHub) {
  const model::Model m = io::read_model_string(R"yaml(
solver: {analysis: static, dt: 1, t_end: 1, linear: true}
bodies:
  - {name: hub, mass: 2, inertia: [0.1, 0.2, 0.3], position: [-0.1, 0.25, 0]}
joints:
  - {name: clamp, type: fixed, body_a: ground, body_b: hub}
shells:
  - name: p
    plate: {corners: [[0, 0, 0], [1, 0, 0], [1, 0.5, 0], [0, 0.5, 0]], elements: [3, 2]}
    material: {E: 1.0e5, nu: 0.3, thickness: 0.05, density: 100}
shell_connections:
  - {shell: p, edge: u0, attach_to: hub}
shell_loads:
  - {shell: p, nodes: [3], force: ["0.2*t", "0.1*t", "-0.5*t"]}
)yaml",
                                               "m.yaml");
  const auto sys = system::System::compile(m);
  integrate::StaticEquilibrium eq(sys, m.solver);
  const VecX x = eq.solve().x;
  const auto r =
      system::joint_reactions(sys, x.head(sys.n()), x.segment(sys.n(), sys.m_selected()));
  const Vec3 P(0.2, 0.1, -0.5);
  Vec3 attached = Vec3::Zero(), clamp = Vec3::Zero();
  int count = 0;
  for (const auto& j : r) {
    if (j.joint == "clamp") {
      clamp = j.force;
    } else {
      EXPECT_NE(j.joint.find("-hub"), std::string::npos) << j.joint;
      attached += j.force;
      ++count;
    }
  }
  std::printf(
      "  [reactions] %d attachments carry (%.6g, %.6g, %.6g), the clamp (%.6g, %.6g, %.6g)\n",
      count, attached.x(), attached.y(), attached.z(), clamp.x(), clamp.y(), clamp.z());
  EXPECT_EQ(count, 3);  // the 3 nodes of edge u0
  EXPECT_LT((clamp + P).norm(), 1e-10 * P.norm());
  EXPECT_LT((attached + P).norm(), 1e-10 * P.norm());  // on body_b, the plate's nodes
}
