// examples/kl_two_patch_roll_up (IGA-thesis §6.4.2.1, Fig. 6.17): the roll-up plate cut in two
// and joined by a bending strip. The file's run reaches the Kirchhoff–Love model's exact tip to
// the penalty's error at β₁ = 10³; over β₁ = 10², 10⁴, 10⁶ the error falls ∝ 1/β₁ and the
// condition number of the Newton matrix grows ∝ β₁ (README.md's table, bench/kl_multipatch_bench).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "isoflex/geometry/refinement.hpp"
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

// tools/kl_multipatch_convergence.py (the README's Figs. 6.18/6.19) on p = 5, 7 and 15 knots, one
// and two patches: against the finer single patch, AF-D at 15 knots is as accurate as the single
// patch (its cut is C¹), the strip (β₁ = 10³) stops at its penalty error; a bad option is exit 2.
TEST(KLTwoPatchRollUp, EnergyConvergenceScript) {
  const test::TempDir dir(test::temp_dir("isoflex_", "energy_convergence"));
  const std::string script = std::string("/usr/bin/python3 ") + ISOFLEX_SOURCE_DIR +
                             "/tools/kl_multipatch_convergence.py --isoflex " + ISOFLEX_BINARY +
                             " ";
  const std::string csv = (dir.path() / "e.csv").string();
  const auto ok = test::run_shell(script + "--degrees 5 --knots 7,15 --patches 1,2 --csv " + csv);
  ASSERT_EQ(ok.code, 0) << ok.out;
  double af_d = -1.0, strip = -1.0;
  int rows = 0;
  // Columns: patches, coupling, p, knots, coordinates, unknowns, energy, tip_x, relative_error.
  std::istringstream lines(test::read_text(csv));
  std::string line;
  std::getline(lines, line);
  EXPECT_EQ(line, "patches,coupling,p,knots,coordinates,unknowns,energy,tip_x,relative_error");
  while (std::getline(lines, line)) {
    std::vector<std::string> f;
    std::istringstream fields(line);
    for (std::string x; std::getline(fields, x, ',');) f.push_back(x);
    ASSERT_EQ(f.size(), 9u) << line;
    ++rows;
    if (f[0] == "2" && f[3] == "15") (f[1] == "angle" ? af_d : strip) = std::stod(f[8]);
  }
  std::printf("  2 patches, 15 knots: AF-D %.2e, strip %.2e\n", af_d, strip);
  EXPECT_EQ(rows, 2 + 2 * 2);
  EXPECT_GE(af_d, 0.0);
  EXPECT_LT(af_d, 1e-7);
  EXPECT_GT(strip, 1e-6);
  EXPECT_EQ(test::run_shell(script + "--knots x").code, 2);
}

namespace {

// examples/kl_l_shaped_plate with the given coupling (and β₁ for the strip): the load point's
// u_z, the linearized angle change at the front triple |Δθ|/θ₀, the unknowns, and the coupling's
// rows and independent rows.
struct LPlate {
  double uz = 0.0, angle = 0.0;
  int unknowns = 0, rows = 0, independent = 0;
};

LPlate l_plate(model::KLCoupling coupling, double beta = 1e3) {
  model::Model m =
      io::read_model_string(test::example_text("kl_l_shaped_plate", "model.yaml"), "model.yaml");
  m.kl_interfaces.coupling = coupling;
  m.kl_interfaces.beta = beta;
  const auto sys = system::System::compile(m);
  integrate::StaticEquilibrium eq(sys, m.solver);
  const VecX dq = eq.solve().x.head(sys.n()) - sys.q0();
  LPlate out;
  const auto& probe = sys.probes().front();
  out.uz = (sys.probe_point(sys.q0() + dq, probe) - sys.probe_point(sys.q0(), probe)).z();
  const system::KLInterfaceInstance& I = sys.kl_interfaces().at(0);
  const auto& f = I.geometry;
  const auto k = static_cast<std::size_t>(3 * (f.triples() - 1));  // the front triple, x = 10
  const std::vector<int> T(I.triple_nodes.begin() + static_cast<std::ptrdiff_t>(k),
                           I.triple_nodes.begin() + static_cast<std::ptrdiff_t>(k + 3));
  EXPECT_NEAR(sys.stacked(sys.q0(), {T[1]}).x(), 10.0, 1e-12);
  const auto angle = [&](const VecX& q) {
    const VecX x = sys.stacked(q, T);
    const Vec3 a = x.segment<3>(0) - x.segment<3>(3), b = x.segment<3>(6) - x.segment<3>(3);
    return std::atan2(a.cross(b).norm(), a.dot(b));
  };
  const double th0 = angle(sys.q0());
  EXPECT_NEAR(th0, std::acos(0.0), 1e-14);
  out.angle = std::abs(0.5 * (angle(sys.q0() + dq) - angle(sys.q0() - dq))) / th0;
  out.unknowns = eq.unknowns();
  if (I.constraint_index >= 0) {
    out.rows = sys.nary_constraints()[static_cast<std::size_t>(I.constraint_index)]
                   .constraint->constraint_count();
    out.independent = sys.independent_rows_of(I.constraint_index);
  }
  return out;
}

}  // namespace

// IGA-thesis Fig. 6.21 (examples/kl_l_shaped_plate/README.md): the hinge turns (8.7e-2); the
// strip's angle error falls ∝ 1/β₁; AF-BS and AF-D hold the linearized angle to round-off, AF-BS
// the stiffer (it also holds the flange lengths, Remark 5.8); the row counts `isoflex check`
// prints (the clamp holds the first two triples).
TEST(KLLShapedPlate, HingeStripAndConstraints) {
  using C = model::KLCoupling;
  const LPlate hinge = l_plate(C::c0), af_bs = l_plate(C::strip_constraints),
               af_d = l_plate(C::angle);
  const LPlate s3 = l_plate(C::bending_strip, 1e3), s6 = l_plate(C::bending_strip, 1e6),
               s9 = l_plate(C::bending_strip, 1e9);
  std::printf("  u_z: hinge %.6f, strip 1e3 %.6f, AF-BS %.6f, AF-D %.6f\n", hinge.uz, s3.uz,
              af_bs.uz, af_d.uz);
  std::printf("  angle: hinge %.2e, strip 1e3 %.2e 1e6 %.2e 1e9 %.2e, AF-BS %.2e, AF-D %.2e\n",
              hinge.angle, s3.angle, s6.angle, s9.angle, af_bs.angle, af_d.angle);
  EXPECT_NEAR(hinge.angle, 8.7e-2, 0.1e-2);
  EXPECT_NEAR(hinge.uz, -0.141137, 1e-6);
  EXPECT_NEAR(af_bs.uz, -0.049947, 1e-6);
  EXPECT_NEAR(af_d.uz, -0.049958, 1e-6);
  EXPECT_GT(af_bs.uz, af_d.uz);  // AF-BS stiffer: the smaller deflection (u_z < 0)
  EXPECT_LT(af_bs.angle, 1e-12);
  EXPECT_LT(af_d.angle, 1e-9);
  EXPECT_NEAR(s6.angle * 1e3, s9.angle * 1e6, 0.05 * s9.angle * 1e6);  // ∝ 1/β₁
  EXPECT_LT(s9.angle, 1e-8);
  EXPECT_EQ(hinge.unknowns, 90);
  EXPECT_EQ(af_bs.unknowns, 99);
  EXPECT_EQ(af_d.unknowns, 93);
  EXPECT_EQ(af_bs.rows, 45);
  EXPECT_EQ(af_bs.independent, 9);
  EXPECT_EQ(af_d.rows, 5);
  EXPECT_EQ(af_d.independent, 3);
  const auto r = test::run_isoflex("check " + std::string(ISOFLEX_SOURCE_DIR) +
                                   "/examples/kl_l_shaped_plate/model.yaml");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("flange v0 -- web v0: 5 triples, angle 90.0°, coupling angle (5 rows, 3 "
                       "independent)"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("unknowns         93"), std::string::npos) << r.out;
}

// AF-D on the roll-up (straight triples: the linear rows (5.36), exact in this nonlinear run):
// the tip of the strip's limit, −11.9945132 (README.md). Its 9 rows are eliminated with 9 slave
// coordinates: 9 unknowns fewer than the strip (210), 18 fewer than as multiplier rows (219).
TEST(KLTwoPatchRollUp, AngleConstraintsGiveTheLimitWithoutAPenalty) {
  model::Model m =
      io::read_model_string(test::example_text("kl_two_patch_roll_up", "model.yaml"), "model.yaml");
  m.kl_interfaces.coupling = model::KLCoupling::angle;
  const auto sys = system::System::compile(m);
  integrate::StaticEquilibrium eq(sys, m.solver);
  const integrate::StaticResult r = eq.solve();
  const auto& p = sys.probes().front();
  const double x = (sys.probe_point(r.x.head(sys.n()), p) - sys.probe_point(sys.q0(), p)).x();
  EXPECT_EQ(eq.unknowns(), 201);
  EXPECT_EQ(eq.tied(), 9);
  EXPECT_NEAR(x, -11.9945132066, 1e-9);
  EXPECT_LT(std::abs(x - exact_tip_x()), 1e-7);
}

namespace {

// u_y of probe `ref` of a linear static model.
double scordelis_uy(const model::Model& m) {
  const auto sys = system::System::compile(m);
  integrate::StaticEquilibrium eq(sys, m.solver);
  const VecX q = eq.solve().x.head(sys.n());
  const auto& p = sys.probes().front();
  return (sys.probe_point(q, p) - sys.probe_point(sys.q0(), p)).y();
}

model::Model scordelis_two_patch(model::KLCoupling c, double beta = 1e3) {
  model::Model m = io::read_model_string(
      test::example_text("kl_scordelis_lo_two_patch", "model.yaml"), "model.yaml");
  m.kl_interfaces.coupling = c;
  m.kl_interfaces.beta = beta;
  return m;
}

}  // namespace

// IGA-thesis §6.4.2.3: the two-patch roof equals the single patch. AF-D's rows (5.36) make the
// joint C¹ with the reference's span ratio, so the two patches span exactly the single patch's
// space with a knot of multiplicity p − 1 = 3 at z = 12.5: the same u_y to round-off. AF-BS, and
// the strip as β₁ grows, give nearly that (the strip holds the triples' curvature, a little
// more than C¹); the hinge alone is softer.
TEST(KLScordelisLoTwoPatch, EqualsTheSinglePatch) {
  model::Model one =
      io::read_model_string(test::example_text("scordelis_lo", "kl_shell.yaml"), "kl_shell.yaml");
  geometry::NurbsSurface& g = one.surfaces.front().surface;
  ASSERT_EQ(g.degree_v(), 4);
  g = geometry::insert_knot(g, geometry::Direction::v, 0.5, 2);
  const double single = scordelis_uy(one);
  const double af_d = scordelis_uy(scordelis_two_patch(model::KLCoupling::angle));
  const double af_bs = scordelis_uy(scordelis_two_patch(model::KLCoupling::strip_constraints));
  const double strip = scordelis_uy(scordelis_two_patch(model::KLCoupling::bending_strip, 1e6));
  const double hinge = scordelis_uy(scordelis_two_patch(model::KLCoupling::c0));
  std::printf(
      "  u_y: single (C¹ at z = 12.5) %.12f, AF-D %.12f, AF-BS %.12f, strip 1e6 %.12f, "
      "hinge %.12f\n",
      single, af_d, af_bs, strip, hinge);
  EXPECT_NEAR(single, -0.3006, 0.0005);
  EXPECT_LT(std::abs(af_d - single), 1e-10 * std::abs(single));
  EXPECT_LT(std::abs(af_bs - single), 1e-6 * std::abs(single));
  EXPECT_LT(std::abs(strip - af_bs), 1e-6 * std::abs(single));
  EXPECT_LT(hinge, single);  // softer: a larger downward deflection
}
