// Follower loads (model `loads` with `frame: body`, loads/follower_body_load.hpp) through the
// System and every solver that uses loads: the load's part of the System's tangents (statics and
// the DAE schemes: static_force; the energy–momentum schemes: discrete_force at q_{n+½}) against
// central differences, for a body and for beam nodes; the energy–momentum Newton matrix against
// central differences in every formulation; the discrete energy balance E − E₀ = W_ext; a
// cantilever rolled into a full circle by a follower end moment (static); a spinning free body
// whose centre of mass a body-fixed force drives around a circle (dynamic, analytic).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <optional>
#include <random>
#include <string>

#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/integrate/time_integrator.hpp"
#include "isoflex/io/model_reader.hpp"
#include "support/finite_difference.hpp"
#include "support/statics.hpp"

using namespace isoflex;
using F = model::Formulation;
using integrate::EnergyMomentumIntegrator;
using integrate::ReducedSolve;

namespace {

constexpr double kPi = std::numbers::pi;
constexpr ReducedSolve kSolves[] = {ReducedSolve::automatic, ReducedSolve::explicit_null_space,
                                    ReducedSolve::bordered, ReducedSolve::tree,
                                    ReducedSolve::blocks};

// A body on a spherical joint at the origin, spinning, with a follower force at an offset point
// and a follower moment (components along d₁, d₂, d₃, varying in t).
const std::string kBody = R"yaml(
name: follower_body
solver: {dt: 0.01, t_end: 1}
bodies:
  - name: b
    mass: 2
    inertia: [1, 2, 2.5]
    position: [0.2, 0.1, 1]
    angular_velocity: [1, -2, 3]
joints:
  - {type: spherical, body_b: b, point: [0, 0, 0]}
loads:
  - body: b
    frame: body
    force: ["1+t", -2, 0.5]
    point_local: [0.3, 0.1, -0.2]
  - body: b
    frame: body
    moment: [0.2, "0.5*cos(t)", -1]
)yaml";

// A soft cantilever (L = 1 along +x, clamped at beam[0], 6 elements) with a follower moment at the
// tip and a follower force at an offset point of beam[3], the tip also under a dead force.
const std::string kBeam = R"yaml(
name: follower_beam
solver: {dt: 0.01, t_end: 1}
beams:
  - name: beam
    points: [[0, 0, 0], [1, 0, 0]]
    elements: 6
    d1: [0, 1, 0]
    section: {EA: 1000, GA: 500, EI1: 1, EI2: 2, GJ: 1.5, A_rho: 1, M_rho1: 0.01, M_rho2: 0.02}
joints:
  - {type: fixed, body_b: "beam[0]"}
loads:
  - body: "beam[6]"
    frame: body
    moment: ["-2*t", 0.3, "0.5*t"]
  - body: "beam[3]"
    frame: body
    force: [0.5, "-t", 0.2]
    point_local: [0.05, 0.02, 0]
  - body: "beam[6]"
    force: [0, 0.2, 0]
)yaml";

model::Model read(const std::string& yaml, F f = F::reparametrized) {
  auto m = io::read_model_string(yaml, "m.yaml");
  m.solver.formulation = f;
  return m;
}

// The model without its loads: its tangents are the elements' and joints' alone.
model::Model without_loads(model::Model m) {
  m.loads.clear();
  return m;
}

// −∂f_ext/∂q from the System (static_force's K with loads minus without) against central
// differences of external_force at a configuration off q₀; the same for discrete_force's
// ∂/∂qₙ₊₁ (−½ ∂f_ext/∂q at q_{n+½}). Returns the larger relative error.
double load_tangent_error(const model::Model& m) {
  const auto sys = system::System::compile(m);
  const auto bare = system::System::compile(without_loads(m));
  std::mt19937 g(5);
  const VecX q = sys.q0() + test::random_vector(g, sys.n(), 0.1);
  const VecX qn1 = q + test::random_vector(g, sys.n(), 0.05);
  const double t = 0.6;
  system::SpMat K, K0;
  sys.static_force(q, t, &K);
  bare.static_force(q, t, &K0);
  const MatX fd =
      test::central_jacobian([&](const VecX& x) { return sys.external_force(x, t); }, q);
  EXPECT_GT(fd.norm(), 0.1);
  const double statics = test::rel_diff(MatX(K) - MatX(K0), -fd);
  sys.discrete_force(q, qn1, t, &K);
  bare.discrete_force(q, qn1, t, &K0);
  const MatX fd_mid = test::central_jacobian(
      [&](const VecX& x) { return sys.external_force(0.5 * (q + x), t); }, qn1);
  const double dynamics = test::rel_diff(MatX(K) - MatX(K0), -fd_mid);
  return std::max(statics, dynamics);
}

}  // namespace

// The loads are quadratic in q: the differences are exact but for round-off (measured: relative
// errors 2.1e-11 body, 1.7e-11 beam).
TEST(FollowerLoads, SystemTangentsOfABodyAndOfBeamNodesMatchFiniteDifferences) {
  const double body = load_tangent_error(read(kBody));
  const double beam = load_tangent_error(read(kBeam));
  EXPECT_LT(body, 1e-9);
  EXPECT_LT(beam, 1e-9);
}

// The Newton matrix of a step equals the central-difference Jacobian of its residual at the
// converged step (after 3 steps: moving, the loads turned), in every formulation and every
// assembly of the reparametrized scheme that applies (the follower loads' tangent enters each:
// System::discrete_force, ReducedNewtonMatrix's blocks). Measured: relative errors 3.8e-12 …
// 7.9e-12.
TEST(FollowerLoads, EnergyMomentumNewtonMatrixMatchesFiniteDifferences) {
  for (const std::string* yaml : {&kBody, &kBeam}) {
    for (F f : {F::constrained, F::nullspace, F::reparametrized}) {
      for (ReducedSolve how : kSolves) {
        if (f != F::reparametrized && how != ReducedSolve::automatic) continue;
        const auto m = read(*yaml, f);
        const auto sys = system::System::compile(m);
        std::unique_ptr<EnergyMomentumIntegrator> integ;
        try {
          integ = std::make_unique<EnergyMomentumIntegrator>(sys, m.solver, how);
        } catch (const std::invalid_argument&) {
          continue;  // a path that does not apply to this model
        }
        auto s0 = integ->initial_state();
        for (int i = 0; i < 3; ++i) integ->step(s0);
        VecX x = integ->start_unknowns(s0);
        MatX J;
        for (int it = 0; it < 30; ++it) {
          const VecX R = integ->residual(s0, x, &J);
          if (R.lpNorm<Eigen::Infinity>() < 1e-12) break;
          x -= J.fullPivLu().solve(R);
        }
        const VecX R = integ->residual(s0, x, &J);
        EXPECT_LT(R.lpNorm<Eigen::Infinity>(), 1e-9);
        const MatX Jfd = test::central_jacobian(
            [&](const VecX& y) -> VecX { return integ->residual(s0, y, nullptr); }, x);
        const double e = test::rel_diff(J, Jfd);
        EXPECT_LT(e, 1e-7) << m.name << " " << model::to_string(f) << " " << static_cast<int>(how);
      }
    }
  }
}

// Every formulation and every linear solve of the reparametrized scheme (the tree recursion and
// the block assembly included) takes the follower loads' tangent: after 20 steps they agree with
// the explicit null-space solve of the reparametrized scheme (measured: to 3e-15).
TEST(FollowerLoads, FormulationsAndSolvePathsAgree) {
  for (const std::string* yaml : {&kBody, &kBeam}) {
    auto run = [&](F f, ReducedSolve how) -> std::optional<VecX> {
      const auto m = read(*yaml, f);
      const auto sys = system::System::compile(m);
      std::unique_ptr<EnergyMomentumIntegrator> integ;
      try {
        integ = std::make_unique<EnergyMomentumIntegrator>(sys, m.solver, how);
      } catch (const std::invalid_argument&) {
        return std::nullopt;
      }
      auto s = integ->initial_state();
      for (int i = 0; i < 20; ++i) integ->step(s);
      return s.q;
    };
    const VecX ref = *run(F::reparametrized, ReducedSolve::explicit_null_space);
    for (F f : {F::constrained, F::nullspace, F::reparametrized})
      for (ReducedSolve how : kSolves) {
        if (f != F::reparametrized && how != ReducedSolve::automatic) continue;
        const auto q = run(f, how);
        if (!q) continue;
        const double d = (*q - ref).lpNorm<Eigen::Infinity>();
        EXPECT_LT(d, 1e-8) << (yaml == &kBody ? "body " : "beam ") << model::to_string(f) << " "
                           << static_cast<int>(how);
      }
  }
}

// A follower load is not conservative: the energy changes, by the work the load does. The
// energy–momentum schemes keep the discrete balance E_n − E₀ = W_n = Σ f_ext(q_{n+½})·Δq exactly
// (to round-off and the Newton tolerance), in every formulation (measured over 50 steps:
// |E − E₀ − W| ≤ 3.8e-14 of the energy scale, while W reaches 0.23 of it (body) and 1.4 (beam)).
TEST(FollowerLoads, EnergyChangesByTheWorkOfTheLoads) {
  for (const std::string* yaml : {&kBody, &kBeam}) {
    for (F f : {F::constrained, F::nullspace, F::reparametrized}) {
      const auto m = read(*yaml, f);
      const auto sys = system::System::compile(m);
      const EnergyMomentumIntegrator integ(sys, m.solver);
      auto s = integ.initial_state();
      const auto a = integ.snapshot(s, {}, {});
      double balance = 0.0, scale = std::abs(a.total_energy), work = 0.0;
      for (int i = 0; i < 50; ++i) {
        const auto st = integ.step(s);
        const auto b = integ.snapshot(s, st, {});
        scale = std::max({scale, b.kinetic_energy, std::abs(b.potential_energy)});
        balance = std::max(balance, std::abs(b.total_energy - a.total_energy - b.external_work));
        work = std::max(work, std::abs(b.external_work));
      }
      EXPECT_GT(work, 1e-3 * scale) << m.name << ": the loads do work";
      EXPECT_LT(balance, 1e-10 * scale) << m.name << " " << model::to_string(f);
    }
  }
}

namespace {

// The cantilever of examples/beam_roll_up (L = 12 along +x, d₁ = +y, EI₁ = 100, N elements)
// under a follower end moment −M t about d₁ (or the same moment with global components, about
// −y), solved statically at t = 0.05, 0.10, …, 1.
model::Model roll_up(int N, double M, const std::string& frame) {
  const std::string moment = frame == "body" ? fmt::format("[\"{:.17g}*t\", 0, 0]", -M)
                                             : fmt::format("[0, \"{:.17g}*t\", 0]", -M);
  return io::read_model_string(fmt::format(R"yaml(
solver: {{analysis: static, dt: 0.05, t_end: 1}}
beams:
  - name: beam
    points: [[0, 0, 0], [12, 0, 0]]
    elements: {0}
    d1: [0, 1, 0]
    section: {{EA: 1.2e5, GA: 6.0e4, EI1: 100, EI2: 1.0e4, GJ: 187.4, A_rho: 0.1,
               M_rho1: 8.333333333333333e-3, M_rho2: 8.333333333333333e-5}}
joints:
  - {{type: fixed, body_b: "beam[0]"}}
loads:
  - {{body: "beam[{0}]", frame: {1}, moment: {2}}}
)yaml",
                                           N, frame, moment),
                               "roll_up.yaml");
}

}  // namespace

// M = 2π EI/L rolls the cantilever into a full circle of radius R = EI/M = L/(2π): the tip returns
// to the root. At every load step t the nodes lie on the arc of angle θ = 2π t (node at arc length
// s: x = ρ sin(s/ρ), z = ρ (1 − cos(s/ρ)), ρ = L/θ, IGA-thesis (6.14)). The linear elements' error
// is second order, |error|/L = C (θ/N)² with C ≈ 0.7 at 360° (tests/examples/
// test_beam_examples.cpp, TipConvergesToTheExactArcAtSecondOrder): the test asserts the bound
// (θ/N)² at every node and step, with N = 64 ((2π/64)² L = 0.116). In the plane the follower
// moment about d₁ and the dead moment about −y are the same load (d₁ stays +y), so both runs reach
// the same equilibria, up to the Newton tolerance. Measured: tip 0.078 from the root (bound 0.116),
// largest node error 0.0065 L at t = 1 (bound 0.0096 L), follower and dead runs 1.5e-14 apart.
TEST(FollowerLoads, CantileverUnderAFollowerEndMomentClosesIntoACircle) {
  const int N = 64;
  const double L = 12.0, EI = 100.0, M = 2.0 * kPi * EI / L;
  const auto m = roll_up(N, M, "body");
  const auto sys = system::System::compile(m);
  EXPECT_TRUE(sys.loads().front()->follower());
  const test::StaticRun run = test::solve_static(sys, m);
  ASSERT_EQ(run.failure, "");
  ASSERT_EQ(run.steps.size(), 20u);
  const auto dead_m = roll_up(N, M, "global");
  const auto dead_sys = system::System::compile(dead_m);
  const test::StaticRun dead = test::solve_static(dead_sys, dead_m);
  ASSERT_EQ(dead.failure, "");
  ASSERT_EQ(dead.steps.size(), 20u);
  double off_plane = 0.0, to_dead = 0.0;
  for (std::size_t k = 0; k < run.steps.size(); ++k) {
    const auto& st = run.steps[k];
    const double theta = 2.0 * kPi * st.t, rho = L / theta;
    double step_error = 0.0;
    for (int a = 0; a <= N; ++a) {
      const int o = sys.q_offset(sys.beams().front().nodes[static_cast<std::size_t>(a)]);
      const Vec3 x = st.q.segment<3>(o);
      const double s = L * a / N;
      const Vec3 exact(rho * std::sin(s / rho), 0.0, rho * (1.0 - std::cos(s / rho)));
      step_error = std::max(step_error, (x - exact).norm() / L);
      off_plane =
          std::max(off_plane, std::abs(x.y()) + (st.q.segment<3>(o + 3) - Vec3::UnitY()).norm());
    }
    EXPECT_LT(step_error, (theta / N) * (theta / N)) << "t = " << st.t;
    to_dead = std::max(to_dead, (st.q - dead.steps[k].q).lpNorm<Eigen::Infinity>());
  }
  const double tip_to_root =
      sys.material_point(run.steps.back().q, sys.beams().front().nodes.back(), Vec3::Zero()).norm();
  EXPECT_LT(tip_to_root, (2 * kPi / N) * (2 * kPi / N) * L);
  EXPECT_LT(off_plane, 1e-10);
  EXPECT_LT(to_dead, 1e-8);
}

namespace {

// A free body (m = 2, principal inertia (1, 2, 3)) spinning at ω = 2 about its principal axis
// d₃ = z, with a force F = 3 along d₁ at its centre of mass. The rotation is torque-free and
// steady, d₁(t) = (cos ωt, sin ωt, 0), and the centre of mass with x(0) = (−R, 0, 0),
// ẋ(0) = (0, −F/(mω), 0) runs around the circle x(t) = −R (cos ωt, sin ωt, 0) of radius
// R = F/(m ω²) = 0.375 (m ẍ = F d₁(t)); the force stays normal to the velocity, so the kinetic
// energy is constant while the momentum turns. `error`: the largest |x − x_exact| over one period
// T = π in `steps` steps.
//
// The energy–momentum step turns the body by α per step with tan(α/2) = ω Δt/2 (the directors'
// midpoint rule) and applies F along the mean director d₁_{n+½}, of length cos(α/2); with these,
// xₙ = −R (cos nα, sin nα, 0), vₙ = (F/(mω)) (sin nα, −cos nα, 0) solve its balance
// m (vₙ₊₁ − vₙ) = Δt F d₁_{n+½}, xₙ₊₁ − xₙ = ½ Δt (vₙ + vₙ₊₁) exactly, from the same start:
// `discrete` is the largest distance from that orbit.
struct Orbit {
  double error = 0.0, discrete = 0.0;
};
Orbit spinning_body(int steps, model::Integrator integrator) {
  const double m = 2.0, w = 2.0, Fd = 3.0, R = Fd / (m * w * w);
  auto model = io::read_model_string(fmt::format(R"yaml(
solver: {{dt: {0:.17g}, t_end: {1:.17g}}}
bodies:
  - name: b
    mass: 2
    inertia: [1, 2, 3]
    position: [{2:.17g}, 0, 0]
    velocity: [0, {3:.17g}, 0]
    angular_velocity: [0, 0, 2]
loads:
  - {{body: b, frame: body, force: [3, 0, 0]}}
)yaml",
                                                 kPi / steps, kPi, -R, -Fd / (m * w)),
                                     "spin.yaml");
  model.solver.integrator = integrator;
  const auto sys = system::System::compile(model);
  const auto integ = integrate::make_time_integrator(sys, model.solver);
  auto s = integ->initial_state();
  Orbit o;
  for (int i = 1; i <= steps; ++i) {
    integ->step(s);
    const double t = i * kPi / steps;
    const Vec3 x = s.q.head<3>();
    o.error = std::max(o.error, (x + R * Vec3(std::cos(w * t), std::sin(w * t), 0.0)).norm());
    const double alpha = 2.0 * std::atan(0.5 * w * kPi / steps);
    o.discrete =
        std::max(o.discrete, (x + R * Vec3(std::cos(i * alpha), std::sin(i * alpha), 0.0)).norm());
  }
  return o;
}

}  // namespace

// The follower force drives the centre of mass around the circle, to second order in Δt in the
// energy–momentum scheme and in generalized-α (measured: errors 1.9e-4 → 4.8e-5 and
// 2.4e-4 → 5.9e-5 from 200 to 400 steps, orders 2.000 and 2.001); the energy–momentum orbit is
// the discrete circle above to round-off (measured 6.8e-14).
TEST(FollowerLoads, BodyFixedForceDrivesASpinningBodyAroundACircle) {
  for (auto integrator :
       {model::Integrator::energy_momentum, model::Integrator::generalized_alpha}) {
    const Orbit a = spinning_body(200, integrator), b = spinning_body(400, integrator);
    EXPECT_LT(a.error, 1e-3 * 0.375);
    EXPECT_NEAR(std::log2(a.error / b.error), 2.0, 0.15) << model::to_string(integrator);
    if (integrator == model::Integrator::energy_momentum) {
      EXPECT_LT(a.discrete, 1e-12);
      EXPECT_LT(b.discrete, 1e-12);
    }
  }
}
