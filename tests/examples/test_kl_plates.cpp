// The Kirchhoff–Love shell benchmarks on flat plates, read from their example files and solved
// in-process (io::read_model_string → System → integrate::StaticEquilibrium):
// - examples/plate_roll_up/kl_shell.yaml: the cantilever rolled up by an end moment, nonlinear,
//   tip vs the exact arc (IGA-thesis (6.14)) at 90°, 180°, 360°;
// - examples/kirchhoff_plates/kl_shell.yaml (simply supported) and kl_shell_clamped.yaml: square
//   plates under uniform pressure, linear, centre deflection vs the Kirchhoff plate solution
//   (Timoshenko & Woinowsky-Krieger; shared/data/references.md).
// The measured figures are in the two READMEs.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "isoflex/io/model_reader.hpp"
#include "support/examples.hpp"
#include "support/statics.hpp"

using namespace isoflex;

namespace {

using test::example_text;
using test::replaced;

// Displacement of probe `ref` after every accepted load step: (t, u).
std::vector<std::pair<double, Vec3>> probe_path(const std::string& text, const std::string& name) {
  const model::Model m = io::read_model_string(text, name);
  const auto sys = test::static_system(m);
  const auto r = test::solve_static(sys, m);
  EXPECT_EQ(r.failure, "");
  const Vec3 X = test::probe_at(sys, sys.q0(), "ref");
  std::vector<std::pair<double, Vec3>> out;
  for (const auto& st : r.steps) out.push_back({st.t, test::probe_at(sys, st.q, "ref") - X});
  return out;
}

// ---- plate roll-up ----------------------------------------------------------------------------

constexpr double kL = 12.0;
constexpr std::array<double, 3> kLoad{0.25, 0.5, 1.0};  // 90°, 180°, 360°

// IGA-thesis (6.14): the inextensible arc of angle θ = 2π t.
Vec3 elastica_tip(double t) {
  const double th = 2.0 * std::numbers::pi * t;
  return {kL * (std::sin(th) / th - 1.0), 0.0, kL * (1.0 - std::cos(th)) / th};
}

// The Kirchhoff–Love model's own exact solution (examples/plate_roll_up/README.md): the arc is
// stretched by λ, λ² = 1 − h²θ²/(6L²) (h = 0.1 the thickness; Green–Lagrange membrane strain
// ε = −h²θ²/(12L²)), and turns further, θ = θ₀/λ², because the bending strain is measured in the
// reference metric.
Vec3 kl_tip(double t) {
  const double th0 = 2.0 * std::numbers::pi * t, h = 0.1;
  double th = th0, lam = 1.0;
  for (int i = 0; i < 50; ++i) {
    lam = std::sqrt(1.0 - h * h * th * th / (6.0 * kL * kL));
    th = th0 / (lam * lam);
  }
  return {lam * kL * std::sin(th) / th - kL, 0.0, lam * kL * (1.0 - std::cos(th)) / th};
}

struct RollUpErrors {
  std::array<double, 3> elastica{};  // |u_h − u_(6.14)| / |u_(6.14)|
  std::array<double, 3> kl{};        // |u_h − u_KL| / |u_(6.14)|
};

// Degree p, N elements along the plate (one across the width). as_is: the file's 16 load steps,
// else 4 steps of 90°: the same equilibria (measured: the same tip positions to 8 digits) at 92
// instead of 176 Newton iterations.
RollUpErrors roll_up(int p, int N, bool as_is = false) {
  std::string text = example_text("plate_roll_up", "kl_shell.yaml");
  if (!as_is) text = replaced(text, "dt: 0.0625", "dt: 0.25");
  text = replaced(text, "refine: {elevate: [2, 2], knots_per_span: [15, 0]}",
                  "refine: {elevate: [" + std::to_string(p - 1) + ", " + std::to_string(p - 1) +
                      "], knots_per_span: [" + std::to_string(N - 1) + ", 0]}");
  const auto path = probe_path(text, "kl_shell.yaml");
  RollUpErrors e;
  std::array<bool, 3> seen{};
  for (const auto& [t, u] : path)
    for (int k = 0; k < 3; ++k)
      if (std::abs(t - kLoad[k]) < 1e-12) {
        seen[k] = true;
        const Vec3 ue = elastica_tip(t);
        e.elastica[k] = (u - ue).norm() / ue.norm();
        e.kl[k] = (u - kl_tip(t)).norm() / ue.norm();
      }
  for (int k = 0; k < 3; ++k) EXPECT_TRUE(seen[k]) << "no load step at t = " << kLoad[k];
  return e;
}

// ---- square plates ----------------------------------------------------------------------------

// Simply supported square plate, uniform load: Navier series for the centre deflection,
// w = α q a⁴/D, α = 16/π⁶ Σ_{m,n odd} (−1)^((m+n)/2 − 1) / (m n (m² + n²)²).
double navier_alpha() {
  double s = 0.0;
  for (int m = 1; m < 2000; m += 2)
    for (int n = 1; n < 2000; n += 2)
      s += (((m + n) / 2 - 1) % 2 == 0 ? 1.0 : -1.0) /
           (double(m) * n * std::pow(double(m) * m + double(n) * n, 2));
  return 16.0 / std::pow(std::numbers::pi, 6) * s;
}

// The plates of the two files: a = 1, t = 0.01, E = 2.1e11, ν = 0.3, q = 1000 downwards.
double plate_w(double alpha) {
  const double D = 2.1e11 * 1e-6 / (12.0 * (1.0 - 0.3 * 0.3));
  return alpha * 1000.0 / D;
}

// Relative error of the centre deflection −u_z against α q a⁴/D, degree p, (k + 1)² elements.
double plate_error(const std::string& file, double alpha, int p, int k) {
  std::string text = example_text("kirchhoff_plates", file);
  text = replaced(text, "refine: {elevate: [2, 2], knots_per_span: [7, 7]}",
                  "refine: {elevate: [" + std::to_string(p - 1) + ", " + std::to_string(p - 1) +
                      "], knots_per_span: [" + std::to_string(k) + ", " + std::to_string(k) + "]}");
  const auto path = probe_path(text, file);
  EXPECT_EQ(path.size(), 1u);
  const double w = plate_w(alpha);
  return path.empty() ? 1.0 : std::abs(-path.back().second.z() - w) / w;
}

}  // namespace

// Measured (README.md), p = 3, 16 × 1 elements: 3.7e-5, 1.2e-4, 2.8e-4 of |u_exact| at 90°, 180°,
// 360°; p = 4: 3.7e-5, 1.3e-4, 4.5e-4 (the Kirchhoff–Love model's own distance from (6.14)).
TEST(PlateRollUpKLShell, DefaultMeshReachesTheExactArc) {
  for (int p : {3, 4}) {
    const RollUpErrors e = roll_up(p, 16, p == 3);  // p = 3: the file unchanged
    for (int k = 0; k < 3; ++k) {
      EXPECT_LT(e.elastica[k], 5e-3) << "p = " << p << ", t = " << kLoad[k];
      EXPECT_LT(e.elastica[k], 1e-3) << "p = " << p << ", t = " << kLoad[k];
    }
  }
}

// p = 3 on N = 4, 8, 16, 32 elements. Against the model's exact stretched arc the error falls by
// more than 8 per halving at every angle (measured 15–129; 2.9e-8, 4.4e-7, 6.5e-6 at N = 32);
// against (6.14) it falls until it reaches the model difference O((tθ/L)²) (3.7e-5, 1.3e-4,
// 4.6e-4), at N = 16 for 90°, N = 32 for 180° and 360°.
TEST(PlateRollUpKLShell, ErrorDecreasesWithRefinement) {
  std::array<RollUpErrors, 4> e;
  for (int i = 0; i < 4; ++i) e[i] = roll_up(3, 4 << i);
  for (int k = 0; k < 3; ++k) {
    for (int i = 0; i + 1 < 4; ++i) EXPECT_LT(8.0 * e[i + 1].kl[k], e[i].kl[k]) << i << ", " << k;
    EXPECT_LT(e[3].kl[k], 1e-5) << k;
    EXPECT_LT(e[1].elastica[k], e[0].elastica[k]) << k;
    EXPECT_LT(e[3].elastica[k], 1e-3) << k;
  }
  for (int k = 1; k < 3; ++k) EXPECT_LT(e[2].elastica[k], e[1].elastica[k]) << k;
}

// The rounded coefficient of references.md is the Navier sum.
TEST(KirchhoffPlatesKLShell, NavierCoefficient) {
  EXPECT_NEAR(navier_alpha(), 0.00406235, 5e-9);
}

// Measured (README.md), 8 × 8 elements: simply supported p = 3, 4, 5: +3.8e-5, +2.9e-6, −3.7e-7;
// clamped: −1.4e-4, +1.2e-5, −5.2e-6 (relative to 0.00126532, itself rounded to ±4e-6).
TEST(KirchhoffPlatesKLShell, DefaultMeshReachesTheKirchhoffSolution) {
  const double a_ss = navier_alpha();
  for (int p : {3, 4, 5}) {
    EXPECT_LT(plate_error("kl_shell.yaml", a_ss, p, 7), 5e-3) << p;
    EXPECT_LT(plate_error("kl_shell.yaml", a_ss, p, 7), 1e-4) << p;
    EXPECT_LT(plate_error("kl_shell_clamped.yaml", 0.00126532, p, 7), 5e-3) << p;
    EXPECT_LT(plate_error("kl_shell_clamped.yaml", 0.00126532, p, 7), 5e-4) << p;
  }
}

// p = 3 on 2², 4², 8², 16² elements. Measured: simply supported 1.5e-2, 5.2e-4, 3.8e-5, 2.5e-6;
// clamped 4.7e-2, 3.3e-3, 1.4e-4, 9e-6.
TEST(KirchhoffPlatesKLShell, ErrorDecreasesWithRefinement) {
  const double a_ss = navier_alpha();
  for (const auto& [file, alpha] : {std::pair{std::string("kl_shell.yaml"), a_ss},
                                    std::pair{std::string("kl_shell_clamped.yaml"), 0.00126532}}) {
    std::array<double, 4> e{};
    for (int i = 0; i < 4; ++i) e[i] = plate_error(file, alpha, 3, (2 << i) - 1);
    for (int i = 0; i + 1 < 4; ++i) EXPECT_LT(e[i + 1], 0.25 * e[i]) << file << " " << i;
  }
}
