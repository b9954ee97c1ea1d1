// examples/kl_hinged_plate (IGA-thesis §6.4.2.5, Table 6.1): the hinged plate swung by a tip
// force, as one patch and as two patches joined by the AF-D rows (5.36) or a bending strip,
// generalized-α with ρ∞ = 0.5. The AF-D plate follows the one-patch plate (the rows make it C¹ at
// the cut, so the two discretizations differ only by the knot spans) with the same Newton effort
// and condition number, its rows hold to the Newton tolerance, and the strip's condition number
// grows ∝ β₁ (README.md's table, bench/kl_transient_table_bench).
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "isoflex/integrate/dae_integrator.hpp"
#include "isoflex/io/model_reader.hpp"
#include "isoflex/solve/linear_solver.hpp"
#include "support/examples.hpp"
#include "support/trajectory.hpp"

using namespace isoflex;

namespace {

struct Swing {
  Vec3 tip;                // at t_end
  int iterations = 0;      // over all steps
  double violation = 0.0;  // the largest max |Φ| of the steps
  double condition = 0.0;  // S_t (2.27) at the first Newton start, scaled
};

Swing swing(const std::string& file, model::KLCoupling coupling, double beta) {
  model::Model m = io::read_model_string(test::example_text("kl_hinged_plate", file), file);
  m.solver.t_end = 1.5;  // the pulse (t < 1) and half a second of the swing
  m.kl_interfaces.coupling = coupling;
  m.kl_interfaces.beta = beta;
  const test::Trajectory r = test::simulate(m);
  Swing s;
  s.tip = r.probe("tip").back();
  for (const auto& x : r.snapshots) {
    s.iterations += x.newton_iterations;
    s.violation = std::max(s.violation, x.constraint_violation);
  }
  const auto sys = system::System::compile(m);
  const integrate::DaeIntegrator dae(sys, m.solver);
  s.condition = solve::condition_number(MatX(dae.iteration_matrix(dae.initial_state())));
  return s;
}

}  // namespace

TEST(KLHingedPlate, AngleRowsFollowTheOnePatchAndStripsWorsenTheCondition) {
  using C = model::KLCoupling;
  const Swing one = swing("one_patch.yaml", C::c0, 1.0), af_d = swing("model.yaml", C::angle, 1.0),
              strip = swing("model.yaml", C::bending_strip, 1e5);
  std::printf(
      "  tip at t = 1.5: one patch (%.6f %.6f %.6f), AF-D (%.6f %.6f %.6f), strip 1e5 (%.6f "
      "%.6f %.6f)\n  Newton iterations %d / %d / %d, max |Phi| %.1e / %.1e, condition %.3e / "
      "%.3e / %.3e\n",
      one.tip.x(), one.tip.y(), one.tip.z(), af_d.tip.x(), af_d.tip.y(), af_d.tip.z(),
      strip.tip.x(), strip.tip.y(), strip.tip.z(), one.iterations, af_d.iterations,
      strip.iterations, one.violation, af_d.violation, one.condition, af_d.condition,
      strip.condition);
  EXPECT_LT(one.tip.z(), -1.0);  // it swings
  EXPECT_LT((af_d.tip - one.tip).norm(), 1e-4 * (one.tip - Vec3(12, 0.5, 0)).norm());
  EXPECT_LT((strip.tip - af_d.tip).norm(), 1e-5 * (one.tip - Vec3(12, 0.5, 0)).norm());
  EXPECT_LT(af_d.violation, 1e-9);
  EXPECT_NEAR(af_d.iterations, one.iterations, 0.1 * one.iterations);
  EXPECT_LT(af_d.condition, 3.0 * one.condition);
  EXPECT_GT(strip.condition, 1e3 * af_d.condition);
}
