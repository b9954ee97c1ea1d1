// The Newton stopping test is scale-aware (EnergyMomentumIntegrator::residual_scale): the heavy
// top of Simo & Wong (tip on a spherical joint, centre of mass 1 from the tip, tilted 0.5 rad,
// spinning at 50 rad/s; examples/heavy_top) at Δt = 0.001 over 10⁴ steps conserves its energy to
// 10⁻¹² relative with the default tolerances in all three formulations — and so does the same top
// in millimetres or kilometres (lengths × s, inertia × s², g × s: the same motion). Before, the
// residual scale of the reparametrized formulation was that of the full momentum terms with a
// floor of 1: the top of 1 mm stopped after 1.7 iterations per step and drifted 3.0·10⁻⁸.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/io/model_reader.hpp"
#include "isoflex/system/system.hpp"
#include "support/models.hpp"

using namespace isoflex;

namespace {

std::string top(double s, const std::string& formulation) {
  std::ostringstream y;
  y.precision(17);
  const double c = std::cos(0.5), n = std::sin(0.5);
  y << "gravity: [0, 0, " << -9.81 * s << "]\n"
    << "solver: {formulation: " << formulation << ", dt: 0.001, t_end: 10}\n"
    << "bodies:\n  - name: top\n    mass: 1.0\n"
    << "    inertia: [" << 0.625 * s * s << ", " << 0.625 * s * s << ", " << 0.25 * s * s << "]\n"
    << "    position: [0, " << -n * s << ", " << c * s << "]\n"
    << "    orientation: [[1, 0, 0], [0, " << c << ", " << n << "], [0, " << -n << ", " << c
    << "]]\n"
    << "    angular_velocity: [0, " << -50 * n << ", " << 50 * c << "]\n"
    << "joints:\n  - {type: spherical, body_a: ground, body_b: top, point: [0, 0, 0]}\n";
  return y.str();
}

}  // namespace

TEST(NewtonScale, HeavyTopConservesEnergyInAnyUnits) {
  for (const char* formulation : {"constrained", "nullspace", "reparametrized"}) {
    for (const double s : {1.0, 1e-3, 1e3}) {
      const model::Model m = io::read_model_string(top(s, formulation), "top.yaml");
      const auto sys = system::System::compile(m);
      integrate::EnergyMomentumIntegrator integ(sys, m.solver);
      auto st = integ.initial_state();
      const integrate::Snapshot first = integ.snapshot(st, {}, {});
      const double scale = std::abs(first.kinetic_energy) + std::abs(first.potential_energy);
      double drift = 0.0;
      long iterations = 0;
      for (int i = 0; i < 10000; ++i) {
        iterations += integ.step(st).iterations;
        drift =
            std::max(drift, std::abs(integ.snapshot(st, {}, {}).total_energy - first.total_energy));
      }
      std::printf(
          "  [Newton scale] %-14s lengths x %-6g: max |E - E0| / E = %.2e, %.2f iterations "
          "per step\n",
          formulation, s, drift / scale, iterations / 1e4);
      EXPECT_LT(drift / scale, 1e-12) << formulation << " x " << s;  // measured ≤ 4.0e-13
      EXPECT_GE(iterations, 20000) << formulation << " x " << s;     // ≥ 2 per step
    }
  }
}

// The reparametrized residual scale's |𝖯|ᵀ t is bounded from above by one leaves-to-root sweep
// of absolute blocks (System::abs_tree_null_space_transpose_bound, linear in the number of
// nodes): every entry at least the exact sum over the explicit 𝖯 = P_tree(q), and equal to it
// where a column's paths have one block (roots of their own: the beam nodes of the slider-crank).
TEST(NewtonScale, TheSweepBoundsTheReducedAbsoluteSums) {
  const auto slider = io::read_model(std::string(ISOFLEX_SOURCE_DIR) +
                                     "/examples/slider_crank_flexible/model.yaml");
  for (const auto& m : {slider, test::chain(6), test::heavy_top()}) {
    const auto sys = system::System::compile(m);
    integrate::EnergyMomentumIntegrator integ(sys, m.solver);
    auto s = integ.initial_state();
    for (int i = 0; i < 5; ++i) integ.step(s);
    std::srand(9);
    const VecX t = VecX::Random(sys.n()).cwiseAbs();
    const VecX exact = system::SpMat(sys.tree_null_space(s.q).cwiseAbs()).transpose() * t;
    const VecX bound = sys.abs_tree_null_space_transpose_bound(s.q, t);
    ASSERT_EQ(bound.size(), exact.size()) << m.name;
    for (Eigen::Index c = 0; c < exact.size(); ++c)
      EXPECT_GE(bound(c), exact(c) * (1.0 - 1e-14)) << m.name << " column " << c;
    if (m.name != slider.name) continue;
    std::vector<bool> parent(sys.node_count(), false);
    for (const auto& J : sys.joints())
      if (J.parent >= 0) parent[J.parent] = true;
    int checked = 0;
    for (std::size_t r = 0; r < sys.roots().size(); ++r) {
      if (parent[sys.roots()[r]]) continue;
      for (int c = 0; c < 6; ++c, ++checked) {
        const int col = sys.root_nu_offsets()[r] + c;
        EXPECT_NEAR(bound(col), exact(col), 1e-14 * exact(col)) << "root column " << col;
      }
    }
    EXPECT_GE(checked, 6 * 30);
  }
}
