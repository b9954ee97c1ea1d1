// The index-3 DAE schemes on System (integrate/dae_integrator.hpp): the Chung–Hulbert parameters;
// the consistent start (q̈₀ is the acceleration of the motion, taken from a fine energy–momentum
// run); the constraints — joints and the directors' orthonormality — held at every time node;
// the observed orders against a fine reference, in positions and, for generalized-α, in the
// multipliers (no order reduction, Arnold & Brüls); the scaled and the unscaled iteration give
// the same motion while the scaled matrix is far better conditioned at small h; linear momentum
// conserved exactly by generalized-α on a free body (M q̈ sums to zero at every node).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "isoflex/integrate/dae_integrator.hpp"
#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/io/model_reader.hpp"
#include "isoflex/solve/linear_solver.hpp"
#include "support/examples.hpp"
#include "support/models.hpp"
#include "support/sanitizers.hpp"

using namespace isoflex;
using integrate::DaeIntegrator;
using I = model::Integrator;

namespace {

// The heavy top, slowed down (as in the energy–momentum order test), with the given scheme.
model::Model top(I scheme, double dt, double rho = 0.8) {
  auto m = test::heavy_top();
  m.bodies[0].angular_velocity /= 10.0;
  m.solver.integrator = scheme;
  m.solver.rho_infinity = rho;
  m.solver.dt = dt;
  return m;
}

// The state after `steps` steps.
integrate::State run(const model::Model& m, int steps) {
  const auto sys = system::System::compile(m);
  const DaeIntegrator dae(sys, m.solver);
  auto s = dae.initial_state();
  for (int i = 0; i < steps; ++i) dae.step(s);
  return s;
}

struct Orders {
  std::vector<double> q, lambda;
};

// log₂ of the ratios of successive errors in q and in λ at T for steps T/k, T/2k, T/4k, against
// the run with steps T/(64k); `model(dt)` gives the model.
template <class Model>
Orders orders_in_q_and_lambda(Model&& model, double T, int k) {
  const auto at = [&](int steps) { return run(model(T / steps), steps); };
  const integrate::State ref = at(64 * k);
  std::vector<integrate::State> s;
  for (int j = 0; j < 3; ++j) s.push_back(at(k << j));
  Orders out;
  for (int j = 0; j + 1 < 3; ++j) {
    out.q.push_back(std::log2((s[j].q - ref.q).norm() / (s[j + 1].q - ref.q).norm()));
    out.lambda.push_back(
        std::log2((s[j].lambda - ref.lambda).norm() / (s[j + 1].lambda - ref.lambda).norm()));
  }
  return out;
}

template <class Model>
std::vector<double> orders_of(Model&& model, double T, int k, bool multipliers) {
  Orders o = orders_in_q_and_lambda(model, T, k);
  return multipliers ? o.lambda : o.q;
}

std::vector<double> orders(I scheme, double T, int k, double rho, bool multipliers) {
  return orders_of([&](double dt) { return top(scheme, dt, rho); }, T, k, multipliers);
}

// A coarse, soft Kirchhoff–Love plate (2 × 1 bicubic elements) under a pulse whose modes the steps
// resolve (as in KLFreePlate.SecondOrderInTheStep: the example's own membrane modes are not
// resolved at its steps, and its order is not observable there).
model::Model kl_plate(I scheme, double dt) {
  auto m = io::read_model_string(R"yaml(
solver: {t_end: 0.5}
surfaces:
  - {name: sheet, builtin: {type: rectangle, size: [1, 0.5]}, refine: {elevate: [2, 2]}}
kl_shells:
  - {name: plate, surface: sheet, material: {E: 1.0e4, nu: 0.3, thickness: 0.05, density: 1000}}
kl_loads:
  - {shell: plate, edge: u1, force_per_length: [0, 0, "40*sin(5*pi*t)^2*(t<=0.2)"]}
  - {shell: plate, area_force: [0, "10*sin(5*pi*t)^2*(t<=0.2)", 0]}
)yaml",
                                 "plate.yaml");
  m.solver.integrator = scheme;
  m.solver.dt = dt;
  return m;
}

// The flexible slider-crank of DNSM-III §5.2 (examples/slider_crank_flexible: beams, rigid
// pyramids, spherical, rigid and point-on-line joints) with the scheme, from rest under its drive;
// coarse (4 and 3 elements) and soft (EA = GA = 10⁴) so that the steps resolve its modes (the
// example's beams have axial modes near 1700 rad/s, which steps of 10⁻² cannot resolve).
model::Model slider_crank(I scheme, double dt) {
  std::string text = test::example_text("slider_crank_flexible", "model.yaml");
  for (const auto& [from, to] : std::vector<std::pair<std::string, std::string>>{
           {"elements: 20", "elements: 4"},
           {"elements: 15", "elements: 3"},
           {"crank[10]", "crank[2]"},
           {"crank[20]", "crank[4]"},
           {"slider[15]", "slider[3]"},
           {"EA: 1.0e5, GA: 1.0e5", "EA: 1.0e4, GA: 1.0e4"},
           {"EA: 1.0e6, GA: 1.0e6", "EA: 1.0e4, GA: 1.0e4"}})
    text = test::replaced_all(text, from, to);
  auto m = io::read_model_string(text, "model.yaml");
  m.solver.integrator = scheme;
  m.solver.dt = dt;
  return m;
}

// The same plate clamped at x = 0 (kl_supports, rows on the first two rows of control points): the
// multipliers carry the plate's bending.
model::Model clamped_kl_plate(I scheme, double dt) {
  auto m = kl_plate(scheme, dt);
  m.kl_supports = io::read_model_string(R"yaml(
surfaces:
  - {name: sheet, builtin: {type: rectangle, size: [1, 0.5]}, refine: {elevate: [2, 2]}}
kl_shells:
  - {name: plate, surface: sheet, material: {E: 1.0e4, nu: 0.3, thickness: 0.05, density: 1000}}
kl_supports:
  - {shell: plate, edge: u0, clamped: all}
)yaml",
                                        "clamp.yaml")
                      .kl_supports;
  return m;
}

// The four-bar (loop-closing rows) with the scheme.
model::Model four_bar(I scheme, double dt) {
  auto m = test::four_bar();
  m.solver.integrator = scheme;
  m.solver.dt = dt;
  return m;
}

}  // namespace

TEST(DaeIntegrator, ChungHulbertParameters) {
  const auto one = DaeIntegrator::alpha_parameters(1.0);  // the trapezoidal rule
  EXPECT_DOUBLE_EQ(one.alpha_m, 0.5);
  EXPECT_DOUBLE_EQ(one.alpha_f, 0.5);
  EXPECT_DOUBLE_EQ(one.gamma, 0.5);
  EXPECT_DOUBLE_EQ(one.beta, 0.25);
  const auto zero = DaeIntegrator::alpha_parameters(0.0);  // asymptotic annihilation
  EXPECT_DOUBLE_EQ(zero.alpha_m, -1.0);
  EXPECT_DOUBLE_EQ(zero.alpha_f, 0.0);
  EXPECT_DOUBLE_EQ(zero.gamma, 1.5);
  EXPECT_DOUBLE_EQ(zero.beta, 1.0);
  EXPECT_THROW(DaeIntegrator::alpha_parameters(1.5), std::invalid_argument);
  EXPECT_THROW(DaeIntegrator::alpha_parameters(-0.1), std::invalid_argument);
}

// q̈₀ from [M Gᵀ; G 0] is the acceleration of the motion: the second difference of a fine
// energy–momentum trajectory at t = h, (q₂ − 2q₁ + q₀)/h² = q̈(h) + O(h²) = q̈₀ + O(h).
TEST(DaeIntegrator, ConsistentStartIsTheAccelerationOfTheMotion) {
  auto m = top(I::generalized_alpha, 1e-4);
  const auto sys = system::System::compile(m);
  const integrate::State s0 = DaeIntegrator(sys, m.solver).initial_state();
  m.solver.integrator = I::energy_momentum;
  m.solver.formulation = model::Formulation::constrained;
  const integrate::EnergyMomentumIntegrator em(sys, m.solver);
  auto s = em.initial_state();
  const VecX q0 = s.q;
  em.step(s);
  const VecX q1 = s.q;
  em.step(s);
  const VecX fd = (s.q - 2.0 * q1 + q0) / (1e-4 * 1e-4);
  std::printf("  [dae] |q̈₀| %.4g, |q̈₀ − second difference| %.3g\n", s0.a.norm(),
              (s0.a - fd).norm());
  EXPECT_GT(s0.a.norm(), 1.0);
  EXPECT_LT((s0.a - fd).norm(), 1e-2 * s0.a.norm());
}

TEST(DaeIntegrator, EveryRowHoldsAtEveryTimeNode) {
  for (const I scheme : {I::generalized_alpha, I::bdf1, I::bdf2}) {
    const auto m = top(scheme, 0.01);
    const auto sys = system::System::compile(m);
    const DaeIntegrator dae(sys, m.solver);
    auto s = dae.initial_state();
    double phi = 0.0;
    for (int i = 0; i < 100; ++i) {
      dae.step(s);
      phi = std::max(phi, sys.constraints(s.q, s.t).lpNorm<Eigen::Infinity>());
    }
    std::printf("  [dae] %s: max |Phi| over 100 steps %.2e\n", model::to_string(scheme), phi);
    EXPECT_LT(phi, 1e-13) << model::to_string(scheme);
  }
}

TEST(DaeIntegrator, ObservedOrders) {
  struct Case {
    I scheme;
    double order;
  };
  for (const Case c : {Case{I::generalized_alpha, 2.0}, Case{I::bdf2, 2.0}, Case{I::bdf1, 1.0}}) {
    const auto [q, lambda] =
        orders_in_q_and_lambda([&](double dt) { return top(c.scheme, dt); }, 0.4, 40);
    std::printf("  [dae] %s: orders in q %.3f %.3f, in lambda %.3f %.3f\n",
                model::to_string(c.scheme), q[0], q[1], lambda[0], lambda[1]);
    for (const double o : {q[0], q[1], lambda[0], lambda[1]})
      EXPECT_NEAR(o, c.order, 0.15) << model::to_string(c.scheme);
  }
}

// Index 3: the rows hold on the positions, not on the velocities. G(qₙ) vₙ — for a frame node the
// rate of its directors' orthonormality — is not zero but falls with h² (generalized-α).
TEST(DaeIntegrator, VelocitiesAreTangentOnlyToSecondOrder) {
  std::vector<double> gv;
  for (const double dt : {0.01, 0.005, 0.0025}) {
    const auto m = top(I::generalized_alpha, dt);
    const auto sys = system::System::compile(m);
    const DaeIntegrator dae(sys, m.solver);
    auto s = dae.initial_state();
    double worst = 0.0;
    const int steps = static_cast<int>(std::lround(0.4 / dt));
    for (int i = 0; i < steps; ++i) {
      dae.step(s);
      worst = std::max(worst, (sys.jacobian(s.q) * s.v).lpNorm<Eigen::Infinity>());
    }
    gv.push_back(worst);
  }
  std::printf("  [dae] max |G v| over t <= 0.4: %.3e %.3e %.3e\n", gv[0], gv[1], gv[2]);
  EXPECT_GT(gv[2], 1e-10);  // not imposed
  EXPECT_NEAR(std::log2(gv[0] / gv[1]), 2.0, 0.3);
  EXPECT_NEAR(std::log2(gv[1] / gv[2]), 2.0, 0.3);
}

// BDF-2 on a grid whose steps alternate between h and h/2 (as after subdivisions): the
// variable-grid coefficients keep second order.
TEST(DaeIntegrator, Bdf2IsSecondOrderOnAVariableGrid) {
  auto at = [](int pairs) {  // `pairs` times a step h and a step h/2 to t = 0.4
    const double h = 0.4 / (1.5 * pairs);
    auto m = top(I::bdf2, h);
    const auto sys = system::System::compile(m);
    const DaeIntegrator long_step(sys, m.solver);
    m.solver.dt = 0.5 * h;
    const DaeIntegrator short_step(sys, m.solver);
    auto s = long_step.initial_state();
    for (int i = 0; i < 2 * pairs; ++i) (i % 2 ? short_step : long_step).step(s);
    EXPECT_NEAR(s.t, 0.4, 1e-12);
    return s.q;
  };
  const VecX ref = run(top(I::bdf2, 0.4 / 2560), 2560).q;
  const double e1 = (at(10) - ref).norm(), e2 = (at(20) - ref).norm(), e3 = (at(40) - ref).norm();
  std::printf("  [dae] bdf2 on a variable grid: orders %.3f %.3f\n", std::log2(e1 / e2),
              std::log2(e2 / e3));
  EXPECT_NEAR(std::log2(e1 / e2), 2.0, 0.15);
  EXPECT_NEAR(std::log2(e2 / e3), 2.0, 0.15);
}

// Arnold & Brüls: generalized-α keeps second order in the multipliers of the index-3 system.
TEST(DaeIntegrator, GeneralizedAlphaSecondOrderInTheMultipliers) {
  for (const double rho : {0.5, 0.8}) {
    const auto p = orders(I::generalized_alpha, 0.4, 40, rho, true);
    std::printf("  [dae] generalized_alpha rho %.1f: orders in lambda %.3f %.3f\n", rho, p[0],
                p[1]);
    for (const double o : p) EXPECT_NEAR(o, 2.0, 0.15);
  }
}

// Scaling changes the equations' rows and the multipliers' unit, not the motion; at small h it
// makes S_t far better conditioned (IGA-thesis §2.2.4).
TEST(DaeIntegrator, ScalingKeepsTheMotionAndHelpsTheCondition) {
  auto scaled = top(I::generalized_alpha, 1e-3);
  auto plain = scaled;
  plain.solver.scaling = false;
  const integrate::State a = run(scaled, 50), b = run(plain, 50);
  EXPECT_LT((a.q - b.q).lpNorm<Eigen::Infinity>(), 1e-12);
  EXPECT_LT((a.lambda - b.lambda).lpNorm<Eigen::Infinity>(), 1e-8 * a.lambda.norm());
  // h⁻² growth without scaling: h = 1e-2 → 1e-3 multiplies the condition number by ~100.
  std::vector<double> with, without;
  for (const double h : {1e-2, 1e-3}) {
    for (auto* m : {&scaled, &plain}) {
      m->solver.dt = h;
      const auto sys = system::System::compile(*m);
      const DaeIntegrator dae(sys, m->solver);
      (m == &scaled ? with : without)
          .push_back(solve::condition_number(MatX(dae.iteration_matrix(dae.initial_state()))));
    }
    std::printf("  [dae] cond(S_t) at h = %g: scaled %.3g, unscaled %.3g\n", h, with.back(),
                without.back());
  }
  EXPECT_LT(with[1], 2.0 * with[0]);         // scaled: independent of h
  EXPECT_GT(without[1], 50.0 * without[0]);  // unscaled: grows at least like h⁻²
  EXPECT_LT(1e3 * with[1], without[1]);
}

// Σ (M q̈)_φ = 0 at every node of a load-free run, so the auxiliary accelerations and the
// velocity updates keep the linear momentum exactly; the angular momentum is not conserved.
TEST(DaeIntegrator, GeneralizedAlphaConservesLinearMomentumOfAFreeBody) {
  auto m = test::free_body_flip();
  m.solver.integrator = I::generalized_alpha;
  const auto sys = system::System::compile(m);
  const DaeIntegrator dae(sys, m.solver);
  auto s = dae.initial_state();
  const Vec3 p0 = sys.linear_momentum(s.v);
  double dp = 0.0;
  for (int i = 0; i < 200; ++i) {
    dae.step(s);
    dp = std::max(dp, (sys.linear_momentum(s.v) - p0).norm());
  }
  std::printf("  [dae] free body: |p − p₀| ≤ %.2e (|p₀| = %.3g)\n", dp, p0.norm());
  EXPECT_LT(dp, 1e-12 * std::max(1.0, p0.norm()));
}

// The orders hold on a Kirchhoff–Love patch (point nodes) and on a closed loop of bodies too.
TEST(DaeIntegrator, ObservedOrdersOnAKirchhoffLovePlateAndTheFourBar) {
  ISOFLEX_SKIP_LONG_RUN_UNDER_ASAN();
  for (const I scheme : {I::generalized_alpha, I::bdf2, I::bdf1}) {
    const double order = scheme == I::bdf1 ? 1.0 : 2.0;
    const auto plate = orders_of([&](double dt) { return kl_plate(scheme, dt); }, 0.5, 100, false);
    const auto bar = orders_of([&](double dt) { return four_bar(scheme, dt); }, 0.5, 20, false);
    std::printf("  [dae] %s: orders in q, KL plate %.3f %.3f, four-bar %.3f %.3f\n",
                model::to_string(scheme), plate[0], plate[1], bar[0], bar[1]);
    // The plate's first ratio is not yet asymptotic for BDF-2 (measured 1.74, then 1.90).
    for (const double o : {plate[1], bar[0], bar[1]})
      EXPECT_NEAR(o, order, 0.15) << model::to_string(scheme);
  }
}

// The DNSM-III slider-crank: every joint kind of the example and the beams' director rows. Orders
// in the positions and in all multipliers (joints and the nodes' internal rows): second for
// generalized-α (no order reduction in λ, Arnold & Brüls) and BDF-2, first for BDF-1.
TEST(DaeIntegrator, ObservedOrdersOnTheSliderCrankInPositionsAndMultipliers) {
  ISOFLEX_SKIP_LONG_RUN_UNDER_ASAN();
  for (const I scheme : {I::generalized_alpha, I::bdf2, I::bdf1}) {
    const double order = scheme == I::bdf1 ? 1.0 : 2.0;
    const auto [q, lambda] =
        orders_in_q_and_lambda([&](double dt) { return slider_crank(scheme, dt); }, 0.2, 20);
    std::printf("  [dae] %s: slider-crank orders in q %.3f %.3f, in lambda %.3f %.3f\n",
                model::to_string(scheme), q[0], q[1], lambda[0], lambda[1]);
    // The first ratios are not yet asymptotic for BDF-2 (measured 1.82 in q, 1.74 in λ).
    for (const double o : {q[0], lambda[0]}) EXPECT_NEAR(o, order, 0.3) << model::to_string(scheme);
    for (const double o : {q[1], lambda[1]})
      EXPECT_NEAR(o, order, 0.15) << model::to_string(scheme);
  }
}

// A clamped Kirchhoff–Love plate: the orders in q and in the clamp's multipliers.
TEST(DaeIntegrator, ObservedOrdersOnAClampedKirchhoffLovePlateInPositionsAndMultipliers) {
  ISOFLEX_SKIP_LONG_RUN_UNDER_ASAN();
  for (const I scheme : {I::generalized_alpha, I::bdf2, I::bdf1}) {
    const double order = scheme == I::bdf1 ? 1.0 : 2.0;
    const auto [q, lambda] =
        orders_in_q_and_lambda([&](double dt) { return clamped_kl_plate(scheme, dt); }, 0.5, 100);
    std::printf("  [dae] %s: clamped KL plate orders in q %.3f %.3f, in lambda %.3f %.3f\n",
                model::to_string(scheme), q[0], q[1], lambda[0], lambda[1]);
    for (const double o : {q[0], q[1], lambda[0], lambda[1]})
      EXPECT_NEAR(o, order, 0.15) << model::to_string(scheme);
  }
}
