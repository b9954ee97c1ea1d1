// The "Complete example" of docs/model-files.md, read from the document itself (so that the two
// cannot diverge), integrated to its t_end in all three formulations: every step converges, the
// energy changes by the work of the push and by nothing else, and the formulations agree.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/io/model_reader.hpp"
#include "support/files.hpp"

using namespace isoflex;
using F = model::Formulation;

namespace {
std::string complete_example_yaml() {
  const std::string doc = test::read_text(std::string(ISOFLEX_SOURCE_DIR) + "/docs/model-files.md");
  const auto section = doc.find("## Complete example");
  EXPECT_NE(section, std::string::npos);
  const auto begin = doc.find("```yaml\n", section);
  EXPECT_NE(begin, std::string::npos);
  const auto end = doc.find("```", begin + 8);
  EXPECT_NE(end, std::string::npos);
  return doc.substr(begin + 8, end - begin - 8);
}

struct Outcome {
  double E0 = 0, E_end = 0, W_end = 0, W_at_push_end = 0;
  double balance = 0;     // max |E − E₀ − W| over the steps
  double after_push = 0;  // max |E − E(t = 1)| after the push
  int steps = 0, expected = 0;
};

Outcome run(F f) {
  auto m = io::read_model_string(complete_example_yaml(), "docs/model-files.md");
  m.solver.formulation = f;
  const auto sys = system::System::compile(m);
  EXPECT_LT(sys.initial_velocity_projection_error(), 1e-12);  // admissible as written
  integrate::EnergyMomentumIntegrator integ(sys, m.solver);
  auto s = integ.initial_state();
  Outcome o;
  o.expected = static_cast<int>(std::lround(m.solver.t_end / m.solver.dt));
  o.E0 = integ.snapshot(s, {}, {}).total_energy;
  double E_push_end = 0;
  for (int i = 0; i < o.expected; ++i) {
    integ.step(s);  // a NewtonFailure fails the test
    ++o.steps;
    const double E = integ.snapshot(s, {}, {}).total_energy;
    o.balance = std::max(o.balance, std::abs(E - o.E0 - s.external_work));
    if (s.t <= 1.0 + 1e-12) {
      E_push_end = E;
      o.W_at_push_end = s.external_work;
    } else {
      o.after_push = std::max(o.after_push, std::abs(E - E_push_end));
    }
    o.E_end = E;
    o.W_end = s.external_work;
  }
  return o;
}
}  // namespace

TEST(ModelFilesDoc, CompleteExampleConservesEnergyInEveryFormulation) {
  std::vector<Outcome> out;
  for (F f : {F::constrained, F::nullspace, F::reparametrized}) {
    SCOPED_TRACE(model::to_string(f));
    const Outcome o = run(f);
    EXPECT_EQ(o.steps, o.expected);
    // E − W constant to round-off: the push's work is the only change of energy …
    EXPECT_LT(o.balance, 1e-10 * o.E0);
    EXPECT_GT(std::abs(o.W_end), 1e-3);
    // … and after the push (t > 1) the energy and the work stay put.
    EXPECT_LT(o.after_push, 1e-10 * o.E0);
    EXPECT_EQ(o.W_end, o.W_at_push_end);
    out.push_back(o);
  }
  // The three formulations solve the same step equations: the same motion, so the same work.
  for (const Outcome& o : out) EXPECT_NEAR(o.W_end, out.front().W_end, 1e-8);
}
