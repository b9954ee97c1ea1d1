// Static load stepping on System (integrate/static_equilibrium.hpp) halves a load increment whose
// Newton iteration fails, as solver.max_subdivisions allows, and says that a diverging iteration
// diverged: the beam rolled up into a full circle (examples/beam_roll_up/model_360.yaml) in two
// increments of 180° instead of the example's twenty.
#include <gtest/gtest.h>

#include <string>

#include "isoflex/integrate/static_equilibrium.hpp"
#include "isoflex/io/model_reader.hpp"
#include "support/examples.hpp"

using namespace isoflex;

namespace {

// The tip after the load stepping of m, or the failure's message.
struct Outcome {
  Vec3 tip = Vec3::Zero();
  int steps = 0, substeps = 0;
  std::string failure;
};

Outcome roll_up(const std::string& solver_lines) {
  const model::Model m = io::read_model_string(
      test::replaced(test::example_text("beam_roll_up", "model_360.yaml"),
                     "  dt: 0.05                  # 20 load steps\n", solver_lines),
      "model_360.yaml");
  const auto sys = system::System::compile(m);
  const integrate::StaticEquilibrium statics(sys, m.solver);
  const integrate::EnergyMomentumIntegrator probe(sys, m.solver);  // for the snapshot
  auto s = statics.initial_state();
  Outcome out;
  const int n = static_cast<int>(std::lround(m.solver.t_end / m.solver.dt));
  try {
    for (int i = 0; i < n; ++i) {
      out.substeps += statics.step(s).substeps;
      ++out.steps;
    }
  } catch (const integrate::NewtonFailure& e) {
    out.failure = e.what();
  }
  for (const auto& p : probe.snapshot(s, {}, {}).probes)
    if (p.name == "tip") out.tip = p.position;
  return out;
}

}  // namespace

TEST(StaticSubdivision, HalvesAFailingIncrementAndReachesTheSameEquilibrium) {
  const Outcome nominal = roll_up("  dt: 0.05\n");  // the example: 20 increments of 18°
  ASSERT_EQ(nominal.failure, "");
  const Outcome halved = roll_up("  dt: 0.5\n  max_subdivisions: 4\n");
  ASSERT_EQ(halved.failure, "");
  EXPECT_EQ(halved.steps, 2);
  EXPECT_GT(halved.substeps, 2);  // the 180° increments had to be taken in parts
  EXPECT_LT((halved.tip - nominal.tip).norm(), 1e-10);
  // Rolled into a full circle: the tip is back near the clamp (exactly there for a continuum).
  EXPECT_LT(nominal.tip.norm(), 0.5);
}

TEST(StaticSubdivision, WithoutHalvingsADivergingIncrementSaysItDiverged) {
  const Outcome o = roll_up("  dt: 0.5\n");
  EXPECT_EQ(o.steps, 0);
  EXPECT_NE(o.failure.find("load step 1 (t = 0.5): Newton diverged: the residual grew from"),
            std::string::npos)
      << o.failure;
  EXPECT_NE(o.failure.find("x scale 1.000e+00 at the start)"), std::string::npos) << o.failure;
}
