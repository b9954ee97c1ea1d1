// The director-shell benchmarks, read from their files: the cantilever plate rolled up by an end
// moment (IGA-thesis (6.14), exact arc) and the Scordelis–Lo roof (IGA-thesis §6.4.1.2, 0.3024).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>

#include "isoflex/integrate/static_equilibrium.hpp"
#include "isoflex/io/model_reader.hpp"
#include "support/examples.hpp"
#include "support/statics.hpp"

using namespace isoflex;

namespace {

using test::example_text;
using test::replaced;

// Position of probe `ref` after each load step of the static solve.
std::vector<std::pair<double, Vec3>> static_probe(const model::Model& m) {
  const auto sys = system::System::compile(m);
  const test::StaticRun run = test::solve_static(sys, m);
  EXPECT_EQ(run.failure, "");
  std::vector<std::pair<double, Vec3>> out;
  const auto& probe = sys.probes().at(0);
  EXPECT_EQ(probe.name, "ref");
  for (const auto& st : run.steps)
    out.push_back({st.t, sys.material_point(st.q, probe.node, probe.X)});
  return out;
}

// Tip errors |x − x_exact|/L at 90°, 180°, 360° for N elements along the plate.
std::array<double, 3> roll_up_errors(int N) {
  std::string text = example_text("plate_roll_up", "director_shell.yaml");
  text = replaced(text, "elements: [32, 1]", "elements: [" + std::to_string(N) + ", 1]");
  text = replaced(text, "body: \"plate[32]\"", "body: \"plate[" + std::to_string(N) + "]\"");
  const auto path = static_probe(io::read_model_string(text, "director_shell.yaml"));
  const double L = 12.0;
  std::array<double, 3> e{};
  for (const auto& [t, x] : path)
    for (int k = 0; k < 3; ++k)
      if (std::abs(t - std::array{0.25, 0.5, 1.0}[k]) < 1e-9) {
        const double th = 2.0 * std::numbers::pi * t;
        e[k] = (x - Vec3(L * std::sin(th) / th, 0, L * (1 - std::cos(th)) / th)).norm() / L;
      }
  return e;
}

double scordelis_lo(int N) {
  std::string text = example_text("scordelis_lo", "director_shell.yaml");
  const std::string n = std::to_string(N);
  text = replaced(text, "elements: [16, 16]", "elements: [" + n + ", " + n + "]");
  const auto m = io::read_model_string(text, "director_shell.yaml");
  const auto sys = system::System::compile(m);
  const auto path = static_probe(m);
  return path.back().second.y() -
         sys.material_point(sys.q0(), sys.probes()[0].node, Vec3::Zero()).y();
}

}  // namespace

// Measured (32 elements): 3.0e-4, 1.9e-3, 7.0e-3 of L at 90°, 180°, 360°; 16 elements: 1.2e-3,
// 7.4e-3, 2.8e-2 (examples/plate_roll_up/README.md).
TEST(PlateRollUpDirectorShell, TipFollowsTheExactArc) {
  const auto e32 = roll_up_errors(32);
  EXPECT_LT(e32[0], 5e-4);
  EXPECT_LT(e32[1], 3e-3);
  EXPECT_LT(e32[2], 1e-2);
  const auto e16 = roll_up_errors(16);
  for (int k = 0; k < 3; ++k) EXPECT_GT(e16[k], 3.0 * e32[k]) << k;  // ≈ second order
}

// Reference 0.3024 (IGA-thesis §6.4.1.2), geometrically linear. Measured (examples/scordelis_lo/
// README.md): 4×4 0.31767 (+5.05 %), 8×8 0.30424 (+0.61 %), 16×16 0.30174 (−0.22 %), 32×32
// 0.30138 (−0.34 %), 64×64 0.30158 (−0.27 %). The coarse meshes are too flexible (in-plane shear
// at the centre); from 32 × 32 on the result approaches the model's limit ≈ 0.3020 from below, at
// first order, as the transverse-shear edge layers (width ~ t) at the free edge and the diaphragm
// are resolved. Hence the error rises from 16 × 16 to 32 × 32 and falls again: asserted are the
// issue's 1 % at 16 × 16, a decreasing error up to 16 × 16 and from 32 × 32 to 64 × 64, and
// shrinking changes between successive meshes.
TEST(ScordelisLoDirectorShell, MidpointOfTheFreeEdgeConvergesToTheReference) {
  const double ref = 0.3024;
  std::array<double, 5> u{}, e{};
  for (int k = 0; k < 5; ++k) {
    u[k] = -scordelis_lo(4 << k);
    e[k] = std::abs(u[k] - ref) / ref;
  }
  EXPECT_LT(e[2], 0.01);  // 16 × 16 (measured 0.22 %)
  EXPECT_LT(e[2], e[1]);
  EXPECT_LT(e[1], e[0]);
  EXPECT_LT(e[3], 0.004);
  EXPECT_LT(e[4], e[3]);
  for (int k = 0; k + 2 < 5; ++k)
    EXPECT_LT(std::abs(u[k + 2] - u[k + 1]), std::abs(u[k + 1] - u[k])) << k;
}

// Reference 0.0924 (IGA-thesis §6.4.1.4, the hemisphere without hole) within 2 % on 16 × 16, as
// the issue asks; the standard 18°-hole model is run (0.094 for it, MacNeal & Harder). Measured:
// 8×8 0.09359, 16×16 0.09324, 32×32 0.09342 (examples/pinched_hemisphere/README.md).
TEST(PinchedHemisphereDirectorShell, LoadPointMovesAsTheReference) {
  const std::string text = example_text("pinched_hemisphere", "director_shell.yaml");
  const auto path = static_probe(io::read_model_string(text, "director_shell.yaml"));
  const double u = path.back().second.x() - 10.0;
  EXPECT_LT(std::abs(u - 0.0924) / 0.0924, 0.02);
  EXPECT_LT(std::abs(u - 0.094) / 0.094, 0.02);
}
