// Force elements of issue #18 (docs/theory/coupling.md §6–§8) in whole systems: nonlinear spring
// and damper laws and actuators on the point spring–dampers (`springs`), bushings (`bushings`)
// and the spring–dampers of revolute and prismatic joints (joints `spring`).
//   - load-free free flights conserve energy and both momenta to round-off in all three
//     energy–momentum formulations (a revolute spring winding up several turns among them);
//   - dampers dissipate exactly what the energy loses, actuators add exactly their work;
//   - static equilibria known in closed form (a cubic spring under a force, a rotational spring
//     under a torque past π, a prismatic spring, a bushing in a linear analysis);
//   - the reader's located errors, forces.csv and history.csv's columns through the CLI.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "isoflex/elements/revolute_spring.hpp"
#include "isoflex/integrate/static_equilibrium.hpp"
#include "isoflex/io/model_reader.hpp"
#include "isoflex/math/frame_node.hpp"
#include "isoflex/system/system.hpp"
#include "support/cli.hpp"
#include "support/examples.hpp"
#include "support/files.hpp"
#include "support/trajectory.hpp"

using namespace isoflex;
using F = model::Formulation;

namespace {

constexpr F kFormulations[] = {F::reparametrized, F::constrained, F::nullspace};

const char* name_of(F f) {
  return model::to_string(f);
}

model::Model read(const std::string& text) {
  return io::read_model_string(text, "m.yaml");
}

std::string reader_error(const std::string& text) {
  try {
    io::read_model_string(text, "m.yaml");
  } catch (const std::exception& e) {
    return e.what();
  }
  return "no error";
}

// Two bodies flying free, spinning, with initial velocities (no gravity, no load).
const std::string kTwoBodies = R"(name: two
solver: {dt: 0.01, t_end: 1}
bodies:
  - {name: a, mass: 2, inertia: [0.05, 0.06, 0.07], position: [0, 0, 0],
     velocity: [0.3, -0.1, 0.2], angular_velocity: [1, -2, 1.5]}
  - {name: b, mass: 1, inertia: [0.02, 0.03, 0.04], position: [0.5, 0.1, 0],
     velocity: [-0.2, 0.4, 0.1], angular_velocity: [-1, 1, 0.5]}
)";

// A bushing between them at their middle, a full symmetric stiffness.
const std::string kBushing = R"(bushings:
  - name: mount
    body_a: a
    body_b: b
    point: [0.25, 0.05, 0]
    axis: [0, 0, 1]
    axis2: [1, 0, 0]
    stiffness: [[200, 10, 0, 0, 0, 1], [10, 150, 0, 0, 0, 0], [0, 0, 300, 0, 0, 0],
                [0, 0, 0, 5, 0, 0], [0, 0, 0, 0, 4, 0], [1, 0, 0, 0, 0, 6]]
)";

// A nonlinear spring between them, stretched at the start.
const std::string kCubicSpring = R"(springs:
  - name: cubic
    a: {body: a, point_local: [0.1, 0, 0]}
    b: {body: b, point_local: [-0.1, 0, 0]}
    free_length: 0.25
    stiffness_law: "200*e + 5000*e^3"
)";

// A chain of three bodies, no ground (examples/joint_springs): b on a revolute joint about x
// with a weak rotational spring, spinning 20 rad/s relative to a (it winds up about five turns in
// 2 s); c on a prismatic joint along y with a spring.
std::string chain() {
  return test::example_text("joint_springs", "model.yaml");
}

// The largest relative change of E + dissipated − external work from its start.
double balance_drift(const test::Trajectory& r) {
  const auto& s = r.snapshots;
  const double E0 = s.front().total_energy;
  double worst = 0.0;
  for (const auto& x : s)
    worst = std::max(worst, std::abs(x.total_energy + x.dissipated_energy - x.external_work - E0) /
                                std::abs(E0));
  return worst;
}

void expect_conserved(const model::Model& m, double energy, double momenta) {
  for (F f : kFormulations) {
    const test::Trajectory r = test::simulate(m, f);
    const test::Drift d = test::drift_after(r, 0.0);
    std::printf("  [force elements] %-14s energy %.2e, p %.2e, L %.2e\n", name_of(f), d.energy, d.p,
                d.L);
    EXPECT_LT(d.energy, energy) << name_of(f);
    EXPECT_LT(d.p, momenta) << name_of(f);
    EXPECT_LT(d.L, momenta) << name_of(f);
  }
}

}  // namespace

// --- Bushing --------------------------------------------------------------------------------

TEST(BushingFreeFlight, ConservesEnergyAndMomentaInEveryFormulation) {
  const model::Model m = read(kTwoBodies + kBushing);
  const auto sys = system::System::compile(m);
  ASSERT_EQ(sys.elements().size(), 3u);  // two bodies and the bushing
  // The bushing does work: its energy varies by a good part of the total.
  const test::Trajectory r = test::simulate(m, F::reparametrized);
  double vmax = 0.0;
  for (const auto& s : r.snapshots) vmax = std::max(vmax, s.potential_energy);
  EXPECT_GT(vmax, 0.05 * r.snapshots.front().total_energy);
  expect_conserved(m, 1e-12, 1e-12);
}

TEST(BushingFreeFlight, DampingDissipatesWhatTheEnergyLosesAndKeepsMomenta) {
  const model::Model m = read(kTwoBodies + kBushing + "    damping: [2, 2, 2, 0.05, 0.05, 0.05]\n");
  for (F f : kFormulations) {
    const test::Trajectory r = test::simulate(m, f);
    EXPECT_GT(r.snapshots.back().dissipated_energy, 0.01 * r.snapshots.front().total_energy);
    const double b = balance_drift(r);
    const test::Drift d = test::drift_after(r, 0.0);
    std::printf("  [force elements] %-14s E + D drift %.2e, p %.2e, L %.2e\n", name_of(f), b, d.p,
                d.L);
    EXPECT_LT(b, 1e-12) << name_of(f);
    EXPECT_LT(d.p, 1e-12) << name_of(f);
    EXPECT_LT(d.L, 1e-12) << name_of(f);
  }
}

// --- Joint springs --------------------------------------------------------------------------

TEST(JointSpringFreeFlight, RevoluteSpringWindsUpSeveralTurnsConservingEnergyAndMomenta) {
  const model::Model m = read(chain());
  for (F f : kFormulations) {
    model::Model mf = m;
    mf.solver.formulation = f;
    const auto sys = system::System::compile(mf);
    const integrate::EnergyMomentumIntegrator integ(sys, mf.solver);
    auto state = integ.initial_state();
    const elements::RevoluteSpring* spring = nullptr;
    for (const auto& e : sys.elements())
      if (const auto* s = dynamic_cast<const elements::RevoluteSpring*>(e.get())) spring = s;
    ASSERT_NE(spring, nullptr);
    const auto angle = [&](const VecX& q) {
      return spring->angle(sys.stacked(q, spring->nodes()));
    };
    test::Trajectory r;
    r.snapshots.push_back(integ.snapshot(state, {}, {}));
    double largest = 0.0, previous = 0.0, jump = 0.0;
    for (int i = 0; i < 200; ++i) {
      integ.step(state);
      r.snapshots.push_back(integ.snapshot(state, {}, {}));
      const double theta = angle(state.q);
      largest = std::max(largest, std::abs(theta));
      jump = std::max(jump, std::abs(theta - previous));
      previous = theta;
    }
    const test::Drift d = test::drift_after(r, 0.0);
    std::printf(
        "  [force elements] %-14s largest angle %.2f rad (%.2f turns), energy %.2e, p %.2e, L "
        "%.2e\n",
        name_of(f), largest, largest / (2 * std::numbers::pi), d.energy, d.p, d.L);
    EXPECT_GT(largest, 4 * 2 * std::numbers::pi) << name_of(f);  // more than four turns
    EXPECT_LT(jump, 0.5) << name_of(f);                          // continuous across turns
    EXPECT_LT(d.energy, 1e-12) << name_of(f);
    EXPECT_LT(d.p, 1e-12) << name_of(f);
    EXPECT_LT(d.L, 1e-12) << name_of(f);
    // At the largest angle the spring holds a good part of the energy: ½ k θ².
    EXPECT_GT(0.5 * 0.005 * largest * largest, 0.3 * r.snapshots.front().total_energy);
  }
}

TEST(JointSpringFreeFlight, DampersDissipateWhatTheEnergyLoses) {
  std::string text = test::replaced(chain(), "spring: {stiffness: 0.005}",
                                    "spring: {stiffness: 0.005, damping: 0.002}");
  text = test::replaced(text, "spring: {stiffness: 30, free_length: 0.1}",
                        "spring: {stiffness: 30, damping: 0.5, free_length: 0.1}");
  const model::Model m = read(text);
  for (F f : kFormulations) {
    const test::Trajectory r = test::simulate(m, f);
    const double b = balance_drift(r);
    const test::Drift d = test::drift_after(r, 0.0);
    std::printf("  [force elements] %-14s dissipated %.3f of %.3f, E + D drift %.2e, L %.2e\n",
                name_of(f), r.snapshots.back().dissipated_energy, r.snapshots.front().total_energy,
                b, d.L);
    EXPECT_GT(r.snapshots.back().dissipated_energy, 0.05 * r.snapshots.front().total_energy);
    EXPECT_LT(b, 1e-12) << name_of(f);
    EXPECT_LT(d.p, 1e-12) << name_of(f);
    EXPECT_LT(d.L, 1e-12) << name_of(f);
  }
}

// --- Nonlinear springs and actuators ------------------------------------------------------------

TEST(NonlinearSpringFreeFlight, ConservesEnergyAndMomentaInEveryFormulation) {
  expect_conserved(read(kTwoBodies + kCubicSpring), 1e-12, 1e-12);
}

TEST(NonlinearSpringFreeFlight, DamperAndActuatorBalanceTheEnergyAndKeepMomenta) {
  const model::Model m =
      read(kTwoBodies + kCubicSpring +
           "    damping_law: \"0.5*v + 2*v^3\"\n    actuator: \"20*sin(9*t)\"\n");
  for (F f : kFormulations) {
    const test::Trajectory r = test::simulate(m, f);
    const auto& last = r.snapshots.back();
    const double b = balance_drift(r);
    const test::Drift d = test::drift_after(r, 0.0);
    double work = 0.0;
    for (const auto& s : r.snapshots) work = std::max(work, std::abs(s.external_work));
    std::printf(
        "  [force elements] %-14s E0 %.3f, dissipated %.3f, largest |work| %.3f, E + D − W drift "
        "%.2e, p %.2e, L %.2e\n",
        name_of(f), r.snapshots.front().total_energy, last.dissipated_energy, work, b, d.p, d.L);
    EXPECT_GT(last.dissipated_energy, 0.0);
    EXPECT_GT(work, 0.05 * r.snapshots.front().total_energy);  // the actuator does work
    EXPECT_LT(b, 1e-12) << name_of(f);
    EXPECT_LT(d.p, 1e-12) << name_of(f);  // the actuator is a pair of opposite forces on a line
    EXPECT_LT(d.L, 1e-12) << name_of(f);
  }
}

// --- Statics in closed form ---------------------------------------------------------------------

namespace {

// The static equilibrium of `text` at t_end: q.
VecX equilibrium(const std::string& text, system::System* out = nullptr) {
  const model::Model m = read(text);
  auto sys = system::System::compile(m);
  integrate::StaticEquilibrium eq(sys, m.solver);
  const VecX q = eq.solve().x.head(sys.n());
  if (out) *out = std::move(sys);
  return q;
}

const std::string kStaticBody = R"(name: s
solver: {analysis: static, dt: 0.05, t_end: 1}
bodies:
  - {name: c, mass: 1, inertia: [1, 1, 1], position: [0, 0, 0]}
)";

}  // namespace

// A body on a prismatic guide along x pulled by F = 50 away from a ground point 1 behind it, on
// a spring N(e) = 100 e + 2000 e³: e solves 100 e + 2000 e³ = 50 (Cardano).
TEST(ForceElementsStatic, CubicSpringUnderAForce) {
  const double u = equilibrium(kStaticBody + R"(joints:
  - {type: prismatic, body_a: ground, body_b: c, point: [0, 0, 0], axis: [1, 0, 0]}
springs:
  - {a: {body: ground, point: [-1, 0, 0]}, b: {body: c}, stiffness_law: "100*e + 2000*e^3"}
loads:
  - {body: c, force: ["50*t", 0, 0]}
)")(0);
  // 2000 e³ + 100 e − 50 = 0: e³ + p e + q = 0 with p = 0.05, q = −0.025.
  const double p = 0.05, q = -0.025, D = std::sqrt(q * q / 4 + p * p * p / 27);
  const double e = std::cbrt(-q / 2 + D) + std::cbrt(-q / 2 - D);
  std::printf("  [force elements] cubic spring: e = %.15f, closed form %.15f\n", u, e);
  EXPECT_NEAR(u, e, 1e-12);
  EXPECT_NEAR(100 * u + 2000 * u * u * u, 50.0, 1e-9);
}

// A body on a revolute joint about z with a rotational spring k = 2 under a torque M = 10 t:
// θ = M/k = 5 rad at t = 1, past π — the load steps carry the branch (System::accept).
TEST(ForceElementsStatic, RotationalSpringUnderATorqueTurnsPastPi) {
  system::System sys;
  const VecX q = equilibrium(kStaticBody + R"(joints:
  - {type: revolute, body_a: ground, body_b: c, point: [0, 0, 0], axis: [0, 0, 1],
     spring: {stiffness: 2}}
loads:
  - {body: c, moment: [0, 0, "10*t"]}
)",
                             &sys);
  const elements::RevoluteSpring* spring = nullptr;
  for (const auto& e : sys.elements())
    if (const auto* s = dynamic_cast<const elements::RevoluteSpring*>(e.get())) spring = s;
  ASSERT_NE(spring, nullptr);
  const double theta = spring->angle(sys.stacked(q, spring->nodes()));
  const Vec3 d1 = frame_node::directors(frame_node::Q(q.head<12>())).col(0);
  std::printf("  [force elements] rotational spring: θ = %.15f (M/k = 5), d1 = (%.6f, %.6f)\n",
              theta, d1.x(), d1.y());
  EXPECT_NEAR(theta, 5.0, 1e-12);
  EXPECT_NEAR(d1.x(), std::cos(5.0), 1e-12);
  EXPECT_NEAR(d1.y(), std::sin(5.0), 1e-12);
}

// A prismatic joint's spring k = 40 with free length 0.1 under F = 2 along the axis:
// s = 0.1 + F/k = 0.15.
TEST(ForceElementsStatic, PrismaticSpringUnderAForce) {
  const VecX q = equilibrium(kStaticBody + R"(joints:
  - {type: prismatic, body_a: ground, body_b: c, point: [0, 0, 0], axis: [0, 1, 0],
     spring: {stiffness: 40, free_length: 0.1}}
loads:
  - {body: c, force: [0, "2*t", 0]}
)");
  EXPECT_NEAR(q(1), 0.15, 1e-12);
  EXPECT_NEAR(q(0), 0.0, 1e-12);
}

// A body held by a bushing to the ground alone, diagonal stiffness, in a linear analysis, under
// a dead force F at the body point r: u = F/k_u and θ = (r × F)/k_θ component by component (the
// rotation from ½ Σ eᵢ × dᵢ, exact in a linear analysis).
TEST(ForceElementsStatic, BushingInALinearAnalysis) {
  const VecX q = equilibrium(test::replaced(kStaticBody, "t_end: 1}", "t_end: 1, linear: true}") +
                             R"(bushings:
  - {body_b: c, point: [0, 0, 0], stiffness: [100, 200, 300, 10, 20, 30]}
loads:
  - {body: c, force: ["1*t", "2*t", "3*t"], point_local: [0.3, -0.1, 0.2]}
)");
  const Mat3 R = frame_node::directors(frame_node::Q(q.head<12>()));
  Vec3 theta = Vec3::Zero();
  for (int i = 0; i < 3; ++i) theta += 0.5 * Vec3::Unit(i).cross(R.col(i));
  const Vec3 F(1, 2, 3), M = Vec3(0.3, -0.1, 0.2).cross(F);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(q(i), F(i) / (100.0 * (i + 1)), 1e-12) << i;
    EXPECT_NEAR(theta(i), M(i) / (10.0 * (i + 1)), 1e-12) << i;
  }
}

// --- Reader -------------------------------------------------------------------------------------

TEST(ForceElementsReader, LocatedErrors) {
  const std::string head = R"(name: s
bodies:
  - {name: a, mass: 1, inertia: [1, 1, 1], position: [0, 0, 0]}
)";
  const auto spring = [&](const std::string& keys) {
    return reader_error(head + "springs:\n  - {a: {body: a}, b: {body: ground, point: [1, 0, 0]}" +
                        keys + "}\n");
  };
  const auto expect_has = [](const std::string& error, const std::string& part) {
    EXPECT_NE(error.find(part), std::string::npos) << error;
  };
  expect_has(spring(", stiffness_law: \"2*x\""),
             "m.yaml:5: springs[0].stiffness_law: invalid expression \"2*x\"");
  expect_has(spring(", stiffness_law: \"2*e\", stiffness: 1"),
             "springs[0].stiffness_law: give either stiffness or stiffness_law, not both");
  expect_has(spring(", damping_law: \"v - 2*v^3\""),
             "springs[0].damping_law: a damper must dissipate, v·N_d(v) ≥ 0 and N_d(0) = 0, but "
             "N_d(-1) = 1");
  expect_has(spring(", damping_law: \"x\""), "springs[0].damping_law: invalid expression \"x\"");
  expect_has(spring(", actuator: \"sin(v)\""), "springs[0].actuator: invalid expression");
  expect_has(spring(""), "springs[0]: give stiffness, damping (or stiffness_law, damping_law)");
  const std::string joint_head =
      head + R"(  - {name: b, mass: 1, inertia: [1, 1, 1], position: [1, 0, 0]}
joints:
)";
  expect_has(reader_error(joint_head + "  - {type: spherical, body_a: a, body_b: b, point: [0, 0, "
                                       "0], spring: {stiffness: 1}}\n"),
             "m.yaml:6: joints[0].spring: a spring is built for revolute and prismatic joints "
             "only, not spherical");
  expect_has(reader_error(joint_head + "  - {type: revolute, body_a: a, body_b: b, point: [0, 0, "
                                       "0], axis: [0, 0, 1], spring: {stiffness: 1, "
                                       "free_length: 2}}\n"),
             "joints[0].spring.free_length: unknown key (valid keys: stiffness, damping, "
             "free_angle)");
  const std::string bushing_head = head + "bushings:\n";
  expect_has(reader_error(bushing_head + "  - {body_b: a, stiffness: [1, 1, 1, 1, 1, 1]}\n"),
             "m.yaml:5: bushings[0].point: missing required key");
  expect_has(reader_error(bushing_head + "  - {body_b: a, point: [0, 0, 0], stiffness: [1, 1]}\n"),
             "bushings[0].stiffness: expected 6 numbers (the diagonal) or 6 rows of 6 numbers");
  expect_has(reader_error(bushing_head + "  - {body_b: a, point: [0, 0, 0], stiffness: [1, 1, -1, "
                                         "1, 1, 1]}\n"),
             "bushings[0].stiffness: must be positive semi-definite (smallest eigenvalue -1)");
  expect_has(reader_error(bushing_head + "  - {body_b: a, point: [0, 0, 0], axis2: [1, 0, 0], "
                                         "damping: [1, 1, 1, 1, 1, 1]}\n"),
             "bushings[0].axis2: the first frame axis needs the third");
}

// Through the CLI: forces.csv reports N(e) + N_d(ζ̇) + F(t) of a spring with laws and an
// actuator; history.csv has dissipated_energy and external_work; check prints the laws.
TEST(NonlinearSpringFreeFlight, CliWritesTheNonlinearForceAndTheWork) {
  const test::TempDir dir(test::temp_dir("isoflex_", "force_elements_cli"));
  const std::string model = (dir.path() / "m.yaml").string();
  test::write_text(model,
                   test::replaced(kTwoBodies, "t_end: 1", "t_end: 0.1") + kCubicSpring +
                       "    damping_law: \"0.5*v + 2*v^3\"\n    actuator: \"20*sin(9*t)\"\n");
  const auto c = test::run_isoflex("check " + model);
  ASSERT_EQ(c.code, 0) << c.out;
  EXPECT_NE(c.out.find("spring           cubic: stiffness law \"200*e + 5000*e^3\", damping law "
                       "\"0.5*v + 2*v^3\", actuator \"20*sin(9*t)\", free length 0.25"),
            std::string::npos)
      << c.out;
  const auto r = test::run_isoflex("run " + model + " -o " + (dir.path() / "out").string());
  ASSERT_EQ(r.code, 0) << r.out;
  std::istringstream forces(test::read_text((dir.path() / "out" / "forces.csv").string()));
  std::string line;
  std::getline(forces, line);
  EXPECT_EQ(line, "t,spring,length,elongation,rate,force");
  int rows = 0;
  while (std::getline(forces, line)) {
    std::istringstream f(line);
    std::string field[6];
    for (auto& x : field) std::getline(f, x, ',');
    const double t = std::stod(field[0]), e = std::stod(field[3]), v = std::stod(field[4]);
    EXPECT_NEAR(std::stod(field[2]) - 0.25, e, 1e-14) << line;
    EXPECT_NEAR(std::stod(field[5]),
                200 * e + 5000 * e * e * e + 0.5 * v + 2 * v * v * v + 20 * std::sin(9 * t), 1e-11)
        << line;
    ++rows;
  }
  EXPECT_EQ(rows, 11);
  const std::string history = test::read_text((dir.path() / "out" / "history.csv").string());
  EXPECT_NE(history.find(",residual,dissipated_energy,external_work\n"), std::string::npos);
}

// forces.csv rows of the springs between frames (the snapshot's springs): a joint spring's angle
// or slide with its moment or force, a bushing's six strains with K e (+ C ė); their energies are
// the potential energy of the free flight (no other potential).
TEST(ForceElementsOutput, JointSpringsAndBushingsAreReported) {
  const test::Trajectory r = test::simulate(read(chain()), F::reparametrized);
  const auto& last = r.snapshots.back();
  ASSERT_EQ(last.springs.size(), 2u);
  const auto& hinge = last.springs[0];
  const auto& slide = last.springs[1];
  EXPECT_EQ(hinge.name, "hinge");
  EXPECT_EQ(slide.name, "slide");
  EXPECT_GT(hinge.length, 30.0);  // θ across five turns
  EXPECT_NEAR(hinge.force, 0.005 * hinge.elongation, 1e-15);
  // V = ½ k_θ θ² + ½ k_s (s − s₀)²: the potential energy of the model.
  const double k_slide = slide.force / slide.elongation;
  EXPECT_NEAR(0.5 * 0.005 * hinge.elongation * hinge.elongation +
                  0.5 * k_slide * slide.elongation * slide.elongation,
              last.potential_energy, 1e-12 * r.snapshots.front().total_energy);
  const test::Trajectory b = test::simulate(read(kTwoBodies + kBushing), F::reparametrized);
  const auto& s = b.snapshots.back();
  ASSERT_EQ(s.springs.size(), 6u);
  EXPECT_EQ(s.springs[0].name, "mount.u1");
  EXPECT_EQ(s.springs[5].name, "mount.theta3");
  double V = 0.0;
  for (const auto& x : s.springs) V += 0.5 * x.force * x.elongation;  // ½ eᵀ K e, no damping
  EXPECT_NEAR(V, s.potential_energy, 1e-12 * b.snapshots.front().total_energy);
  EXPECT_GT(s.potential_energy, 1e-3);
}
