// Static load stepping on System (integrate/static_equilibrium.hpp) halves a load increment whose
// Newton iteration fails, as solver.max_subdivisions allows, and says that a diverging iteration
// diverged: the beam rolled up into a full circle (examples/beam_roll_up/model_360.yaml) in two
// increments of 180° instead of the example's twenty — and the director-shell plate of
// examples/plate_roll_up the same way (its statics used to ignore solver.max_subdivisions).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "isoflex/io/model_reader.hpp"
#include "support/examples.hpp"
#include "support/statics.hpp"

using namespace isoflex;

namespace {

// The tip after the load stepping of m, or the failure's message.
struct Outcome {
  Vec3 tip = Vec3::Zero();
  int steps = 0, substeps = 0;
  std::string failure;
};

Outcome roll_up(const std::string& solver_lines, const std::string& dir = "beam_roll_up",
                const std::string& file = "model_360.yaml", const std::string& probe = "tip") {
  const model::Model m = io::read_model_string(
      test::replaced(test::example_text(dir, file), "  dt: 0.05                  # 20 load steps\n",
                     solver_lines),
      file);
  const auto sys = system::System::compile(m);
  const test::StaticRun r = test::solve_static(sys, m);
  Outcome out;
  out.failure = r.failure;
  VecX q = sys.q0();
  for (const auto& st : r.steps) {
    out.substeps += 1;
    // An accepted step on the nominal grid k·dt ends a nominal step.
    const double k = st.t / m.solver.dt;
    if (std::abs(k - std::round(k)) < 1e-9) ++out.steps;
    q = st.q;
  }
  out.tip = test::probe_at(sys, q, probe);
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
  const Outcome o = roll_up("  dt: 0.5\n  max_subdivisions: 0\n");
  EXPECT_EQ(o.steps, 0);
  EXPECT_NE(o.failure.find("load step 1 did not converge at load factor 0.5"), std::string::npos)
      << o.failure;
  EXPECT_NE(o.failure.find(": Newton diverged: the residual grew from"), std::string::npos)
      << o.failure;
}

TEST(StaticSubdivision, DirectorShellStaticsHalveToo) {
  const auto plate = [](const std::string& lines) {
    return roll_up(lines, "plate_roll_up", "director_shell.yaml", "ref");
  };
  const Outcome nominal = plate("  dt: 0.05\n");
  ASSERT_EQ(nominal.failure, "");
  const Outcome whole = plate("  dt: 0.5\n  max_subdivisions: 0\n");
  EXPECT_EQ(whole.steps, 0);
  EXPECT_NE(whole.failure.find("load step 1 did not converge at load factor 0.5"),
            std::string::npos)
      << whole.failure;
  const Outcome halved = plate("  dt: 0.5\n  max_subdivisions: 6\n");
  ASSERT_EQ(halved.failure, "");
  EXPECT_EQ(halved.steps, 2);
  EXPECT_GT(halved.substeps, 2);
  EXPECT_LT((halved.tip - nominal.tip).norm(), 1e-8);
  EXPECT_LT(nominal.tip.norm(), 0.5);  // a full circle: back near the clamp
}
