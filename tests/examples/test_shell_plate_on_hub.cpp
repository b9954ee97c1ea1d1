// A Reissner–Mindlin director-shell plate clamped to a spinning rigid hub
// (examples/shell_plate_on_hub): director nodes attached to a frame node by rigid tree joints,
// the director-shell element and a rigid body in one System. After the torque pulse energy and
// momenta are conserved to round-off in every formulation, the formulations agree, and Newton
// takes few iterations per step (issue #20's goal for this model: ≤ 8 on average).
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
model::Model hub(double t_end) {
  model::Model m =
      io::read_model_string(test::example_text("shell_plate_on_hub", "model.yaml"), "model.yaml");
  m.solver.t_end = t_end;
  return m;
}
}  // namespace

TEST(ShellPlateOnHub, Counts) {
  const auto sys = system::System::compile(hub(0.1));
  EXPECT_EQ(sys.node_count(NodeKind::frame), 1);
  EXPECT_EQ(sys.node_count(NodeKind::director), 85);  // 17 × 5 nodes
  EXPECT_EQ(sys.n(), 12 + 6 * 85);
  EXPECT_EQ(sys.m_selected(), 6 + 85 + 5 * 5);  // the hub's 6, |d| = 1, 5 attached nodes
  EXPECT_EQ(sys.k(), 6 + 5 * 80);               // the hub's twist, 80 free director nodes
  EXPECT_TRUE(sys.redundant_rows().empty());
}

TEST(ShellPlateOnHub, ConservesAndTheFormulationsAgree) {
  ISOFLEX_SKIP_LONG_RUN_UNDER_ASAN();
  const model::Model m = hub(0.5);
  std::vector<std::vector<Vec3>> tip;
  std::vector<int> unknowns;
  for (F f : {F::reparametrized, F::constrained, F::nullspace}) {
    const test::Trajectory r = test::simulate(m, f);
    tip.push_back(r.probe("tip"));
    unknowns.push_back(r.unknowns);
    const auto& s = r.snapshots;
    const std::size_t i0 = r.first_at(0.2);
    ASSERT_GT(s[i0].total_energy, 1.0);
    int iterations = 0;
    for (std::size_t i = 1; i < s.size(); ++i) iterations += s[i].newton_iterations;
    EXPECT_LE(iterations, 8 * 50) << model::to_string(f);
    const test::Drift d = test::drift_after(r, 0.2);
    EXPECT_LT(d.energy, 1e-12) << model::to_string(f);
    EXPECT_LT(d.L, 1e-12) << model::to_string(f);
    // p = 0 (the pulse is a pure torque): absolute.
    for (std::size_t i = i0; i < s.size(); ++i) EXPECT_LT(s[i].linear_momentum.norm(), 1e-11) << i;
    for (const auto& x : s) EXPECT_LT(x.constraint_violation, 1e-13);
  }
  EXPECT_EQ(unknowns, (std::vector<int>{406, 522 + 116, 522}));
  for (std::size_t k = 1; k < tip.size(); ++k)
    for (std::size_t i = 0; i < tip[0].size(); ++i)
      EXPECT_LT((tip[k][i] - tip[0][i]).norm(), 1e-8) << k << " " << i;
}

// The extrapolation qₙ + Δt vₙ moves a director node's position by Δt vₙ but turns its director
// as in the last step (NodeType::extrapolate, EnergyMomentumIntegrator::secant_directors): vₙ of
// the directors carries the period-2 oscillation of their unresolved modes.
TEST(ShellPlateOnHub, TheExtrapolationTurnsDirectorsAsInTheLastStep) {
  for (F f : {F::reparametrized, F::constrained, F::nullspace}) {
    model::Model m = hub(1.0);
    m.solver.formulation = f;
    const auto sys = system::System::compile(m);
    integrate::EnergyMomentumIntegrator integ(sys, m.solver);
    auto s = integ.initial_state();
    for (int i = 0; i < 30; ++i) integ.step(s);
    const VecX x = integ.start_unknowns(s);
    const double dt = m.solver.dt;
    int checked = 0;
    if (f == F::reparametrized) {
      for (std::size_t r = 0; r < sys.roots().size(); ++r) {
        const int i = sys.roots()[r], at = sys.root_nu_offsets()[r];
        if (sys.node_kind(i) != NodeKind::director) continue;
        EXPECT_LT((x.segment<3>(at) - dt * s.v.segment<3>(sys.q_offset(i))).norm(), 1e-15);
        EXPECT_EQ(x.segment<2>(at + 3), s.last_unknowns.segment<2>(at + 3));
        ++checked;
      }
    } else {
      for (int i = 0; i < sys.node_count(); ++i) {
        if (sys.node_kind(i) != NodeKind::director) continue;
        const int at = sys.q_offset(i);
        EXPECT_EQ(x.segment<3>(at), s.q.segment<3>(at) + dt * s.v.segment<3>(at));
        EXPECT_EQ(x.segment<3>(at + 3),
                  s.q.segment<3>(at + 3) + s.last_unknowns.segment<3>(at + 3));
        ++checked;
      }
    }
    EXPECT_EQ(checked, f == F::reparametrized ? 80 : 85) << model::to_string(f);
  }
}

// From the velocity extrapolation of the directors Newton failed once in each formulation (at
// t = 3.83 reparametrized, 4.25 constrained: a nearly singular Newton matrix at the start); with
// the directors turned as in the last step no start fails over the whole run (README.md).
TEST(ShellPlateOnHub, NoNewtonStartFails) {
  ISOFLEX_SKIP_LONG_RUN_UNDER_ASAN();
  for (F f : {F::reparametrized, F::constrained}) {
    model::Model m = hub(4.3);
    m.solver.formulation = f;
    const auto sys = system::System::compile(m);
    integrate::EnergyMomentumIntegrator integ(sys, m.solver);
    auto s = integ.initial_state();
    int iterations = 0, failed = 0;
    for (int i = 0; i < 430; ++i) {
      const auto st = integ.step(s);
      iterations += st.iterations;
      failed += st.failed_starts;
    }
    EXPECT_EQ(failed, 0) << model::to_string(f);
    EXPECT_LE(iterations, 6 * 430) << model::to_string(f);
  }
}
