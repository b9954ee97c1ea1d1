// A prescribed displacement of a Kirchhoff–Love edge in a dynamic run: rheonomic rows
// C (x − X) = d(t) (joints/linear_rows.hpp, IGA-thesis (3.37)–(3.40)) held at every time node
// tₙ₊₁ of the midpoint rule. Checked: a uniform edge motion ū(t) (in the trace space, so the L²
// projection is exact) moves the edge's control points by exactly ū(tₙ₊₁) in the three
// formulations, which agree; the response converges with order 2 in Δt (evaluating d at a wrong
// time node would make it order 1); a motion that starts with a speed starts the edge with that
// speed (the initial velocities solve G ν = ḋ(0)); and the energy changes in every step by exactly
// the work of the motion, −λᵀ(d(tₙ₊₁) − d(tₙ)) (docs/theory/schemes.md §7).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "isoflex/integrate/time_integrator.hpp"
#include "isoflex/io/model_reader.hpp"
#include "isoflex/loads/patch_edge.hpp"
#include "support/trajectory.hpp"

using namespace isoflex;

namespace {

// A free biquadratic strip 0.8 × 0.3 (3 × 1 elements) whose edge u0 is moved by `motion` (z).
model::Model strip(const std::string& motion, double dt, double t_end) {
  return io::read_model_string(
      "solver: {dt: " + std::to_string(dt) + ", t_end: " + std::to_string(t_end) +
          "}\n"
          "surfaces:\n"
          "  - {name: s, builtin: {type: rectangle, size: [0.8, 0.3]},\n"
          "     refine: {elevate: [1, 1], knots_per_span: [2, 0]}}\n"
          "kl_shells:\n"
          "  - {name: strip, surface: s,\n"
          "     material: {E: 2.0e4, nu: 0.25, thickness: 0.04, density: 800}}\n"
          "kl_supports:\n"
          "  - {shell: strip, edge: u0, displacement: [0, 0, \"" +
          motion +
          "\"]}\n"
          "probes:\n"
          "  - {name: tip, shell: strip, point: [0.8, 0.3, 0]}\n",
      "strip.yaml");
}

const std::string kShake = "0.05*sin(4*pi*t)^2";

double shake(double t) {
  return 0.05 * std::pow(std::sin(4.0 * M_PI * t), 2);
}

// The system coordinates of the control points on the moving edge (row 0 of u0).
std::vector<int> edge_offsets(const system::System& sys) {
  const auto& P = sys.kl_patches().front();
  std::vector<int> out;
  for (int cp : loads::edge_control_points(P.element->patch().reference(), loads::PatchEdge::u0, 0))
    out.push_back(sys.q_offset(P.nodes[static_cast<std::size_t>(cp)]));
  return out;
}

}  // namespace

TEST(PrescribedMotion, TheEdgeFollowsExactlyInEveryFormulation) {
  using F = model::Formulation;
  std::vector<Vec3> tips;
  for (const F f : {F::reparametrized, F::constrained, F::nullspace}) {
    model::Model m = strip(kShake, 0.01, 0.5);
    m.solver.formulation = f;
    const auto sys = system::System::compile(m);
    ASSERT_TRUE(sys.rheonomic());
    const integrate::EnergyMomentumIntegrator integ(sys, m.solver);
    auto s = integ.initial_state();
    const std::vector<int> edge = edge_offsets(sys);
    ASSERT_EQ(edge.size(), 3u);
    double off = 0.0, phi = 0.0;
    for (int i = 1; i <= 50; ++i) {
      integ.step(s);
      for (int o : edge) {
        off = std::max(off, std::abs(s.q(o + 2) - sys.q0()(o + 2) - shake(s.t)));
        off = std::max(off, (s.q.segment<2>(o) - sys.q0().segment<2>(o)).norm());
      }
      phi = std::max(phi, sys.constraints(s.q, s.t).lpNorm<Eigen::Infinity>());
    }
    std::printf("  [prescribed] %s: edge off its motion %.2e, max |Phi| %.2e\n",
                model::to_string(f), off, phi);
    EXPECT_LT(off, 1e-14);
    EXPECT_LT(phi, 1e-15);
    tips.push_back(integ.snapshot(s, {}, {}).probes.front().position);
  }
  EXPECT_GT(std::abs(tips[0].z()), 1e-3);  // the free end swings
  EXPECT_LT((tips[1] - tips[0]).norm(), 1e-8);
  EXPECT_LT((tips[2] - tips[0]).norm(), 1e-8);
}

TEST(PrescribedMotion, SecondOrderInTheStep) {
  std::vector<Vec3> at;
  for (const double dt : {0.01, 0.005, 0.0025, 0.00125})
    at.push_back(test::simulate(strip(kShake, dt, 0.2), model::Formulation::reparametrized)
                     .probe("tip")
                     .back());
  const std::vector<double> r = test::successive_ratios(at);
  std::printf("  [prescribed] ratios of successive differences: %.3f %.3f\n", r[0], r[1]);
  for (const double x : r) {
    EXPECT_GT(x, 3.5);
    EXPECT_LT(x, 4.5);
  }
}

TEST(PrescribedMotion, AMotionWithASpeedStartsWithIt) {
  const model::Model m = strip("0.1*t", 0.01, 0.01);
  const auto sys = system::System::compile(m);
  const std::vector<int> edge = edge_offsets(sys);
  for (int i = 0; i < sys.n(); ++i) {
    const bool moving = i % 3 == 2 && std::find(edge.begin(), edge.end(), i - 2) != edge.end();
    EXPECT_NEAR(sys.v0()(i), moving ? 0.1 : 0.0, 1e-12) << "coordinate " << i;
  }
}

TEST(PrescribedMotion, EnergyChangesByTheWorkOfTheMotion) {
  model::Model m = strip(kShake, 0.01, 0.3);
  m.solver.formulation = model::Formulation::constrained;
  const auto sys = system::System::compile(m);
  const integrate::EnergyMomentumIntegrator integ(sys, m.solver);
  auto s = integ.initial_state();
  const int n = sys.n(), ms = sys.m_selected();
  // d(t) of every row: Φ(q₀) = 0, so constraints(q₀, t) = −d(t).
  auto d = [&](double t) -> VecX { return -sys.constraints(sys.q0(), t); };
  double E = integ.snapshot(s, {}, {}).total_energy, worst = 0.0, scale = 0.0;
  for (int i = 1; i <= 30; ++i) {
    const double t0 = s.t;
    integ.step(s);
    ASSERT_EQ(s.last_unknowns.size(), n + ms);
    const VecX lambda = s.last_unknowns.tail(ms);
    const VecX dd = d(s.t) - d(t0);
    double work = 0.0;
    for (int r = 0; r < ms; ++r)
      work -= lambda(r) * dd(sys.selected_rows()[static_cast<std::size_t>(r)]);
    const double E1 = integ.snapshot(s, {}, {}).total_energy;
    worst = std::max(worst, std::abs(E1 - E - work));
    scale = std::max(scale, std::abs(work));
    E = E1;
  }
  std::printf("  [prescribed] energy balance: max |dE - W| %.2e, max |W| %.2e\n", worst, scale);
  EXPECT_GT(scale, 1e-3);
  EXPECT_LT(worst, 1e-11 * scale);
}

// The DAE schemes impose the same rows at their time nodes (integrate/dae_integrator.hpp).
TEST(PrescribedMotion, TheEdgeFollowsExactlyWithTheDaeSchemes) {
  using I = model::Integrator;
  for (const I scheme : {I::generalized_alpha, I::bdf1, I::bdf2}) {
    model::Model m = strip(kShake, 0.01, 0.5);
    m.solver.integrator = scheme;
    const auto sys = system::System::compile(m);
    const auto integ = integrate::make_time_integrator(sys, m.solver);
    auto s = integ->initial_state();
    const std::vector<int> edge = edge_offsets(sys);
    double off = 0.0;
    for (int i = 1; i <= 50; ++i) {
      integ->step(s);
      for (int o : edge) off = std::max(off, std::abs(s.q(o + 2) - sys.q0()(o + 2) - shake(s.t)));
    }
    std::printf("  [prescribed] %s: edge off its motion %.2e\n", model::to_string(scheme), off);
    EXPECT_LT(off, 1e-14) << model::to_string(scheme);
  }
}
