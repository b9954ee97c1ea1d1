// The Kirchhoff–Love shell benchmarks of IGA-thesis §6.4.1.2–6.4.1.4, read from their example
// files (examples/{scordelis_lo,pinched_cylinder,pinched_hemisphere}/kl_shell*.yaml): the default
// model (p = 4) reaches the reference within 0.5 %, and for p = 3 the error falls over a sequence
// of uniform knot refinements (the model text with its `refine` replaced, solved in process). The
// measured values are the tables of the example READMEs.
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "isoflex/io/model_reader.hpp"
#include "support/examples.hpp"
#include "support/statics.hpp"

using namespace isoflex;

namespace {

using test::example_text;
using test::replaced;

// The refine line of the example with degree p (surface degrees pu, pv) and k knots per span.
std::string refined(const std::string& text, const std::string& refine, int pu, int pv, int p,
                    int k) {
  const std::string ks = std::to_string(k);
  return replaced(text, refine,
                  "refine: {elevate: [" + std::to_string(p - pu) + ", " + std::to_string(p - pv) +
                      "], knots_per_span: [" + ks + ", " + ks + "]}");
}

// Displacement of probe `ref` (the first probe) after the static solve of the model text.
Vec3 ref_displacement(const std::string& text, const std::string& name) {
  const auto m = io::read_model_string(text, name);
  const auto sys = test::static_system(m);
  const auto r = test::solve_static(sys, m);
  EXPECT_EQ(r.failure, "");
  if (r.steps.empty()) return Vec3::Zero();
  return test::probe_at(sys, r.steps.back().q, "ref") - test::probe_at(sys, sys.q0(), "ref");
}

double rel(double u, double ref) {
  return std::abs(u - ref) / std::abs(ref);
}

constexpr const char* kRoofRefine = "refine: {elevate: [2, 3], knots_per_span: [3, 3]}";
constexpr const char* kShellRefine = "refine: {elevate: [2, 2], knots_per_span: [15, 15]}";
constexpr const char* kCylinderRefine = "refine: {elevate: [2, 3], knots_per_span: [15, 15]}";

}  // namespace

// Scordelis–Lo roof: −u_y at the midpoint of the free edge. Reference 0.3006, the converged
// Kirchhoff–Love value (the model's limit is 0.300592); the shear-deformable 0.3024 lies 0.6 %
// above it. Measured: default (p = 4, 4 × 4 elements) 0.300583 (−0.006 %); p = 3 with 0, 1, 3, 7
// knots per span 0.23501, 0.28816, 0.30007, 0.300584.
TEST(ScordelisLoKLShell, DefaultModelMatchesTheKirchhoffLoveValue) {
  const std::string text = example_text("scordelis_lo", "kl_shell.yaml");
  const double u = -ref_displacement(text, "kl_shell.yaml").y();
  EXPECT_LT(rel(u, 0.3006), 0.005);
  EXPECT_LT(rel(u, 0.3006), 2e-4);
  // The convention: the Kirchhoff–Love value, not the shear-deformable one (−0.60 %).
  EXPECT_GT(rel(u, 0.3024), 0.005);
  EXPECT_LT(rel(u, 0.3024), 0.007);
}

TEST(ScordelisLoKLShell, ErrorFallsWithKnotRefinementForCubics) {
  const std::string text = example_text("scordelis_lo", "kl_shell.yaml");
  std::array<double, 4> e{};
  const std::array<int, 4> knots{0, 1, 3, 7};
  for (std::size_t i = 0; i < knots.size(); ++i)
    e[i] =
        rel(-ref_displacement(refined(text, kRoofRefine, 2, 1, 3, knots[i]), "kl_shell.yaml").y(),
            0.3006);
  for (std::size_t i = 0; i + 1 < e.size(); ++i) EXPECT_LT(e[i + 1], e[i]) << knots[i + 1];
  EXPECT_LT(e[3], 2e-4);  // measured 5.2e-5
}

// The binary on the file itself: summary.json holds the probe (as the issue asks).
TEST(ScordelisLoKLShell, RunWritesTheProbeToTheSummary) {
  namespace fs = std::filesystem;
  const fs::path out =
      fs::temp_directory_path() / ("isoflex_klex_roof_" + std::to_string(::getpid()));
  const std::string cmd = std::string(ISOFLEX_BINARY) + " run --static \"" + ISOFLEX_SOURCE_DIR +
                          "/examples/scordelis_lo/kl_shell.yaml\" -o \"" + out.string() +
                          "\" > /dev/null 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  std::ifstream in(out / "summary.json");
  std::stringstream s;
  s << in.rdbuf();
  const std::string j = s.str();
  const auto at = j.find("\"ref\": {\"position\"");
  ASSERT_NE(at, std::string::npos) << j;
  const auto d = j.find("\"displacement\": [", at);
  ASSERT_NE(d, std::string::npos);
  double ux = 0, uy = 0, uz = 0;
  ASSERT_EQ(std::sscanf(j.c_str() + d, "\"displacement\": [%lf, %lf, %lf]", &ux, &uy, &uz), 3);
  EXPECT_LT(rel(-uy, 0.3006), 0.005);
  fs::remove_all(out);
}

// Pinched cylinder: u_z under the load (1/4 of the unit load on the eighth model) vs −1.8248e-5.
// Measured: default (p = 4, 16 × 16) −1.82056e-5 (−0.23 %); p = 3 with 3, 7, 15, 31 knots per
// span: see examples/pinched_cylinder/README.md (monotone from below, membrane locking).
TEST(PinchedCylinderKLShell, DefaultModelReachesTheReference) {
  const std::string text = example_text("pinched_cylinder", "kl_shell.yaml");
  const double u = ref_displacement(text, "kl_shell.yaml").z();
  EXPECT_LT(rel(u, -1.8248e-5), 0.005);
}

TEST(PinchedCylinderKLShell, ErrorFallsWithKnotRefinementForCubics) {
  const std::string text = example_text("pinched_cylinder", "kl_shell.yaml");
  std::array<double, 4> e{};
  const std::array<int, 4> knots{3, 7, 15, 31};
  for (std::size_t i = 0; i < knots.size(); ++i)
    e[i] = rel(
        ref_displacement(refined(text, kCylinderRefine, 2, 1, 3, knots[i]), "kl_shell.yaml").z(),
        -1.8248e-5);
  for (std::size_t i = 0; i + 1 < e.size(); ++i) EXPECT_LT(e[i + 1], e[i]) << knots[i + 1];
}

// Pinched hemisphere, closed, pole fixed (the thesis' version): u_x at (10, 0, 0) vs 0.0924. The
// patch has a collapsed edge at the pole; the Gauss points are interior, so it is accepted.
// Measured: default (p = 4, 16 × 16) 0.0923794 (−0.02 %); p = 3 with 3, 7, 15 knots per span
// 0.036902, 0.088896, 0.092277.
TEST(PinchedHemisphereKLShell, ClosedDefaultModelReachesTheReference) {
  const std::string text = example_text("pinched_hemisphere", "kl_shell.yaml");
  const double u = ref_displacement(text, "kl_shell.yaml").x();
  EXPECT_LT(rel(u, 0.0924), 0.005);
  EXPECT_LT(rel(u, 0.0924), 0.001);
}

TEST(PinchedHemisphereKLShell, ClosedErrorFallsWithKnotRefinementForCubics) {
  const std::string text = example_text("pinched_hemisphere", "kl_shell.yaml");
  std::array<double, 3> e{};
  const std::array<int, 3> knots{3, 7, 15};
  for (std::size_t i = 0; i < knots.size(); ++i)
    e[i] =
        rel(ref_displacement(refined(text, kShellRefine, 2, 2, 3, knots[i]), "kl_shell.yaml").x(),
            0.0924);
  for (std::size_t i = 0; i + 1 < e.size(); ++i) EXPECT_LT(e[i + 1], e[i]) << knots[i + 1];
  EXPECT_LT(e[2], 0.005);  // measured 0.13 %
}

// The 18°-hole version (MacNeal–Harder): the model converges to 0.093520, 0.51 % below the
// rounded 0.094 (references.md allows 1–2 %; CalculiX S8R: 0.093717). Measured: default (p = 4,
// 16 × 16) 0.0935003 (−0.53 % vs 0.094); p = 3 with 3, 7, 15 knots: 0.039543, 0.090667, 0.093431.
TEST(PinchedHemisphereKLShell, HoleVersionConvergesNearItsReference) {
  const std::string text = example_text("pinched_hemisphere", "kl_shell_hole.yaml");
  const double u = ref_displacement(text, "kl_shell_hole.yaml").x();
  EXPECT_LT(rel(u, 0.094), 0.01);
  EXPECT_LT(rel(u, 0.093717), 0.005);  // within 0.5 % of CalculiX S8R's converged value
  std::array<double, 3> e{};
  const std::array<int, 3> knots{3, 7, 15};
  for (std::size_t i = 0; i < knots.size(); ++i)
    e[i] = rel(
        ref_displacement(refined(text, kShellRefine, 2, 2, 3, knots[i]), "kl_shell_hole.yaml").x(),
        0.094);
  for (std::size_t i = 0; i + 1 < e.size(); ++i) EXPECT_LT(e[i + 1], e[i]) << knots[i + 1];
}
