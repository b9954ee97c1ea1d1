// The path-following examples (solver.path_following; integrate/static_newton.hpp), run in
// process from their model files: the hinged cylindrical roof through its limit points
// (examples/kl_snap_through, README.md) and the Kirchhoff–Love roll-up past the full circle
// (examples/plate_roll_up/kl_arc_length.yaml).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "isoflex/io/model_reader.hpp"
#include "support/examples.hpp"
#include "support/statics.hpp"

using namespace isoflex;

namespace {

struct Path {
  std::vector<double> load, w;  // P = 3000 λ; the centre's inward displacement
  test::StaticRun run;
};

const Vec3 kInward(-std::cos(0.1), -std::sin(0.1), 0.0);

std::string fmt_double(double v) {
  char text[64];
  std::snprintf(text, sizeof text, "%.17g", v);
  return text;
}

Path roof_path(const std::string& text, const std::string& name) {
  const auto m = io::read_model_string(text, name);
  const auto sys = test::static_system(m);
  Path p;
  p.run = test::solve_static(sys, m);
  EXPECT_EQ(p.run.failure, "") << name;
  const Vec3 x0 = test::probe_at(sys, sys.q0(), "centre");
  for (const auto& s : p.run.steps) {
    p.load.push_back(3000.0 * s.t);
    p.w.push_back(kInward.dot(test::probe_at(sys, s.q, "centre") - x0));
  }
  return p;
}

// The sampled maximum before w = 15 and minimum after it (the two limit points of the roof).
double top(const Path& p) {
  double v = -1e300;
  for (std::size_t i = 0; i < p.w.size(); ++i)
    if (p.w[i] < 15.0) v = std::max(v, p.load[i]);
  return v;
}
double bottom(const Path& p) {
  double v = 1e300;
  for (std::size_t i = 0; i < p.w.size(); ++i)
    if (p.w[i] > 15.0 && p.w[i] < 25.0) v = std::min(v, p.load[i]);
  return v;
}

}  // namespace

// Displacement control and arc length pass the same limit points of the 12.7 roof. Measured
// (README.md): maximum 2225.1 / 2225.5 at w = 10.5 / 10.82, minimum 510.3 / 515.0 at w = 19.5 /
// 19.84 (each a sample of the path, below the true maximum and above the true minimum).
TEST(KLSnapThrough, DisplacementControlAndArcLengthPassTheLimitPoints) {
  const Path d = roof_path(test::example_text("kl_snap_through", "model.yaml"), "model.yaml");
  const Path a =
      roof_path(test::example_text("kl_snap_through", "arc_length.yaml"), "arc_length.yaml");
  ASSERT_EQ(d.w.size(), 40u);
  for (std::size_t i = 0; i < d.w.size(); ++i)
    EXPECT_NEAR(d.w[i], 0.75 * static_cast<double>(i + 1), 1e-9) << "step " << i + 1;
  EXPECT_NEAR(top(d), 2225.1, 0.5);
  EXPECT_NEAR(bottom(d), 510.3, 1.0);
  EXPECT_NEAR(top(a), top(d), 0.005 * top(d));
  EXPECT_NEAR(bottom(a), bottom(d), 0.02 * bottom(d));
  // The snap: the load falls to less than a quarter of the limit load and rises again.
  EXPECT_LT(bottom(d), 0.25 * top(d));
  EXPECT_EQ(a.run.steps.back().t, 1.0);  // the arc-length run ends on λ = t_end exactly
  EXPECT_GT(a.w.back(), 25.0);           // on the far branch
}

// The same equilibrium by both methods: displacement control to the arc length's last
// displacement finds its load factor, 1.
TEST(KLSnapThrough, ArcLengthEndIsAnEquilibriumOfDisplacementControl) {
  const Path a =
      roof_path(test::example_text("kl_snap_through", "arc_length.yaml"), "arc_length.yaml");
  const std::string text =
      test::replaced(test::example_text("kl_snap_through", "model.yaml"), "displacement: 30",
                     "displacement: " + fmt_double(a.w.back()));
  const Path d = roof_path(text, "model.yaml");
  ASSERT_FALSE(d.run.steps.empty());
  EXPECT_NEAR(d.run.steps.back().t, 1.0, 1e-8);
}

// At half the thickness the path snaps back: past the load maximum the centre's displacement
// decreases along the path while the load is negative, where displacement control jumps.
TEST(KLSnapThrough, ThinRoofSnapsBack) {
  const Path a = roof_path(test::example_text("kl_snap_through", "thin_arc_length.yaml"),
                           "thin_arc_length.yaml");
  ASSERT_GT(a.w.size(), 20u);
  double w_max = 0.0, back = 0.0, load_min = 0.0;
  for (std::size_t i = 0; i < a.w.size(); ++i) {
    w_max = std::max(w_max, a.w[i]);
    back = std::max(back, w_max - a.w[i]);
    load_min = std::min(load_min, a.load[i]);
  }
  EXPECT_GT(back, 2.0);  // measured 2.48 (from w = 16.98 back to 14.50)
  EXPECT_NEAR(load_min, -386.8, 2.0);
  EXPECT_NEAR(top(a), 586.8, 2.0);
  EXPECT_EQ(a.run.steps.back().t, 1.0);
}

// Past the full circle: arc length to λ = 1.5 (540°) ends where load control to 1.5 ends, and the
// tip is the exact (6.14) x = 0, z = 8/π within the discretization error (measured 3.3e-3 in x,
// 2.6e-3 in z with 16 elements of p = 3).
TEST(KLRollUpArcLength, PastTheFullCircle) {
  const std::string text = test::example_text("plate_roll_up", "kl_arc_length.yaml");
  const auto m = io::read_model_string(text, "kl_arc_length.yaml");
  const auto sys = test::static_system(m);
  const test::StaticRun arc = test::solve_static(sys, m);
  ASSERT_EQ(arc.failure, "");
  for (std::size_t i = 1; i < arc.steps.size(); ++i)
    EXPECT_GT(arc.steps[i].t, arc.steps[i - 1].t) << "step " << i + 1;
  EXPECT_EQ(arc.steps.back().t, 1.5);
  model::Model load_control = m;
  load_control.solver.path = {};
  const test::StaticRun ref = test::solve_static(sys, load_control);
  ASSERT_EQ(ref.failure, "");
  const Vec3 x0 = test::probe_at(sys, sys.q0(), "ref");
  const Vec3 u = test::probe_at(sys, arc.steps.back().q, "ref") - x0;
  const Vec3 u_ref = test::probe_at(sys, ref.steps.back().q, "ref") - x0;
  EXPECT_LT((u - u_ref).norm(), 1e-8);
  EXPECT_NEAR(u.x(), -12.0, 5e-3);
  EXPECT_NEAR(u.z(), 8.0 / M_PI, 5e-3);
  EXPECT_NEAR(u.y(), 0.0, 1e-10);
}

// Arc length on the two-patch roll-up with AF-D's rows (straight: eliminated as tied rows, the
// bordered Cholesky step) and with AF-BS's strip forces as rows with multipliers (the bordered LU
// step), chosen at the start of each step (pinned for the step, whose Newton iteration evaluates
// at many λ); both end at λ = 1.5 where load control to 1.5 ends. Measured tip (−12.01235, 0, 2.542493) for both couplings and both methods.
TEST(KLRollUpArcLength, TwoPatchesWithConstraintRows) {
  for (const char* coupling : {"angle", "strip_constraints"}) {
    std::string text = test::example_text("kl_two_patch_roll_up", "model.yaml");
    text = test::replaced(text, "  coupling: bending_strip ",
                          std::string("  coupling: ") + coupling + " # ");
    text = test::replaced(text, "  t_end: 1\n", "  t_end: 1.5\n");
    const auto load = io::read_model_string(text, "model.yaml");
    const auto arc = io::read_model_string(
        test::replaced(text, "  t_end: 1.5\n",
                       "  t_end: 1.5\n  path_following: {method: arc_length, target_iterations: "
                       "8}\n"),
        "model.yaml");
    const auto sys = test::static_system(arc);
    const test::StaticRun ra = test::solve_static(sys, arc), rl = test::solve_static(sys, load);
    ASSERT_EQ(ra.failure, "") << coupling;
    ASSERT_EQ(rl.failure, "") << coupling;
    EXPECT_GT(ra.steps.size(), rl.steps.size()) << coupling;
    EXPECT_EQ(ra.steps.back().t, 1.5);
    const Vec3 x0 = test::probe_at(sys, sys.q0(), "tip");
    const Vec3 ua = test::probe_at(sys, ra.steps.back().q, "tip") - x0;
    const Vec3 ul = test::probe_at(sys, rl.steps.back().q, "tip") - x0;
    EXPECT_LT((ua - ul).norm(), 1e-8) << coupling;
    EXPECT_NEAR(ua.z(), 2.542493, 1e-5) << coupling;
  }
}

// Arc length on a geometrically exact beam (director coordinates, internal constraint rows): the
// roll-up of examples/beam_roll_up to λ = 1.5 ends where load control ends. (With the first arc
// as long as the linear tangent over dt, the first step found a kinked equilibrium with 300× the
// strain energy; the first step is now load control's.)
TEST(BeamRollUpArcLength, EndsWhereLoadControlEnds) {
  std::string text = test::example_text("beam_roll_up", "model_360.yaml");
  text = test::replaced(text, "  t_end: 1\n", "  t_end: 1.5\n");
  const auto load = io::read_model_string(text, "model_360.yaml");
  const auto arc = io::read_model_string(
      test::replaced(text, "  t_end: 1.5\n",
                     "  t_end: 1.5\n  path_following: {method: arc_length}\n"),
      "model_360.yaml");
  const auto sys = test::static_system(arc);
  const test::StaticRun ra = test::solve_static(sys, arc), rl = test::solve_static(sys, load);
  ASSERT_EQ(ra.failure, "");
  ASSERT_EQ(rl.failure, "");
  EXPECT_EQ(ra.steps.back().t, 1.5);
  EXPECT_NEAR(ra.steps.front().t, 0.05, 1e-15);  // the first step: load control over dt
  const Vec3 x0 = test::probe_at(sys, sys.q0(), "tip");
  const Vec3 ua = test::probe_at(sys, ra.steps.back().q, "tip") - x0;
  const Vec3 ul = test::probe_at(sys, rl.steps.back().q, "tip") - x0;
  EXPECT_LT((ua - ul).norm(), 1e-8);
  for (const auto& st : ra.steps) EXPECT_LE(st.iterations, 25);
}
