// A Kirchhoff–Love plate clamped to a spinning rigid hub (examples/kl_plate_on_hub): point nodes
// attached to a frame node by tree joints (joints/point_joints.hpp), the KL patch element and a
// rigid body in one System. After the torque pulse energy and momenta are conserved to round-off
// in every formulation, the formulations agree, the joints hold to round-off, and the scheme is
// second order in Δt.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/io/model_reader.hpp"
#include "support/examples.hpp"
#include "support/sanitizers.hpp"
#include "support/trajectory.hpp"

using namespace isoflex;
using F = model::Formulation;

namespace {

model::Model hub(const std::string& text, double t_end, double dt) {
  model::Model m = io::read_model_string(text, "model.yaml");
  m.solver.t_end = t_end;
  m.solver.dt = dt;
  return m;
}

std::string example() {
  return test::example_text("kl_plate_on_hub", "model.yaml");
}

}  // namespace

TEST(KLPlateOnHub, Counts) {
  const auto sys = system::System::compile(hub(example(), 0.1, 0.01));
  EXPECT_EQ(sys.node_count(NodeKind::frame), 1);
  EXPECT_EQ(sys.node_count(NodeKind::point), 55);  // 11 × 5 control points
  EXPECT_EQ(sys.n(), 12 + 3 * 55);
  EXPECT_EQ(sys.m_selected(), 6 + 3 * 10);  // the hub's 6, 10 attached control points
  EXPECT_EQ(sys.k(), 6 + 3 * 45);           // the hub's twist, 45 free control points
  EXPECT_TRUE(sys.redundant_rows().empty());
}

TEST(KLPlateOnHub, ConservesAndTheFormulationsAgree) {
  ISOFLEX_SKIP_LONG_RUN_UNDER_ASAN();
  const model::Model m = hub(example(), 0.5, 0.01);
  std::vector<std::vector<Vec3>> tip;
  std::vector<int> unknowns;
  for (F f : {F::reparametrized, F::constrained, F::nullspace}) {
    const test::Trajectory r = test::simulate(m, f);
    tip.push_back(r.probe("tip"));
    unknowns.push_back(r.unknowns);
    const auto& s = r.snapshots;
    const std::size_t i0 = r.first_at(0.2);
    ASSERT_GT(s[i0].total_energy, 1.0);
    for (std::size_t i = i0; i < s.size(); ++i) {
      EXPECT_LT(std::abs(s[i].total_energy - s[i0].total_energy) / s[i0].total_energy, 1e-12) << i;
      // p = 0: the pulse is a pure torque.
      EXPECT_LT((s[i].linear_momentum - s[i0].linear_momentum).norm(), 1e-11) << i;
      EXPECT_LT(
          (s[i].angular_momentum - s[i0].angular_momentum).norm() / s[i0].angular_momentum.norm(),
          1e-12)
          << i;
    }
    for (const auto& x : s) EXPECT_LT(x.constraint_violation, 1e-13);
  }
  EXPECT_EQ(unknowns, (std::vector<int>{141, 177 + 36, 177}));
  for (std::size_t k = 1; k < tip.size(); ++k)
    for (std::size_t i = 0; i < tip[0].size(); ++i)
      EXPECT_LT((tip[k][i] - tip[0][i]).norm(), 1e-8) << k << " " << i;
}

TEST(KLPlateOnHub, SecondOrderInTheStep) {
  // As for the free plate, on a coarse (2 × 1 spans), soft, thick blade where every mode is
  // resolved: the tip at t = 0.4 for Δt = 0.01 … 0.00125, differences of successive runs.
  const std::string soft = test::replaced(
      test::replaced(test::replaced(example(), "knots_per_span: [7, 1]", "knots_per_span: [1, 0]"),
                     "E: 1.0e6", "E: 1.0e4"),
      "thickness: 0.02", "thickness: 0.05");
  std::vector<Vec3> at;
  for (double dt : {0.01, 0.005, 0.0025, 0.00125})
    at.push_back(test::simulate(hub(soft, 0.4, dt), F::reparametrized).probe("tip").back());
  for (double ratio : test::successive_ratios(at)) {
    EXPECT_GT(ratio, 3.6);
    EXPECT_LT(ratio, 4.4);
  }
}
