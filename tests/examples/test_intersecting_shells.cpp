// The intersecting shells of DNSM-III §5.3 (examples/intersecting_shells): equation counts, and
// conservation of energy and of all momenta after the loads end (t > T = 2).
#include <gtest/gtest.h>

#include <cstdio>

#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/io/model_reader.hpp"

using namespace isoflex;

namespace {
model::Model intersecting_shells(model::Formulation f) {
  auto m =
      io::read_model(std::string(ISOFLEX_SOURCE_DIR) + "/examples/intersecting_shells/model.yaml");
  m.solver.formulation = f;
  return m;
}
}  // namespace

// n = 44 director nodes × 6 + 2 bodies × 12 = 288 (the paper's 288); m = 56 internal + 4 × 5
// attachments + 2 × 4 intersection rows = 84; reparametrized n − m = 204 (paper: 216).
TEST(IntersectingShells, EquationCounts) {
  const auto sys = system::System::compile(intersecting_shells(model::Formulation::constrained));
  EXPECT_EQ(sys.n(), 288);
  EXPECT_EQ(sys.m_selected(), 84);
  EXPECT_EQ(sys.k(), 204);
  EXPECT_EQ(sys.node_count(isoflex::NodeKind::director), 44);
}

// From t = 2 (loads off) to t = 3: energy, linear and angular momentum constant to round-off in
// the reparametrized and the constrained scheme, which stay on the same trajectory.
TEST(IntersectingShells, ConservesEnergyAndMomentaAfterTheLoads) {
  std::vector<VecX> finals;
  for (auto f : {model::Formulation::reparametrized, model::Formulation::constrained}) {
    const auto m = intersecting_shells(f);
    const auto sys = system::System::compile(m);
    integrate::EnergyMomentumIntegrator integ(sys, m.solver);
    auto s = integ.initial_state();
    std::vector<integrate::Snapshot> after;
    for (int i = 0; i < 150; ++i) {
      const auto st = integ.step(s);
      if (s.t > 2.0 - 1e-9) after.push_back(integ.snapshot(s, st, {}));
    }
    const auto& a = after.front();
    EXPECT_GT(a.kinetic_energy, 10.0);
    for (const auto& b : after) {
      EXPECT_LT(std::abs(b.total_energy - a.total_energy), 1e-12 * a.total_energy);
      EXPECT_LT((b.linear_momentum - a.linear_momentum).norm(), 1e-11);
      EXPECT_LT((b.angular_momentum - a.angular_momentum).norm(), 1e-11);
      EXPECT_LT(b.constraint_violation, 1e-13);
    }
    finals.push_back(s.q);
  }
  EXPECT_LT((finals[0] - finals[1]).lpNorm<Eigen::Infinity>(), 1e-8);
}

// Issue #20's goal, the whole run to t = 10 (500 steps of 0.02): Newton (EnergyMomentumIntegrator::
// attempt) with the mixed integration point tangent (solver.mixed_tangent) from the predictor with
// the smaller residual. Measured (all work counted, retried halves included): constrained 2274
// iterations and null space 2277, no failed start; reparametrized 2661 and 2 failed starts (t =
// 8.66, where the exact tangent failed 3 times), against 4363 iterations and 3 failed starts with
// the exact tangent; with numerical dissipation χ = 0.05 (reparametrized) 2311 and none.
TEST(IntersectingShells, NewtonConvergesFromItsFirstStartWithTheMixedTangent) {
  struct Run {
    model::Formulation f;
    bool mixed;
    double chi;
    int iterations = 0, failed = 0, substeps = 0;
  };
  std::vector<Run> runs = {{model::Formulation::constrained, true, 0.0},
                           {model::Formulation::nullspace, true, 0.0},
                           {model::Formulation::reparametrized, true, 0.0},
                           {model::Formulation::reparametrized, false, 0.0},
                           {model::Formulation::reparametrized, true, 0.05}};
  for (Run& r : runs) {
    auto m = intersecting_shells(r.f);
    m.solver.mixed_tangent = r.mixed;
    m.solver.numerical_dissipation = r.chi;
    const auto sys = system::System::compile(m);
    integrate::EnergyMomentumIntegrator integ(sys, m.solver);
    auto s = integ.initial_state();
    for (int i = 0; i < 500; ++i) {
      const auto st = integ.step(s);
      r.iterations += st.iterations;
      r.failed += st.failed_starts;
      r.substeps += st.substeps;
    }
    std::printf("  [%s, %s tangent, chi %g] %d iterations, %d failed starts, %d parts of steps\n",
                model::to_string(r.f), r.mixed ? "mixed" : "exact", r.chi, r.iterations, r.failed,
                r.substeps);
    EXPECT_EQ(r.substeps, 500);
  }
  EXPECT_LE(runs[0].iterations, 2400);  // ≤ 8 per step is the goal: 4000
  EXPECT_EQ(runs[0].failed, 0);
  EXPECT_LE(runs[1].iterations, 2400);
  EXPECT_EQ(runs[1].failed, 0);
  EXPECT_LE(runs[2].iterations, 2800);
  EXPECT_LE(runs[2].failed, 2);
  EXPECT_LT(runs[2].iterations, 0.7 * runs[3].iterations);
  EXPECT_LE(runs[4].iterations, 2400);  // with χ = 0.05: 2311 (the dissipative stress mixed too)
  EXPECT_EQ(runs[4].failed, 0);
}
