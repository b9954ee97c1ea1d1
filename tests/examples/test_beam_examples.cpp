// The beam examples, read from their files: the cantilever rolled up by an end moment (static,
// against the exact arc of IGA-thesis (6.14)) and the free-flying beam (conservation).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/integrate/static_equilibrium.hpp"
#include "isoflex/io/model_reader.hpp"
#include "support/finite_difference.hpp"
#include "support/sanitizers.hpp"
#include "support/statics.hpp"

using namespace isoflex;

namespace {

std::string example_file(const std::string& dir, const std::string& file) {
  return std::string(ISOFLEX_SOURCE_DIR) + "/examples/" + dir + "/" + file;
}

// The roll-up model for θ (degrees) with N elements: the beam's mesh and the node named by the
// end moment and the tip probe are changed together.
model::Model roll_up(int degrees, int N) {
  auto m =
      io::read_model(example_file("beam_roll_up", "model_" + std::to_string(degrees) + ".yaml"));
  m.beams.at(0).elements = {N};
  const std::string tip = "beam[" + std::to_string(N) + "]";
  m.loads.at(0).body = tip;
  m.probes.at(0).body = tip;
  return m;
}

struct RollUp {
  Vec3 tip;
  int iterations = 0;
};

// Static equilibrium at t = dt, 2 dt, …, t_end = 1 (the full moment).
RollUp solve_roll_up(const model::Model& m) {
  const auto sys = system::System::compile(m);
  const test::StaticRun run = test::solve_static(sys, m);
  EXPECT_EQ(run.failure, "");
  RollUp r;
  for (const auto& st : run.steps) r.iterations += st.iterations;
  const auto& p = sys.probes().at(0);
  r.tip = sys.material_point(run.steps.empty() ? sys.q0() : run.steps.back().q, p.node, p.X);
  return r;
}

// IGA-thesis (6.14): beam of length L along +x from the origin, rolled towards +z into an arc of
// angle θ: tip at x = L sin θ/θ, z = L (1 − cos θ)/θ.
Vec3 exact_tip(double theta, double L) {
  return Vec3(L * std::sin(theta) / theta, 0.0, L * (1.0 - std::cos(theta)) / theta);
}

}  // namespace

TEST(BeamRollUp, StaticTangentMatchesFiniteDifferences) {
  // A bent, loaded configuration (after 6 of 20 load steps of the 180° model, 4 elements) with its
  // multipliers; then x is perturbed off the manifold so that every term of J is exercised.
  auto m = roll_up(180, 4);
  const auto sys = system::System::compile(m);
  const integrate::StaticEquilibrium statics(sys, m.solver);
  m.solver.t_end = 6 * m.solver.dt;
  VecX x_bent;
  double t_bent = 0.0;
  integrate::StaticEquilibrium(sys, m.solver).solve([&](const auto& st, const VecX& x) {
    x_bent = x;
    t_bent = st.t;
  });
  std::mt19937 g(7);
  VecX x = x_bent;
  x += test::random_vector(g, static_cast<int>(x.size()), 1e-2);
  MatX J;
  statics.residual(t_bent, x, &J);
  const MatX Jfd = test::central_jacobian(
      [&](const VecX& y) { return statics.residual(t_bent, y, nullptr); }, x);
  EXPECT_LT(test::rel_diff(J, Jfd), 1e-8);
}

// Tip error against (6.14) at the model's mesh (32 elements) and at 64 elements. The error is
// second order in the element size (examples/beam_roll_up/README.md: observed orders 2.00–2.06
// between 32 and 128 elements): |error|/L = C (θ/N)², the square of the rotation per element, with
// C = 0.47 (90°), 0.74–0.75 (180°), 0.68–0.70 (360°) at N = 32 and 64. The test asserts
// |error|/L ≤ (θ/N)², i.e. C ≤ 1, and an observed order between 1.9 and 2.1.
TEST(BeamRollUp, TipConvergesToTheExactArcAtSecondOrder) {
  for (int degrees : {90, 180, 360}) {
    const double theta = degrees * std::numbers::pi / 180.0, L = 12.0;
    const Vec3 exact = exact_tip(theta, L);
    const auto file = example_file("beam_roll_up", "model_" + std::to_string(degrees) + ".yaml");
    EXPECT_EQ(io::read_model(file).beams.at(0).elements, std::vector<int>{32}) << file;
    double error[2];
    for (int k = 0; k < 2; ++k) {
      const int N = 32 << k;
      const RollUp r = solve_roll_up(roll_up(degrees, N));
      error[k] = (r.tip - exact).norm();
      EXPECT_LT(error[k] / L, (theta / N) * (theta / N)) << degrees << "° N = " << N;
      EXPECT_LT(std::abs(r.tip.y()), 1e-12) << "the roll-up stays in the xz-plane";
    }
    const double order = std::log2(error[0] / error[1]);
    EXPECT_GT(order, 1.9) << degrees << "°";
    EXPECT_LT(order, 2.1) << degrees << "°";
  }
}

namespace {
struct Conservation {
  double energy = 0;    // max |E − E₀| / max(|E₀|, T, |V|)
  double p = 0, L = 0;  // max |p − p₀|, |L − L₀| over their round-off scales (below)
  double p_rel = 0, L_rel = 0;  // the same over |p₀|, |L₀| (reported in the README)
  double phi = 0;
  double max_potential = 0, energy_after_pulse = 0;
  VecX q_at_200;  // q after 200 steps, to compare the formulations
};

// Runs the free-flying beam for `pulse` + `free` steps; drifts are measured from the end of the
// load pulse (step `pulse`, t = 0.05: the loads vanish from t_{n+½} = 0.0525 on). Energy relative
// to the largest of |E|, T and |V| seen (as tests/examples/test_examples.cpp); p = Σ (M v)_φ and
// L = Σ q_k × (M v)_k relative to their round-off scales, the largest Σ |(M v)_φ| over the nodes
// and Σ |q_k| |(M v)_k| over the 3-vector blocks seen (the sizes of the terms that are summed).
Conservation fly(model::Formulation f, int pulse, int free) {
  auto m = io::read_model(example_file("free_flying_beam", "model.yaml"));
  m.solver.formulation = f;
  const auto sys = system::System::compile(m);
  const integrate::EnergyMomentumIntegrator integ(sys, m.solver);
  auto s = integ.initial_state();
  for (int i = 0; i < pulse; ++i) integ.step(s);
  const auto a = integ.snapshot(s, {}, {});
  double scale = std::max({std::abs(a.total_energy), a.kinetic_energy, a.potential_energy});
  double ps = a.linear_momentum.norm(), Ls = a.angular_momentum.norm();
  Conservation c;
  c.energy_after_pulse = a.total_energy;
  for (int i = 0; i < free; ++i) {
    const auto st = integ.step(s);
    const auto b = integ.snapshot(s, st, {});
    scale = std::max({scale, b.kinetic_energy, std::abs(b.potential_energy)});
    const VecX Mv = sys.mass() * s.v;
    double pk = 0, lk = 0;
    for (int k = 0; k < Mv.size() / 3; ++k) {
      if (k % 4 == 0) pk += Mv.segment<3>(3 * k).norm();  // φ block of a frame node
      lk += s.q.segment<3>(3 * k).norm() * Mv.segment<3>(3 * k).norm();
    }
    ps = std::max(ps, pk);
    Ls = std::max(Ls, lk);
    const double dp = (b.linear_momentum - a.linear_momentum).norm();
    const double dL = (b.angular_momentum - a.angular_momentum).norm();
    c.energy = std::max(c.energy, std::abs(b.total_energy - a.total_energy));
    c.p = std::max(c.p, dp);
    c.L = std::max(c.L, dL);
    c.p_rel = std::max(c.p_rel, dp / a.linear_momentum.norm());
    c.L_rel = std::max(c.L_rel, dL / a.angular_momentum.norm());
    c.phi = std::max(c.phi, b.constraint_violation);
    c.max_potential = std::max(c.max_potential, b.potential_energy);
    if (pulse + i + 1 == 200) c.q_at_200 = s.q;
  }
  c.energy /= scale;
  c.p /= ps;
  c.L /= Ls;
  return c;
}
}  // namespace

// 10 000 free steps (t = 0.05 … 50.05) of the default (reparametrized) formulation.
TEST(FreeFlyingBeam, ConservesEnergyAndMomentaOver10000Steps) {
  ISOFLEX_SKIP_LONG_RUN_UNDER_ASAN();
  const auto c = fly(model::Formulation::reparametrized, 10, 10000);
  EXPECT_LT(c.energy, 1e-10);
  EXPECT_LT(c.p, 1e-10);
  EXPECT_LT(c.L, 1e-10);
  EXPECT_LT(c.phi, 1e-12);
  // The motion is not a rigid one: the elastic energy reaches a fifth of the total.
  EXPECT_GT(c.max_potential, 0.1 * c.energy_after_pulse);
}

// The other two formulations over 1000 free steps, and all three agree after 200 steps.
TEST(FreeFlyingBeam, AllFormulationsConserveAndAgree) {
  const auto r = fly(model::Formulation::reparametrized, 10, 190);
  for (auto f : {model::Formulation::constrained, model::Formulation::nullspace}) {
    const auto c = fly(f, 10, 1000);
    EXPECT_LT(c.energy, 1e-10) << model::to_string(f);
    EXPECT_LT(c.p, 1e-10) << model::to_string(f);
    EXPECT_LT(c.L, 1e-10) << model::to_string(f);
    EXPECT_LT((c.q_at_200 - r.q_at_200).lpNorm<Eigen::Infinity>(), 1e-8) << model::to_string(f);
  }
}
