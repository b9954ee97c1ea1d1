// examples/kl_two_patch_roll_up (IGA-thesis §6.4.2.1, Fig. 6.17): the roll-up plate cut in two
// and joined by a bending strip. The file's run reaches the Kirchhoff–Love model's exact tip to
// the penalty's error at β₁ = 10³; over β₁ = 10², 10⁴, 10⁶ the error falls ∝ 1/β₁ and the
// condition number of the Newton matrix grows ∝ β₁ (README.md's table, bench/kl_multipatch_bench).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "isoflex/integrate/static_equilibrium.hpp"
#include "isoflex/io/model_reader.hpp"
#include "support/cli.hpp"
#include "support/examples.hpp"
#include "support/files.hpp"

using namespace isoflex;

namespace {

// The tip x-displacement of the Kirchhoff–Love model at 360° (examples/plate_roll_up/README.md:
// the arc stretched by λ, λ² = 1 − t²θ²/(6L²), turned to θ = 2π/λ²).
double exact_tip_x() {
  const double L = 12.0, h = 0.1, th0 = 2.0 * std::acos(-1.0);
  double th = th0, lam = 1.0;
  for (int i = 0; i < 50; ++i) {
    lam = std::sqrt(1.0 - h * h * th * th / (6.0 * L * L));
    th = th0 / (lam * lam);
  }
  return lam * L * std::sin(th) / th - L;
}

struct Solved {
  double tip_x = 0.0, condition = 0.0;
  int unknowns = 0;
};

Solved solve(double beta) {
  model::Model m =
      io::read_model_string(test::example_text("kl_two_patch_roll_up", "model.yaml"), "model.yaml");
  if (beta > 0.0) m.kl_interfaces.beta = beta;
  const auto sys = system::System::compile(m);
  integrate::StaticEquilibrium eq(sys, m.solver);
  const integrate::StaticResult r = eq.solve();
  const auto& p = sys.probes().front();
  Solved s;
  s.tip_x = (sys.probe_point(r.x.head(sys.n()), p) - sys.probe_point(sys.q0(), p)).x();
  s.condition = eq.newton_matrix_condition(m.solver.t_end, r.x);
  s.unknowns = eq.unknowns();
  return s;
}

}  // namespace

// The file: β₁ = 10³, tip −11.99371304 (README.md), 8.0e-4 short of the exact −11.99451313; the
// unknowns `isoflex check` prints.
TEST(KLTwoPatchRollUp, TheFileReachesTheExactTipToThePenaltyError) {
  EXPECT_NEAR(exact_tip_x(), -11.99451313034389, 1e-12);
  const Solved s = solve(0.0);
  EXPECT_EQ(s.unknowns, 210);
  EXPECT_NEAR(s.tip_x, -11.9937130388, 1e-8);
  EXPECT_NEAR(s.tip_x - exact_tip_x(), 8.0e-4, 0.1e-4);
  const auto r = test::run_isoflex("check " + std::string(ISOFLEX_SOURCE_DIR) +
                                   "/examples/kl_two_patch_roll_up/model.yaml");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("unknowns         210"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("left u1 -- right u0: 3 triples, angle 180.0°, coupling bending_strip "
                       "(β = 1000, E_s = 1.2e+09)"),
            std::string::npos)
      << r.out;
}

// Fig. 6.17: a factor 100 in β₁ divides the error by ~100 (measured 100, 110) and multiplies the
// condition number by ~100 (measured 99.8, 100.0).
TEST(KLTwoPatchRollUp, PenaltyErrorFallsAndConditionGrowsWithBeta) {
  std::vector<Solved> s;
  for (double beta : {1e2, 1e4, 1e6}) {
    s.push_back(solve(beta));
    std::printf("  beta %.0e: tip x %.10f (error %.2e), condition %.3e\n", beta, s.back().tip_x,
                std::abs(s.back().tip_x - exact_tip_x()), s.back().condition);
  }
  for (int k = 0; k + 1 < 3; ++k) {
    const double e0 = std::abs(s[k].tip_x - exact_tip_x());
    const double e1 = std::abs(s[k + 1].tip_x - exact_tip_x());
    EXPECT_GT(e0 / e1, 80.0) << k;
    EXPECT_LT(e0 / e1, 130.0) << k;
    EXPECT_GT(s[k + 1].condition / s[k].condition, 90.0) << k;
    EXPECT_LT(s[k + 1].condition / s[k].condition, 110.0) << k;
  }
}

// tools/kl_beta_plot.py draws the committed study (the README's figure) and refuses a file
// without the bench's columns.
TEST(KLTwoPatchRollUp, BetaPlotScript) {
  const test::TempDir dir(test::temp_dir("isoflex_", "beta_plot"));
  const std::string script =
      std::string("/usr/bin/python3 ") + ISOFLEX_SOURCE_DIR + "/tools/kl_beta_plot.py ";
  const auto ok = test::run_shell(script + ISOFLEX_SOURCE_DIR +
                                  "/examples/kl_two_patch_roll_up/beta_study.csv --out " +
                                  (dir.path() / "b.png").string() + " --reference -11.9945");
  ASSERT_EQ(ok.code, 0) << ok.out;
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "b.png"));
  EXPECT_NE(ok.out.find("beta 1e+10: no result (the run failed)"), std::string::npos) << ok.out;
  const std::string bad = (dir.path() / "bad.csv").string();
  test::write_text(bad, "beta,x\n1,2\n");
  const auto no = test::run_shell(script + bad + " --out " + (dir.path() / "c.png").string());
  EXPECT_EQ(no.code, 2) << no.out;
  EXPECT_NE(no.out.find("expected the columns"), std::string::npos) << no.out;
}
