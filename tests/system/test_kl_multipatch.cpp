// Several Kirchhoff–Love patches in one System (docs/model-files.md "kl_interfaces",
// docs/theory/multipatch.md): the cantilever of examples/plate_roll_up cut in two at x = 6
// (IGA-thesis §6.4.2.1) — joined only by shared control points it is a hinge, with a bending
// strip it rolls up like the single patch as β₁ grows; `isoflex check` lists the interface; the
// energy–momentum scheme keeps energy and momenta of a free kinked two-patch plate with its strip
// to round-off; located errors for interfaces that cannot be joined and for bad keys.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "isoflex/io/model_error.hpp"
#include "isoflex/io/model_reader.hpp"
#include "support/cli.hpp"
#include "support/examples.hpp"
#include "support/files.hpp"
#include "support/model_errors.hpp"
#include "support/statics.hpp"
#include "support/trajectory.hpp"

using namespace isoflex;

namespace {

// The roll-up plate of examples/plate_roll_up/kl_shell.yaml (L = 12, b = 1, t = 0.1, E = 1.2e6,
// ν = 0, end moment 2π EI/L · t about −y), cut at x = 6: two bicubic patches of 8 × 1 elements.
std::string two_patch_roll_up(const std::string& interfaces) {
  return R"(name: two_patch_roll_up
solver: {analysis: static, dt: 0.25, t_end: 1, max_subdivisions: 6}
surfaces:
  - name: left
    builtin: {type: rectangle, size: [6, 1]}
    refine: {elevate: [2, 2], knots_per_span: [7, 0]}
  - name: right
    builtin: {type: rectangle, size: [6, 1], corner: [6, 0, 0]}
    refine: {elevate: [2, 2], knots_per_span: [7, 0]}
kl_shells:
  - {name: left, surface: left, material: {E: 1.2e6, nu: 0, thickness: 0.1}}
  - {name: right, surface: right, material: {E: 1.2e6, nu: 0, thickness: 0.1}}
kl_supports:
  - {shell: left, edge: u0, clamped: all}
kl_loads:
  - {name: end_moment, shell: right, edge: u1, moment_per_length: "52.35987755982988*t",
     axis: [0, -1, 0]}
probes:
  - {name: ref, shell: right, point: [12, 0.5, 0]}
)" + interfaces;
}

// The Kirchhoff–Love model's exact tip displacement at load t (examples/plate_roll_up/README.md:
// the arc stretched by λ, λ² = 1 − h²θ²/(6L²), turned to θ = θ₀/λ²).
Vec3 kl_tip(double t) {
  const double L = 12.0, th0 = 2.0 * std::numbers::pi * t, h = 0.1;
  double th = th0, lam = 1.0;
  for (int i = 0; i < 50; ++i) {
    lam = std::sqrt(1.0 - h * h * th * th / (6.0 * L * L));
    th = th0 / (lam * lam);
  }
  return {lam * L * std::sin(th) / th - L, 0.0, lam * L * (1.0 - std::cos(th)) / th};
}

// |u_h − u_KL| / |u_KL| at 90° and 360° (t = 0.25, 1), or the Newton failure.
struct RollUp {
  double at90 = 1.0, at360 = 1.0;
  std::string failure;
  int unknowns = 0;
};
RollUp roll_up(const std::string& text) {
  const model::Model m = io::read_model_string(text, "m.yaml");
  const auto sys = test::static_system(m);
  const test::StaticRun r = test::solve_static(sys, m);
  RollUp out;
  out.failure = r.failure;
  out.unknowns = r.unknowns;
  const Vec3 X = test::probe_at(sys, sys.q0(), "ref");
  for (const auto& st : r.steps) {
    const Vec3 u = test::probe_at(sys, st.q, "ref") - X, e = kl_tip(st.t);
    if (std::abs(st.t - 0.25) < 1e-12) out.at90 = (u - e).norm() / e.norm();
    if (std::abs(st.t - 1.0) < 1e-12) out.at360 = (u - e).norm() / e.norm();
  }
  return out;
}

}  // namespace

// Counts: the two patches share the 4 control points of the cut (11 × 4 each, 84 distinct, 252
// coordinates); the strip is one more element over the 4 triples.
TEST(KLMultipatch, SharedControlPointsAreOneNodeAndTheStripIsAnElement) {
  const model::Model m =
      io::read_model_string(two_patch_roll_up("kl_interfaces: {beta: 1e4}\n"), "m.yaml");
  const auto sys = system::System::compile(m);
  ASSERT_EQ(sys.kl_patches().size(), 2u);
  EXPECT_EQ(sys.node_count(NodeKind::point), 84);
  EXPECT_EQ(sys.n(), 252);
  ASSERT_EQ(sys.kl_interfaces().size(), 1u);
  const system::KLInterfaceInstance& I = sys.kl_interfaces()[0];
  EXPECT_EQ(I.a, "left");
  EXPECT_EQ(I.b, "right");
  EXPECT_EQ(I.geometry.triples(), 4);
  EXPECT_EQ(I.coupling, model::KLCoupling::bending_strip);
  EXPECT_EQ(I.young, 1.2e10);
  ASSERT_GE(I.element_index, 0);
  EXPECT_EQ(sys.elements()[static_cast<std::size_t>(I.element_index)]->nodes().size(), 12u);
  // The right patch's control points on the cut are the left patch's.
  const auto& L = sys.kl_patches()[0].nodes;
  const auto& R = sys.kl_patches()[1].nodes;
  for (int k = 0; k < 4; ++k) EXPECT_EQ(L[static_cast<std::size_t>(10 + 11 * k)], R[11 * k]);
}

// IGA-thesis §6.4.2.1 and Fig. 6.20b: with only the shared control points the cut is a hinge, the
// end moment finds no stiffness (Newton fails); with the strip the error against the exact roll-up
// falls with β₁ (penalty: ∝ 1/β₁) to the single patch's at 16 × 1 elements (3.7e-5 at 90°, 2.8e-4
// at 360°, examples/plate_roll_up/README.md, mostly the distance of (6.14) from the KL model).
TEST(KLMultipatch, RollUpWithAStripApproachesTheSinglePatchAsBetaGrows) {
  const RollUp hinge = roll_up(two_patch_roll_up("kl_interfaces: {coupling: c0}\n"));
  EXPECT_NE(hinge.failure, "") << "a hinge under an end moment must not converge";
  std::vector<RollUp> r;
  for (const char* beta : {"1e1", "1e3", "1e5"}) {
    r.push_back(roll_up(two_patch_roll_up(std::string("kl_interfaces: {beta: ") + beta + "}\n")));
    EXPECT_EQ(r.back().failure, "") << "beta " << beta;
    std::printf("  beta %s: error at 90° %.3e, at 360° %.3e\n", beta, r.back().at90,
                r.back().at360);
  }
  // The single patch of the example at the same 16 × 1 bicubic elements, 90° steps.
  const RollUp one = roll_up(test::replaced(test::example_text("plate_roll_up", "kl_shell.yaml"),
                                            "dt: 0.0625", "dt: 0.25"));
  std::printf("  one patch: error at 90° %.3e, at 360° %.3e\n", one.at90, one.at360);
  EXPECT_GT(r[0].at90, 50.0 * r[1].at90);  // O(1/β)
  EXPECT_GT(r[0].at360, 50.0 * r[1].at360);
  EXPECT_LT(r[2].at90, 2.0 * one.at90);
  EXPECT_LT(r[2].at360, 2.0 * one.at360);
}

// `isoflex check` names the interface, its triples, angle and coupling, and the counts it prints
// are the System's.
TEST(KLMultipatch, CheckListsTheInterface) {
  const test::TempDir dir(test::temp_dir("isoflex_", "multipatch_check"));
  const std::string file = (dir.path() / "m.yaml").string();
  test::write_text(file, two_patch_roll_up("kl_interfaces: {beta: 1e4}\n"));
  const auto r = test::run_isoflex("check " + file);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("kl interfaces    1 (edges coincide within 1.2e-05"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("  left u1 -- right u0: 4 triples, angle 180.0°, coupling bending_strip "
                       "(β = 10000, E_s = 1.2e+10)"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("n                252"), std::string::npos) << r.out;
}

namespace {

// A free two-patch plate kicked by a short pulse, then free (energy–momentum, reparametrized):
// the largest relative drift of energy and momenta after the pulse. `edge_u` is the second
// patch's direction away from the joint x = 1, `interfaces` its kl_interfaces entry.
using test::Drift;
Drift free_plate_drift(const std::string& edge_u, const std::string& interfaces, double angle) {
  const std::string text = R"yaml(name: free_plate
solver: {dt: 0.01, t_end: 0.5}
surfaces:
  - name: a
    builtin: {type: rectangle, size: [1, 0.5]}
    refine: {elevate: [1, 1], knots_per_span: [3, 1]}
  - name: b
    builtin: {type: rectangle, corner: [1, 0, 0], edge_u: )yaml" +
                           edge_u + R"yaml(, edge_v: [0, 0.5, 0]}
    refine: {elevate: [1, 1], knots_per_span: [1, 1]}
kl_shells:
  - {name: a, surface: a, material: {E: 1.0e6, nu: 0.3, thickness: 0.02, density: 1000}}
  - {name: b, surface: b, material: {E: 1.0e6, nu: 0.3, thickness: 0.02, density: 1000}}
kl_loads:
  - {shell: a, edge: u0, force_per_length: [0, 0, "400*sin(10*pi*t)^2*(t<=0.1)"]}
  - {shell: b, area_force: [0, "80*sin(10*pi*t)^2*(t<=0.1)", 0]}
)yaml" + interfaces;
  const model::Model m = io::read_model_string(text, "m.yaml");
  const auto sys = system::System::compile(m);
  EXPECT_EQ(sys.kl_interfaces().size(), 1u);
  EXPECT_NEAR(sys.kl_interfaces().at(0).geometry.angle_min, angle, 1e-9);
  const test::Trajectory r = test::simulate(m, model::Formulation::reparametrized);
  const auto& s = r.snapshots;
  const std::size_t i0 = r.first_at(0.1);
  const Drift d = test::drift_after(r, 0.1);
  std::printf("  after the pulse: energy %.2e, |p| %.2e, |L| %.2e (relative)\n", d.energy, d.p,
              d.L);
  EXPECT_GT(s[i0].potential_energy, 1e-3 * s[i0].total_energy);  // it is bent, not only moving
  return d;
}

}  // namespace

// Bent at 120° along the cut, with a strip: the strip's discrete gradient (kl-shell.md §10 on the
// strip material) keeps energy and both momenta after the pulse to round-off.
TEST(KLMultipatch, EnergyMomentumConservesWithAStrip) {
  const Drift d =
      free_plate_drift("[0.5, 0, 0.8660254037844386]", "kl_interfaces: {beta: 100}\n", 120.0);
  EXPECT_LT(d.energy, 1e-11);
  EXPECT_LT(d.p, 1e-11);
  EXPECT_LT(d.L, 1e-11);
}

// Flat, with AF-D: the linear rows (5.36) hold exactly at every time node of the midpoint rule
// and their forces do no work, so energy and momenta are kept to round-off as well.
TEST(KLMultipatch, EnergyMomentumConservesWithAngleConstraints) {
  const Drift d = free_plate_drift("[0.5, 0, 0]", "kl_interfaces: {coupling: angle}\n", 180.0);
  EXPECT_LT(d.energy, 1e-11);
  EXPECT_LT(d.p, 1e-11);
  EXPECT_LT(d.L, 1e-11);
}

// Bent at 120° along the cut, with AF-D: the angle row (5.37) with its discrete derivative in the
// invariants (joints/triple_continuity_rows.hpp) keeps energy and momenta to round-off.
TEST(KLMultipatch, EnergyMomentumConservesWithAngleConstraintsAtAKink) {
  const Drift d =
      free_plate_drift("[0.5, 0, 0.8660254037844386]", "kl_interfaces: {coupling: angle}\n", 120.0);
  EXPECT_LT(d.energy, 1e-11);
  EXPECT_LT(d.p, 1e-11);
  EXPECT_LT(d.L, 1e-11);
}

// Interfaces that cannot be joined stop the compile at the shell; bad kl_interfaces keys are
// located reader errors.
TEST(KLMultipatch, LocatedErrors) {
  std::string half = two_patch_roll_up("");
  half = test::replaced(half, "builtin: {type: rectangle, size: [6, 1], corner: [6, 0, 0]}",
                        "builtin: {type: rectangle, size: [6, 0.5], corner: [6, 0, 0]}");
  try {
    system::System::compile(io::read_model_string(half, "m.yaml"));
    ADD_FAILURE() << "no error for a T-junction";
  } catch (const system::CompileError& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "m.yaml:12: kl_shells[1]: \"right\" edge u0 lies along part of \"left\" edge u1"),
              std::string::npos)
        << e.what();
  }
  EXPECT_NE(test::error_of(two_patch_roll_up("kl_interfaces: {coupling: glue}\n"))
                .find("m.yaml:20: kl_interfaces.coupling: unknown coupling \"glue\" (expected c0, "
                      "bending_strip, strip_constraints, perturbed_lagrange or angle)"),
            std::string::npos);
  EXPECT_NE(test::error_of(two_patch_roll_up("kl_interfaces: {tolerance: 0.5}\n"))
                .find("kl_interfaces.tolerance: at most 0.01"),
            std::string::npos);
  // A pair of one shell names its seam and knot lines; a flat plate has neither.
  try {
    system::System::compile(io::read_model_string(
        two_patch_roll_up("kl_interfaces: {pairs: [{shells: [left, left]}]}\n"), "m.yaml"));
    ADD_FAILURE() << "no error for a pair of one shell without a seam";
  } catch (const system::CompileError& e) {
    EXPECT_NE(std::string(e.what()).find("kl_interfaces.pairs[0]: \"left\" has no interface "
                                         "with itself"),
              std::string::npos)
        << e.what();
  }
  EXPECT_NE(test::error_of(two_patch_roll_up("kl_interfaces: {pairs: [{shells: [left, x]}]}\n"))
                .find("kl_interfaces.pairs[0].shells[1]: no kl_shell named \"x\""),
            std::string::npos);
}

namespace {

// Two free cubic plates (2 × 2 elements each, 5 triples, n = 4 strip elements), flat or at a
// right angle, with a coupling of rows, in a linear analysis: the coupling's rows and
// independent rows. Without supports nothing else takes rows away.
std::pair<int, int> coupling_rows(bool kinked, const std::string& coupling) {
  const std::string second = kinked ? "{type: rectangle, corner: [0, 0, 0], edge_u: [10, 0, 0], "
                                      "edge_v: [0, 0, -3]}"
                                    : "{type: rectangle, corner: [0, 0, 0], edge_u: [10, 0, 0], "
                                      "edge_v: [0, -3, 0]}";
  const std::string text = R"(name: rows
solver: {analysis: static, linear: true}
surfaces:
  - name: a
    builtin: {type: rectangle, corner: [0, 0, 0], edge_u: [10, 0, 0], edge_v: [0, 1, 0]}
    refine: {elevate: [2, 2], knots_per_span: [1, 1]}
  - name: b
    builtin: )" + second + R"(
    refine: {elevate: [2, 2], knots_per_span: [1, 1]}
kl_shells:
  - {name: a, surface: a, material: {E: 1.2e6, nu: 0, thickness: 0.1}}
  - {name: b, surface: b, material: {E: 1.2e6, nu: 0, thickness: 0.1}}
kl_interfaces: {coupling: )" +
                           coupling + "}\n";
  const auto sys = system::System::compile(io::read_model_string(text, "m.yaml"));
  const int c = sys.kl_interfaces().at(0).constraint_index;
  if (c < 0) {  // AF-D on straight triples: tied rows, as many slaves as independent rows
    const system::LinearConstraints& lin = sys.linear_constraints();
    EXPECT_EQ(3 * sys.kl_interfaces().at(0).tied_triples, static_cast<int>(lin.tied.size()));
    const auto map = system::DofMap::build(sys.n(), lin.eliminated, lin.tied);
    return {static_cast<int>(lin.tied.size()), static_cast<int>(map.slaves.size())};
  }
  return {sys.nary_constraints()[static_cast<std::size_t>(c)].constraint->constraint_count(),
          sys.independent_rows_of(c)};
}

}  // namespace

// IGA-thesis Conjecture 5.1: the strip forces as constraints (AF-BS, 3 × 3 × 5 = 45 rows) have
// rank 3(n + 1) = 15 at a kink and n + 1 = 5 where the patches continue flat (n = 4 strip
// elements, 3 × 2 quadrature points); the direct constraints (AF-D) are independent: one angle
// row per kinked triple (5.37), three rows (5.36) per straight one (in a static analysis tied
// rows, each eliminating a slave coordinate).
TEST(KLMultipatch, IndependentCouplingRowsFollowConjecture51) {
  EXPECT_EQ(coupling_rows(true, "strip_constraints"), std::make_pair(45, 15));
  EXPECT_EQ(coupling_rows(false, "strip_constraints"), std::make_pair(45, 5));
  EXPECT_EQ(coupling_rows(true, "angle"), std::make_pair(5, 5));
  EXPECT_EQ(coupling_rows(false, "angle"), std::make_pair(15, 15));
}

// The perturbed Lagrange rows and AF-BS in a dynamic run stop the compile at the kl_interfaces
// entry, saying why.
TEST(KLMultipatch, UnsupportedCouplingsAreLocatedErrors) {
  const auto error = [](const std::string& text) {
    try {
      system::System::compile(io::read_model_string(text, "m.yaml"));
    } catch (const system::CompileError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  std::string dynamic = test::example_text("kl_hinged_plate", "model.yaml");
  const std::string pl =
      error(test::replaced(dynamic, "coupling: angle ", "coupling: perturbed_lagrange "));
  EXPECT_NE(pl.find("kl_interfaces (left -- right): coupling perturbed_lagrange is built for "
                    "static analyses so far"),
            std::string::npos)
      << pl;
  dynamic = test::replaced(dynamic, "coupling: angle ", "coupling: strip_constraints ");
  const std::string bs = error(dynamic);
  EXPECT_NE(bs.find("coupling strip_constraints is built for static analyses so far"),
            std::string::npos)
      << bs;
}

// AF-BS in the nonlinear roll-up (the strip forces as rows, chosen again in every load step): the
// error against the KL exact roll-up at 90° and 360° is AF-D's (both make the cut C¹; the
// discretization's own error), and every one of the 36 rows holds — the n + 1 = 4 rows
// independent at the flat reference imply the others here.
TEST(KLMultipatch, NonlinearStripConstraintsRollTheTwoPatchPlateUp) {
  const std::string text = two_patch_roll_up("kl_interfaces: {coupling: strip_constraints}\n");
  const RollUp af_bs = roll_up(text),
               af_d = roll_up(two_patch_roll_up("kl_interfaces: {coupling: angle}\n"));
  ASSERT_EQ(af_bs.failure, "");
  const model::Model m = io::read_model_string(text, "m.yaml");
  const auto sys = test::static_system(m);
  const test::StaticRun r = test::solve_static(sys, m);
  const auto& c = sys.nary_constraints().at(0);
  const VecX phi = sys.constraints(r.steps.back().q, 1.0)
                       .segment(c.row_offset, c.constraint->constraint_count());
  std::printf(
      "  error at 90 / 360 deg: AF-BS %.3e / %.3e, AF-D %.3e / %.3e; rows %d, kept %d, "
      "max |Phi| %.2e\n",
      af_bs.at90, af_bs.at360, af_d.at90, af_d.at360, c.constraint->constraint_count(),
      sys.independent_rows_of(0), phi.cwiseAbs().maxCoeff());
  EXPECT_EQ(sys.independent_rows_of(0), 4);
  EXPECT_NEAR(af_bs.at90, af_d.at90, 1e-3 * af_d.at90);
  EXPECT_NEAR(af_bs.at360, af_d.at360, 1e-3 * af_d.at360);
  EXPECT_LT(phi.cwiseAbs().maxCoeff(), 1e-6);
}

// Perturbed Lagrange in the nonlinear roll-up (the strip's nonlinear forces with the compliance
// ŝ/α₁, all rows kept): a penalty ŝ α₁ G_sᵀ f_s on the strip forces, so its error against AF-BS
// at 360° falls like 1/α₁.
TEST(KLMultipatch, NonlinearPerturbedLagrangeTendsToStripConstraints) {
  const RollUp af_bs = roll_up(two_patch_roll_up("kl_interfaces: {coupling: strip_constraints}\n"));
  ASSERT_EQ(af_bs.failure, "");
  double previous = 1e300;
  for (const char* alpha : {"1e-2", "1e0", "1e2"}) {
    const RollUp pl = roll_up(two_patch_roll_up(
        std::string("kl_interfaces: {coupling: perturbed_lagrange, beta: ") + alpha + "}\n"));
    ASSERT_EQ(pl.failure, "") << alpha;
    const double gap = std::abs(pl.at360 - af_bs.at360);
    std::printf("  alpha %s: error at 360 deg %.6e (AF-BS %.6e), gap %.3e\n", alpha, pl.at360,
                af_bs.at360, gap);
    EXPECT_LT(gap, 0.05 * previous) << alpha;  // measured: 2.8e-5, 2.8e-7, 2.8e-9 (∝ 1/α₁)
    previous = gap;
  }
  EXPECT_LT(previous, 1e-2 * af_bs.at360);
}

namespace {

// The angle between the legs of every triple of the L-plate's interface at q (degrees).
std::vector<double> triple_angles(const system::System& sys, const VecX& q) {
  const auto& T = sys.kl_interfaces().at(0).triple_nodes;
  std::vector<double> out;
  for (std::size_t k = 0; k < T.size(); k += 3) {
    const auto x = [&](std::size_t i) { return Vec3(q.segment<3>(sys.q_offset(T[k + i]))); };
    const Vec3 a = x(1) - x(0), b = x(2) - x(1);
    out.push_back(std::acos(a.dot(b) / (a.norm() * b.norm())) * 180.0 / M_PI);
  }
  return out;
}

}  // namespace

// AF-D at a kink in a nonlinear analysis (the angle row (5.37) with its Hessian): the L-plate of
// IGA-thesis §6.4.2.2 under 10⁻³ of its load deflects as the linear analysis does (relative
// 10⁻³), and under 30× the load (a deflection of the order of the web's height) keeps the
// angle of every triple that has its row at 90° to the Newton tolerance. The rows are selected at
// the reference (Alg. 5.1 once, modulo the supports): the row of triple 1, on row 1 of the clamp,
// is dropped there because the clamp's linear rows hold that angle to first order; the clamp
// leaves the stretch across the edge free, so under large loads that triple's angle moves at
// second order (10⁻⁴° here) — the deviation that a selection in every Newton iteration would
// remove (docs/theory/multipatch.md).
TEST(KLMultipatch, NonlinearAngleConstraintsKeepTheKink) {
  const std::string linear_text = test::example_text("kl_l_shaped_plate", "model.yaml");
  const auto tip = [&](const std::string& text) {
    const model::Model m = io::read_model_string(text, "model.yaml");
    const auto sys = test::static_system(m);
    const test::StaticRun r = test::solve_static(sys, m);
    EXPECT_EQ(r.failure, "");
    const VecX q = r.steps.empty() ? sys.q0() : r.steps.back().q;
    return std::make_tuple(Vec3(test::probe_at(sys, q, "load") - Vec3(10, 1, 0)),
                           triple_angles(sys, q), r.steps.empty() ? 0 : r.steps.back().iterations);
  };
  const std::string load = "force: [0, 0, -3]";
  const auto [u_lin, a_lin, it_lin] =
      tip(test::replaced(linear_text, load, "force: [0, 0, -0.003]"));
  const std::string nonlinear = test::replaced(linear_text, "linear: true, dt: 1", "dt: 0.1");
  const auto [u_small, a_small, it_small] =
      tip(test::replaced(nonlinear, load, "force: [0, 0, -0.003]"));
  std::printf("  small load: linear uz %.9e, nonlinear %.9e\n", u_lin.z(), u_small.z());
  EXPECT_LT(u_lin.z(), 0.0);
  EXPECT_NEAR(u_small.z() / u_lin.z(), 1.0, 1e-3);
  const auto [u, angles, iterations] = tip(test::replaced(nonlinear, load, "force: [0, 0, -90]"));
  std::printf("  30x load: uz %.4f, last step %d iterations, angles", u.z(), iterations);
  for (double a : angles) std::printf(" %.12f", a);
  std::printf("\n");
  EXPECT_LT(u.z(), -0.5);  // large: of the order of the web's height 3
  ASSERT_EQ(angles.size(), 5u);
  for (std::size_t k : {0, 2, 3, 4}) EXPECT_NEAR(angles[k], 90.0, 1e-8) << "triple " << k;
  EXPECT_NEAR(angles[1], 90.0, 1e-3);
  EXPECT_GT(std::abs(angles[1] - 90.0), 1e-6);  // the dropped row: held to first order only
  EXPECT_LE(iterations, 8);
}

namespace {

// The linear L-plate (examples/kl_l_shaped_plate) with the coupling given, solved by the static
// solver: the configuration at the load.
VecX l_plate(model::KLCoupling coupling, double beta, system::System* out = nullptr) {
  model::Model m =
      io::read_model_string(test::example_text("kl_l_shaped_plate", "model.yaml"), "model.yaml");
  m.kl_interfaces.coupling = coupling;
  m.kl_interfaces.beta = beta;
  auto sys = test::static_system(m);
  const test::StaticRun r = test::solve_static(sys, m);
  EXPECT_EQ(r.failure, "");
  if (out) *out = std::move(sys);
  return r.steps.back().q;
}

}  // namespace

// IGA-thesis Theorem 5.1: the perturbed Lagrange rows ŝ f_s − (ŝ/α₁) λ = 0 (5.24b) are the
// penalty ŝ α₁ K_sᵀK_s on the strip forces — at α₁ = 1 the solution equals the one of
// K + (1/c) GᵀG with G the rows and c their compliance, built here by hand from the hinge's
// stiffness (dense, on the coordinates the clamps leave free) — and, as a penalty, it tends to
// AF-BS (the strip forces as exact constraints) with an error ∝ 1/α₁.
TEST(KLMultipatch, PerturbedLagrangeIsAPenaltyOnTheStripForces) {
  using C = model::KLCoupling;
  const double alpha = 1.0;
  system::System pl_sys = system::System::compile(
      io::read_model_string(test::example_text("kl_l_shaped_plate", "model.yaml"), "model.yaml"));
  const VecX q_pl = l_plate(C::perturbed_lagrange, alpha, &pl_sys);
  system::System hinge;
  l_plate(C::c0, 1.0, &hinge);
  ASSERT_EQ(hinge.n(), pl_sys.n());
  const system::LinearConstraints lc = hinge.linear_constraints();
  ASSERT_EQ(lc.multipliers(), 0);  // the clamps only eliminate
  // K u = f_ext + penalty, over the free coordinates.
  system::SpMat Ks;
  const VecX f = hinge.static_force(hinge.q0(), 1.0, &Ks);  // ∇V(q₀) − f_ext = −f_ext
  MatX K(Ks);
  const auto& rows = *pl_sys.nary_constraints().at(0).constraint;
  ASSERT_GT(rows.compliance(), 0.0);
  MatX G = MatX::Zero(rows.constraint_count(), pl_sys.n());
  const MatX Gc = rows.jacobian(VecX::Zero(3 * static_cast<int>(rows.nodes().size())));
  for (std::size_t a = 0; a < rows.nodes().size(); ++a)
    G.middleCols<3>(pl_sys.q_offset(rows.nodes()[a])) = Gc.middleCols<3>(3 * static_cast<int>(a));
  K += G.transpose() * G / rows.compliance();
  std::vector<int> free;
  for (int i = 0; i < hinge.n(); ++i)
    if (!std::binary_search(lc.eliminated.begin(), lc.eliminated.end(), i)) free.push_back(i);
  MatX Kf(free.size(), free.size());
  VecX ff(free.size());
  for (std::size_t i = 0; i < free.size(); ++i) {
    ff(static_cast<int>(i)) = -f(free[i]);
    for (std::size_t j = 0; j < free.size(); ++j)
      Kf(static_cast<int>(i), static_cast<int>(j)) = K(free[i], free[j]);
  }
  const VecX uf = Kf.lu().solve(ff);
  VecX u_pl = q_pl - pl_sys.q0();
  double diff = 0.0;
  for (std::size_t i = 0; i < free.size(); ++i)
    diff = std::max(diff, std::abs(u_pl(free[i]) - uf(static_cast<int>(i))));
  std::printf("  perturbed Lagrange vs the penalty by hand: %.2e (of %.3e)\n", diff,
              uf.lpNorm<Eigen::Infinity>());
  // Both solves carry the penalty's conditioning: their residuals in K + GᵀG/c are 1e-7 (by
  // hand) and 1.6e-6 (the static solver) of the load.
  EXPECT_LT(diff, 1e-7 * uf.lpNorm<Eigen::Infinity>());
  // The limit α₁ → ∞ is AF-BS, approached ∝ 1/α₁.
  const VecX u_bs = l_plate(C::strip_constraints, 1.0) - pl_sys.q0();
  const double e3 = (l_plate(C::perturbed_lagrange, 1e3) - pl_sys.q0() - u_bs).norm(),
               e6 = (l_plate(C::perturbed_lagrange, 1e6) - pl_sys.q0() - u_bs).norm();
  std::printf("  distance to AF-BS: alpha 1e3 %.3e, 1e6 %.3e\n", e3, e6);
  EXPECT_NEAR(e3 / e6, 1e3, 100.0);
  EXPECT_LT(e6, 1e-6 * u_bs.norm());
}
