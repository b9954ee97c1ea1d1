// Joint drivers (joints `driver`, system/joint_drivers.hpp): a joint coordinate or a body point
// prescribed as a time function, a rheonomic row Φ(q) = d(t) held at every time node t_{n+1} of
// the three energy–momentum formulations (DNSM-III (9), (11), (14) with the loop-closing rows
// kept by (12)–(13)) and of the DAE schemes. Checked:
//   (a) a crank driven about a fixed axis, θ(t) = ω t + a (1 − cos t) over more than one turn,
//       follows θ(tₙ) at every node to round-off, in each formulation;
//   (b) its driving torque (reactions: −λ of the driver row) matches J θ̈ + the gravity moment,
//       with an error O(Δt²) (measured at two steps);
//   (c) the three formulations give the same trajectory;
//   (d) a prismatic driver moves the body by s(tₙ) exactly; a point driver moves the body's point
//       along p(tₙ) exactly, and its force closes the discrete momentum balance exactly;
//   (e) E(t) − W_driver(t) stays constant to round-off (history.csv driver_work);
//   (f) the driver rows' Jacobian and Hessian equal central differences, and the discrete
//       derivative is exact for increments;
//   (g) located errors of the reader and the compiler;
//   the initial velocities follow ḟ(0), and the DAE schemes hold the rows at their nodes too.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/integrate/time_integrator.hpp"
#include "isoflex/io/model_reader.hpp"
#include "isoflex/math/frame_node.hpp"
#include "isoflex/system/compile_error.hpp"
#include "isoflex/system/joint_drivers.hpp"
#include "isoflex/system/joint_reactions.hpp"
#include "isoflex/system/system.hpp"
#include "support/cli.hpp"
#include "support/files.hpp"
#include "support/finite_difference.hpp"
#include "support/model_errors.hpp"
#include "support/models.hpp"

using namespace isoflex;
using F = model::Formulation;

namespace {

// The crank: a rod of mass 1 and length 1 from the origin along x (centre of mass at 0.5), on a
// revolute joint to the ground about z at the origin, driven by θ(t) = 2 t + 0.5 (1 − cos t);
// gravity −9.81 along y. J_O = 1/12 + 1/4 = 1/3; the driving torque on the crank about z is
// τ = J_O θ̈ + ½ m g cos θ.
constexpr double kOmega = 2.0, kA = 0.5, kG = 9.81, kJ = 1.0 / 3.0;
double theta(double t) {
  return kOmega * t + kA * (1.0 - std::cos(t));
}
double theta_ddot(double t) {
  return kA * std::cos(t);
}
double torque(double t) {
  return kJ * theta_ddot(t) + 0.5 * kG * std::cos(theta(t));
}

std::string crank_yaml(double dt, double t_end,
                       const std::string& driver = "2*t + 0.5*(1 - cos(t))",
                       const std::string& integrator = "energy_momentum") {
  return "solver: {dt: " + std::to_string(dt) + ", t_end: " + std::to_string(t_end) +
         ", integrator: " + integrator +
         ", residual_tolerance: 1e-12}\n"
         "gravity: [0, -9.81, 0]\n"
         "bodies:\n"
         "  - {name: crank, mass: 1, inertia: [0.001, 0.08333333333333333, "
         "0.08333333333333333], position: [0.5, 0, 0]}\n"
         "joints:\n"
         "  - {name: motor, type: revolute, body_a: ground, body_b: crank, point: [0, 0, 0],\n"
         "     axis: [0, 0, 1], driver: \"" +
         driver + "\"}\n";
}

model::Model crank(double dt, double t_end, F f) {
  model::Model m = io::read_model_string(crank_yaml(dt, t_end), "crank.yaml");
  m.solver.formulation = f;
  return m;
}

// The crank's angle from its director d₁ (the rod's axis), unwrapped near `near`.
double crank_angle(const VecX& q, double near) {
  const double raw = std::atan2(q(4), q(3));
  return near + std::remainder(raw - near, 2.0 * M_PI);
}

// The driver row of the first driven joint.
const system::JointDriver& driver_of(const system::System& sys) {
  for (const auto& J : sys.joints())
    if (J.driver >= 0)
      return dynamic_cast<const system::JointDriver&>(
          *sys.nary_constraints()[static_cast<std::size_t>(J.driver)].constraint);
  throw std::logic_error("no driver");
}

double driving_torque(const system::System& sys, const integrate::State& s) {
  for (const auto& r : system::joint_reactions(sys, s.q, s.lambda))
    if (r.driver) return *r.driver;
  throw std::logic_error("no driver reaction");
}

struct CrankRun {
  std::vector<VecX> q;
  double off = 0.0;                  // max |θ(qₙ) − θ(tₙ)|, the crank's own angle
  double row = 0.0;                  // max |Φ| of the driver row
  double torque = 0.0;               // max |τₙ₊½ − τ(tₙ₊½)|
  double torque_mean = 0.0;          // max |½ (τₙ₋½ + τₙ₊½) − τ(tₙ)|
  double balance = 0.0, work = 0.0;  // max |E − W − E₀|, max |W|
  int iterations = 0, steps = 0;
};

CrankRun run_crank(double dt, double t_end, F f) {
  const model::Model m = crank(dt, t_end, f);
  const auto sys = system::System::compile(m);
  const integrate::EnergyMomentumIntegrator integ(sys, m.solver);
  auto s = integ.initial_state();
  const auto& D = driver_of(sys);
  CrankRun out;
  const auto energy = [&] { return integ.snapshot(s, {}, {}).total_energy; };
  const double E0 = energy();
  const int steps = static_cast<int>(std::lround(t_end / dt));
  double angle = 0.0, last_torque = 0.0;
  for (int i = 0; i < steps; ++i) {
    const double t0 = s.t;
    out.iterations += integ.step(s).iterations;
    ++out.steps;
    angle = crank_angle(s.q, angle);
    out.off = std::max(out.off, std::abs(angle - theta(s.t)));
    out.row = std::max(out.row, std::abs(D.value(sys.stacked(s.q, D.nodes())) - theta(s.t)));
    const double tau = driving_torque(sys, s);
    out.torque = std::max(out.torque, std::abs(tau - torque(0.5 * (t0 + s.t))));
    if (i > 0)
      out.torque_mean = std::max(out.torque_mean, std::abs(0.5 * (last_torque + tau) - torque(t0)));
    last_torque = tau;
    out.balance = std::max(out.balance, std::abs(energy() - s.driver_work - E0));
    out.work = std::max(out.work, std::abs(s.driver_work));
    out.q.push_back(s.q);
  }
  return out;
}

}  // namespace

// (a), (c), (e): every formulation holds θ(tₙ) at the nodes, keeps E − W_driver, and they agree.
TEST(JointDrivers, TheCrankFollowsItsAngleInEveryFormulation) {
  std::vector<CrankRun> runs;
  for (const F f : {F::constrained, F::nullspace, F::reparametrized}) {
    runs.push_back(run_crank(0.01, 4.0, f));
    const CrankRun& r = runs.back();
    std::printf(
        "  [drivers] %s: angle off %.2e, driver row off %.2e, |E - W - E0| %.2e (max |W| %.3g), "
        "%.2f Newton iterations per step\n",
        model::to_string(f), r.off, r.row, r.balance, r.work,
        static_cast<double>(r.iterations) / r.steps);
    EXPECT_LT(r.off, 1e-12);
    EXPECT_LT(r.row, 1e-12);
    EXPECT_GT(r.work, 1.0);  // the motor works: more than a joule
    EXPECT_LT(r.balance, 1e-11);
  }
  EXPECT_GT(theta(4.0), 2.0 * M_PI);  // more than one turn
  double diff = 0.0;
  for (std::size_t k = 1; k < runs.size(); ++k)
    for (std::size_t i = 0; i < runs[0].q.size(); ++i)
      diff = std::max(diff, (runs[k].q[i] - runs[0].q[i]).lpNorm<Eigen::Infinity>());
  std::printf("  [drivers] formulations apart by %.2e\n", diff);
  EXPECT_LT(diff, 1e-10);
}

// (b): the reaction torque −λ of the step tₙ → tₙ₊₁ against τ = J θ̈ + ½ m g cos θ. The midpoint
// velocities vₙ₊₁ = 2Δq/Δt − vₙ of the directors carry an alternating error ±A, A = O(Δt²) (the
// chord of a turning director is not its mean velocity, −(Δt²/12) d⃛ ≠ 0 even for a steady turn),
// which the torque, a velocity difference over Δt, turns into an alternating error ±2A/Δt = O(Δt)
// per step; the mean of two consecutive steps cancels it and is O(Δt²) from τ(tₙ) (measured: a
// ratio near 4 when Δt is halved).
TEST(JointDrivers, TheDrivingTorqueIsJThetaDdotPlusTheGravityMoment) {
  const CrankRun a = run_crank(0.01, 2.0, F::reparametrized);
  const CrankRun b = run_crank(0.005, 2.0, F::reparametrized);
  std::printf(
      "  [drivers] torque per step off by %.3e (dt 0.01), %.3e (dt 0.005), ratio %.2f; mean of "
      "two steps off by %.3e, %.3e, ratio %.2f\n",
      a.torque, b.torque, a.torque / b.torque, a.torque_mean, b.torque_mean,
      a.torque_mean / b.torque_mean);
  EXPECT_LT(a.torque, 1e-2);            // the torque is O(5) N m
  EXPECT_GT(a.torque / b.torque, 1.6);  // O(Δt) per step
  // The mean of τ at tₙ ± Δt/2 alone is off τ(tₙ) by Δt² τ''/8 ≈ 4e-4 (τ'' ≈ ½ g θ̇² ≈ 30).
  EXPECT_LT(a.torque_mean, 1e-3);
  EXPECT_GT(a.torque_mean / b.torque_mean, 3.5);  // O(Δt²) for the mean
  EXPECT_LT(a.torque_mean / b.torque_mean, 4.5);
}

TEST(JointDrivers, TheInitialVelocitiesFollowTheDriverRate) {
  const auto sys = system::System::compile(crank(0.01, 0.01, F::reparametrized));
  const VecX& v = sys.v0();
  // θ̇(0) = ω: the centre of mass moves at ω × (0.5, 0, 0), d₁ at ω × e_x.
  EXPECT_NEAR(v(1), 0.5 * kOmega, 1e-9);
  EXPECT_NEAR(v(4), kOmega, 1e-9);
  EXPECT_NEAR(v.norm(), std::sqrt(0.25 + 1.0 + 1.0) * kOmega, 1e-9);
}

// (d) A body on a prismatic joint along x, driven by s(t) = 0.3 (1 − cos 2t), gravity along −x:
// its centre follows s(tₙ) exactly, and the driving force is m s̈ + m g to O(Δt²).
TEST(JointDrivers, APrismaticDriverSlidesTheBody) {
  for (const F f : {F::constrained, F::nullspace, F::reparametrized}) {
    model::Model m = io::read_model_string(
        "solver: {dt: 0.01, t_end: 1, residual_tolerance: 1e-12}\n"
        "gravity: [-9.81, 0, 0]\n"
        "bodies:\n"
        "  - {name: slider, mass: 2, inertia: [0.1, 0.1, 0.1], position: [1, 0, 0]}\n"
        "joints:\n"
        "  - {name: ram, type: prismatic, body_a: ground, body_b: slider, point: [1, 0, 0],\n"
        "     axis: [1, 0, 0], driver: \"0.3*(1 - cos(2*t))\"}\n",
        "slider.yaml");
    m.solver.formulation = f;
    const auto sys = system::System::compile(m);
    const integrate::EnergyMomentumIntegrator integ(sys, m.solver);
    auto s = integ.initial_state();
    double off = 0.0, force = 0.0;
    for (int i = 0; i < 100; ++i) {
      const double t0 = s.t;
      integ.step(s);
      off = std::max(off, std::abs(s.q(0) - 1.0 - 0.3 * (1.0 - std::cos(2.0 * s.t))));
      double F_drive = 0.0;
      for (const auto& r : system::joint_reactions(sys, s.q, s.lambda))
        if (r.driver) F_drive = *r.driver;
      const double tm = 0.5 * (t0 + s.t);
      force = std::max(force, std::abs(F_drive - (2.0 * 1.2 * std::cos(2.0 * tm) + 2.0 * 9.81)));
    }
    std::printf("  [drivers] prismatic, %s: slide off %.2e, force off %.2e\n", model::to_string(f),
                off, force);
    EXPECT_LT(off, 1e-13);
    EXPECT_LT(force, 1e-3);
  }
}

// (d) A rod hanging from a spherical joint whose ground point is driven along p(t): the rod's
// point follows p(tₙ) exactly; the reaction (the driving force) closes the discrete balance of
// linear momentum, pₙ₊₁ − pₙ = Δt (m g + F), to round-off.
TEST(JointDrivers, APointDriverMovesTheBodyPoint) {
  for (const F f : {F::constrained, F::nullspace, F::reparametrized}) {
    model::Model m = io::read_model_string(
        "solver: {dt: 0.01, t_end: 1, residual_tolerance: 1e-12}\n"
        "gravity: [0, 0, -9.81]\n"
        "bodies:\n"
        "  - {name: rod, mass: 1.5, inertia: [0.1, 0.1, 0.01], position: [0, 0, -0.5]}\n"
        "joints:\n"
        "  - {name: hand, type: spherical, body_a: ground, body_b: rod, point: [0, 0, 0],\n"
        "     driver: [\"0.1*sin(3*t)\", \"0.05*(1 - cos(2*t))\", \"0.02*t\"]}\n",
        "hand.yaml");
    m.solver.formulation = f;
    const auto sys = system::System::compile(m);
    EXPECT_FALSE(sys.joints()[0].tree);
    const integrate::EnergyMomentumIntegrator integ(sys, m.solver);
    auto s = integ.initial_state();
    double off = 0.0, balance = 0.0, scale = 0.0;
    for (int i = 0; i < 100; ++i) {
      const Vec3 p0 = sys.linear_momentum(s.v);
      integ.step(s);
      const Vec3 p(0.1 * std::sin(3 * s.t), 0.05 * (1 - std::cos(2 * s.t)), 0.02 * s.t);
      off = std::max(off, (sys.material_point(s.q, 0, Vec3(0, 0, 0.5)) - p).norm());
      const auto r = system::joint_reactions(sys, s.q, s.lambda).front();
      EXPECT_FALSE(r.driver);
      const Vec3 rate = (sys.linear_momentum(s.v) - p0) / 0.01;
      balance = std::max(balance, (rate - Vec3(0, 0, -1.5 * 9.81) - r.force).norm());
      scale = std::max(scale, r.force.norm());
    }
    std::printf("  [drivers] point, %s: point off %.2e, momentum balance off %.2e (|F| %.3g)\n",
                model::to_string(f), off, balance, scale);
    EXPECT_LT(off, 1e-13);
    EXPECT_LT(balance, 1e-9 * scale);
  }
}

// A driven crank in a closed loop (the planar four-bar of four revolute joints, three redundant
// loop rows): the driver row is a loop-closing row beside them, kept by the row selection; the
// mechanism has no freedom left. Every formulation follows θ(tₙ), keeps E − W_driver, and they
// agree.
TEST(JointDrivers, ADrivenFourBarInEveryFormulation) {
  std::vector<std::vector<VecX>> runs;
  for (const F f : {F::constrained, F::nullspace, F::reparametrized}) {
    model::Model m = test::four_bar(f);
    m.joints[0].driver = {"2*t + 0.3*(1 - cos(3*t))"};  // θ̇(0) = 2, the crank's given spin
    m.solver.residual_tolerance = 1e-12;
    const auto sys = system::System::compile(m);
    EXPECT_EQ(sys.dof(), 0);
    EXPECT_EQ(sys.redundant_rows().size(), 3u);
    const integrate::EnergyMomentumIntegrator integ(sys, m.solver);
    auto s = integ.initial_state();
    const auto& D = driver_of(sys);
    // The given velocities (the crank alone spins) are projected onto G v = ḋ(0): θ̇(0) = 2.
    EXPECT_NEAR((D.jacobian(sys.stacked(s.q, D.nodes())) * sys.stacked(s.v, D.nodes()))(0), 2.0,
                1e-9);
    EXPECT_LT(sys.constraints(s.q, 0.0).lpNorm<Eigen::Infinity>(), 1e-12);
    const double E0 = integ.snapshot(s, {}, {}).total_energy;
    double off = 0.0, balance = 0.0;
    int iterations = 0;
    std::vector<VecX> q;
    for (int i = 0; i < 150; ++i) {
      iterations += integ.step(s).iterations;
      off = std::max(off, std::abs(D.value(sys.stacked(s.q, D.nodes())) -
                                   (2 * s.t + 0.3 * (1 - std::cos(3 * s.t)))));
      balance =
          std::max(balance, std::abs(integ.snapshot(s, {}, {}).total_energy - s.driver_work - E0));
      q.push_back(s.q);
    }
    std::printf(
        "  [drivers] four-bar, %s: angle off %.2e, |E - W - E0| %.2e (W %.3g), %.2f "
        "iterations per step\n",
        model::to_string(f), off, balance, s.driver_work, iterations / 150.0);
    EXPECT_LT(off, 1e-12);
    EXPECT_LT(balance, 1e-10);
    runs.push_back(std::move(q));
  }
  double diff = 0.0;
  for (std::size_t k = 1; k < runs.size(); ++k)
    for (std::size_t i = 0; i < runs[0].size(); ++i)
      diff = std::max(diff, (runs[k][i] - runs[0][i]).lpNorm<Eigen::Infinity>());
  std::printf("  [drivers] four-bar: formulations apart by %.2e\n", diff);
  EXPECT_LT(diff, 1e-10);
}

// A static analysis follows the driver with the load parameter: the crank held at θ(t) against
// gravity, the driving torque ½ m g cos θ(t).
TEST(JointDrivers, AStaticAnalysisFollowsTheDriver) {
  std::string yaml = crank_yaml(0.05, 1.0);
  yaml.replace(yaml.find("integrator: energy_momentum"), 27, "analysis: static");
  const auto dir = test::temp_dir("isoflex_drivers_", "static");
  std::ofstream(dir / "m.yaml") << yaml;
  const auto r =
      test::run_isoflex("run " + (dir / "m.yaml").string() + " -o " + (dir / "out").string());
  ASSERT_EQ(r.code, 0) << r.out;
  std::ifstream in(dir / "out" / "reactions.csv");
  std::string line;
  std::getline(in, line);
  EXPECT_TRUE(line.ends_with(",driver")) << line;
  double worst = 0.0;
  int rows = 0;
  while (std::getline(in, line)) {
    std::vector<double> v;
    std::stringstream ss(line);
    std::string field;
    while (std::getline(ss, field, ',')) v.push_back(field == "motor" ? 0.0 : std::stod(field));
    ASSERT_EQ(v.size(), 18u);
    worst = std::max(worst, std::abs(v[17] - 0.5 * kG * std::cos(theta(v[0]))));
    ++rows;
  }
  std::printf("  [drivers] static: %d load steps, torque off %.2e\n", rows, worst);
  EXPECT_EQ(rows, 20);
  EXPECT_LT(worst, 1e-9);
  std::filesystem::remove_all(dir);
}

// The command line: reactions.csv's `driver` column and history.csv's `driver_work`, with
// E − driver_work constant in the file and the summary's drift near round-off.
TEST(JointDrivers, TheRunWritesTheDriverColumnsAndTheBalanceHolds) {
  const auto dir = test::temp_dir("isoflex_drivers_", "cli");
  std::ofstream(dir / "m.yaml") << crank_yaml(0.01, 1.0);
  const auto r =
      test::run_isoflex("run " + (dir / "m.yaml").string() + " -o " + (dir / "out").string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("rates of the prescribed motions"), std::string::npos) << r.out;
  std::ifstream h(dir / "out" / "history.csv");
  std::string line;
  std::getline(h, line);
  ASSERT_TRUE(line.ends_with(",residual,driver_work")) << line;
  double E0 = 0.0, worst = 0.0, W = 0.0;
  for (int row = 0; std::getline(h, line); ++row) {
    std::vector<double> v;
    std::stringstream ss(line);
    std::string field;
    while (std::getline(ss, field, ',')) v.push_back(std::stod(field));
    if (row == 0) E0 = v[3];
    W = v[13];
    worst = std::max(worst, std::abs(v[3] - W - E0));
  }
  std::printf("  [drivers] history.csv: |E - driver_work - E0| %.2e, driver_work %.4g\n", worst, W);
  EXPECT_GT(std::abs(W), 1.0);
  EXPECT_LT(worst, 1e-12);
  std::ifstream rc(dir / "out" / "reactions.csv");
  std::getline(rc, line);
  EXPECT_TRUE(line.ends_with(",M1,M2,M3,driver")) << line;
  std::getline(rc, line);
  EXPECT_EQ(std::count(line.begin(), line.end(), ','), 17) << line;
  std::filesystem::remove_all(dir);
}

// The DAE schemes take the same rows: generalized-α holds θ(tₙ) at its nodes.
TEST(JointDrivers, TheDaeSchemesHoldTheAngleAtTheirNodes) {
  for (const std::string scheme : {"generalized_alpha", "bdf2"}) {
    const model::Model m =
        io::read_model_string(crank_yaml(0.01, 2.0, "2*t + 0.5*(1 - cos(t))", scheme), "c.yaml");
    const auto sys = system::System::compile(m);
    const auto integ = integrate::make_time_integrator(sys, m.solver);
    auto s = integ->initial_state();
    double off = 0.0, tq = 0.0, angle = 0.0;
    for (int i = 0; i < 200; ++i) {
      integ->step(s);
      angle = crank_angle(s.q, angle);
      off = std::max(off, std::abs(angle - theta(s.t)));
      tq = std::max(tq, std::abs(driving_torque(sys, s) - torque(s.t)));
    }
    std::printf("  [drivers] %s: angle off %.2e, torque off %.2e\n", scheme.c_str(), off, tq);
    EXPECT_LT(off, 1e-12);
    // λ at tₙ₊₁: first order for BDF-2's multipliers (its first step is BDF-1), closer for α.
    EXPECT_LT(tq, scheme == "bdf2" ? 0.3 : 0.05);
  }
}

// (f) The driver rows against central differences, at a configuration off the constraint
// manifold (the rows are functions on all of R²⁴ or R¹²).
TEST(JointDrivers, JacobianHessianAndDiscreteDerivativeOfTheDriverRows) {
  std::mt19937 g(7);
  for (const std::string type : {"revolute", "prismatic"}) {
    const model::Model m = io::read_model_string(
        "bodies:\n"
        "  - {name: a, mass: 1, inertia: [1, 1, 1], position: [0, 0, 0]}\n"
        "  - {name: b, mass: 1, inertia: [1, 1, 1], position: [0.4, 0.1, 0]}\n"
        "joints:\n"
        "  - {type: " +
            type +
            ", body_a: a, body_b: b, point: [0.2, 0.1, 0.05], axis: [0.3, 0.4, 0.866], "
            "driver: \"sin(t)\"}\n",
        "pair.yaml");
    const auto sys = system::System::compile(m);
    const auto& D = driver_of(sys);
    ASSERT_EQ(D.nodes().size(), 2u);
    const VecX q0 = sys.stacked(sys.q0(), D.nodes());
    const VecX q = q0 + test::random_vector(g, 24, 0.05);
    const auto phi = [&](const VecX& x) { return D.constraints(x); };
    const MatX G = D.jacobian(q);
    const double eG = test::rel_diff(G, test::central_jacobian(phi, q));
    MatX H = MatX::Zero(24, 24);
    D.add_constraint_hessian(q, VecX::Ones(1), H);
    const auto grad = [&](const VecX& x) { return VecX(D.jacobian(x).transpose()); };
    const double eH = test::rel_diff(H, test::central_jacobian(grad, q));
    // G̃ (q_b − q_a) = Φ(q_b) − Φ(q_a) for a finite increment, and G̃ → G(q) as q_b → q_a.
    const VecX qb = q + test::random_vector(g, 24, 0.05);
    const double exact = std::abs((D.discrete_jacobian(q, qb) * (qb - q))(0) -
                                  (D.constraints(qb) - D.constraints(q))(0));
    const double limit = test::rel_diff(D.discrete_jacobian(q, q), G);
    std::printf(
        "  [drivers] %s row: |G - FD| %.1e, |H - FD| %.1e, |G~ dq - dPhi| %.1e, |G~(q,q) - G| "
        "%.1e\n",
        type.c_str(), eG, eH, exact, limit);
    EXPECT_LT(eG, 1e-8);
    EXPECT_LT(eH, 1e-7);
    EXPECT_LT(exact, 1e-15);
    EXPECT_LT(limit, 1e-14);
    EXPECT_TRUE(D.rheonomic());
    EXPECT_NEAR(D.prescribed(0.3)(0), std::sin(0.3), 1e-15);
  }
}

// (g) Located errors: the reader for what the file says, the compiler for what the
// configuration says.
TEST(JointDrivers, LocatedErrors) {
  const std::string head =
      "bodies:\n"
      "  - {name: b, mass: 1, inertia: [1, 1, 1], position: [0.5, 0, 0]}\n"
      "joints:\n";
  const auto reader = [&](const std::string& joint) { return test::error_of(head + joint); };
  std::string e = reader(
      "  - {type: cylindrical, body_b: b, point: [0, 0, 0], axis: [0, 0, 1], driver: \"t\"}\n");
  EXPECT_NE(e.find("m.yaml:4"), std::string::npos) << e;
  EXPECT_NE(e.find("joints[0].driver"), std::string::npos) << e;
  EXPECT_NE(e.find("not cylindrical"), std::string::npos) << e;
  e = reader(
      "  - {type: revolute, body_b: b, point: [0, 0, 0], axis: [0, 0, 1], driver: \"2*\"}\n");
  EXPECT_NE(e.find("m.yaml:4"), std::string::npos) << e;
  EXPECT_NE(e.find("joints[0].driver"), std::string::npos) << e;
  e = reader(
      "  - {type: revolute, body_b: b, point: [0, 0, 0], axis: [0, 0, 1], driver: [t, 0, 0]}\n");
  EXPECT_NE(e.find("expected one number or expression in t"), std::string::npos) << e;
  e = reader("  - {type: spherical, body_b: b, point: [0, 0, 0], driver: \"t\"}\n");
  EXPECT_NE(e.find("expected a list of 3"), std::string::npos) << e;
  e = test::error_of(
      "bodies:\n"
      "  - {name: b, mass: 1, inertia: [1, 1, 1], position: [0.5, 0, 0]}\n"
      "  - {name: c, mass: 1, inertia: [1, 1, 1], position: [1.5, 0, 0]}\n"
      "joints:\n"
      "  - {type: spherical, body_a: b, body_b: c, point: [1, 0, 0], driver: [t, 0, 0]}\n");
  EXPECT_NE(e.find("m.yaml:5"), std::string::npos) << e;
  EXPECT_NE(e.find("body_a must be ground"), std::string::npos) << e;

  // Inconsistent with the configuration at t = 0: by how much.
  const auto compile = [&](const std::string& joint) -> std::string {
    try {
      system::System::compile(io::read_model_string(head + joint, "m.yaml"));
    } catch (const system::CompileError& err) {
      return err.what();
    }
    return "(no error)";
  };
  e = compile(
      "  - {type: revolute, body_b: b, point: [0, 0, 0], axis: [0, 0, 1], driver: \"0.3 + t\"}\n");
  EXPECT_NE(e.find("m.yaml:4"), std::string::npos) << e;
  EXPECT_NE(e.find("joints[0].driver"), std::string::npos) << e;
  EXPECT_NE(e.find("inconsistent by 0.3 rad"), std::string::npos) << e;
  e = compile(
      "  - {type: prismatic, body_b: b, point: [0, 0, 0], axis: [1, 0, 0], driver: \"1e-12 + "
      "t\"}\n");
  EXPECT_EQ(e, "(no error)");  // within the assembly tolerance
  e = compile(
      "  - {type: spherical, body_b: b, point: [0, 0, 0], driver: [\"0.1\", \"t\", \"0\"]}\n");
  EXPECT_NE(e.find("m.yaml:4"), std::string::npos) << e;
  EXPECT_NE(e.find("inconsistent by 0.1"), std::string::npos) << e;
  // A driver on what other rows already hold.
  e = compile(
      "  - {type: revolute, body_b: b, point: [0, 0, 0], axis: [0, 0, 1], driver: \"t\"}\n"
      "  - {type: revolute, body_b: b, point: [0, 0, 0], axis: [0, 0, 1], driver: \"t\"}\n");
  EXPECT_NE(e.find("prescribed motion"), std::string::npos) << e;
}
