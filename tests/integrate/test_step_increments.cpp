// The step's velocities v_{n+1} = (2/Δt)(q_{n+1} − qₙ) − vₙ from the increments, not from the
// difference of rounded coordinates (docs/theory/schemes.md §7): the constrained and null-space
// unknowns are Δq, the reparametrized free nodes' increments come from u (System::update,
// NodeType::root_update with an increment). The momenta's round-off then scales with the
// increments, not with the distance from the origin. Before, reparametrized, a director plate, a
// Kirchhoff–Love plate and a rigid body 100 m from the origin drifted 5.4·10⁻¹¹, 2.3·10⁻¹⁰
// and 1.4·10⁻¹⁰ in linear momentum (|p| = 2, 2, 0.1) over 40, 40 and 100 steps, and 3·10⁻¹¹ …
// 9·10⁻¹⁰ relative in angular momentum; now 8·10⁻¹⁶, 6·10⁻¹⁶, 0 and ≤ 10⁻¹⁵. The constrained and
// null-space runs drifted 6–9·10⁻¹¹ (plates) and now ≤ 3·10⁻¹⁵.
#include <gtest/gtest.h>

#include <string>

#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/io/model_reader.hpp"
#include "isoflex/system/system.hpp"

using namespace isoflex;

namespace {

struct Drift {
  double linear, angular, energy;  // |Δp|/|p|, |ΔL|/|L|, |ΔE|/E
};

Drift drift_after(const std::string& yaml, int steps, model::Formulation f) {
  model::Model m = io::read_model_string(yaml, "far.yaml");
  m.solver.formulation = f;
  const auto sys = system::System::compile(m);
  integrate::EnergyMomentumIntegrator integ(sys, m.solver);
  auto s = integ.initial_state();
  const integrate::Snapshot first = integ.snapshot(s, {}, {});
  for (int i = 0; i < steps; ++i) integ.step(s);
  const integrate::Snapshot last = integ.snapshot(s, {}, {});
  return {(last.linear_momentum - first.linear_momentum).norm() / first.linear_momentum.norm(),
          (last.angular_momentum - first.angular_momentum).norm() / first.angular_momentum.norm(),
          std::abs(last.total_energy - first.total_energy) / first.total_energy};
}

// The spinning 2 × 1 plate of tests/system/test_shell_velocities.cpp, its corner at (100, 100, 0).
const std::string kSpin =
    "    material: {E: 1.0e6, nu: 0.3, thickness: 0.01, density: 1000}\n"
    "    velocity: [0.1, 0, 0]\n    angular_velocity: [0.3, 0, 1]\n"
    "    velocity_point: [101, 100.5, 0]\n";

void expect_round_off(const std::string& yaml, int steps) {
  using F = model::Formulation;
  for (const F f : {F::constrained, F::nullspace, F::reparametrized}) {
    const Drift d = drift_after(yaml, steps, f);
    EXPECT_LT(d.linear, 1e-14) << model::to_string(f);
    EXPECT_LT(d.angular, 1e-14) << model::to_string(f);
    // The energy keeps V's own round-off: strains from coordinates of size 100 (the director
    // plate: 1.1·10⁻¹² in the constrained run, 1.7·10⁻¹¹ before at most along it).
    EXPECT_LT(d.energy, 5e-12) << model::to_string(f);
  }
}

}  // namespace

TEST(StepIncrements, DirectorShellFarFromTheOriginKeepsItsMomenta) {
  expect_round_off(
      "name: far\nsolver: {dt: 0.005, t_end: 1}\nshells:\n  - name: p\n"
      "    plate: {corners: [[100, 100, 0], [102, 100, 0], [102, 101, 0], [100, 101, 0]],"
      " elements: [4, 2]}\n" +
          kSpin,
      40);
}

TEST(StepIncrements, KirchhoffLoveShellFarFromTheOriginKeepsItsMomenta) {
  expect_round_off(
      "name: far\nsolver: {dt: 0.005, t_end: 1}\nsurfaces:\n"
      "  - {name: s, builtin: {type: rectangle, size: [2, 1], corner: [100, 100, 0]},\n"
      "     refine: {elevate: [1, 1], knots_per_span: [1, 1]}}\n"
      "kl_shells:\n  - name: p\n    surface: s\n" +
          kSpin,
      40);
}

TEST(StepIncrements, RigidBodyFarFromTheOriginKeepsItsMomenta) {
  expect_round_off(
      "name: far\nsolver: {dt: 0.01, t_end: 1}\nbodies:\n  - name: nut\n    mass: 1.0\n"
      "    inertia: [1.0, 2.0, 3.0]\n    position: [100, 100, 100]\n    velocity: [0.1, 0, 0]\n"
      "    angular_velocity: [0.01, 5.0, 0.01]\n",
      100);
}

// Two bodies on a spherical joint, flying free, at the origin and 100 m away: the child's
// increment composed down the tree from the root's (Joint::update with a StepIncrement), not the
// difference of its rounded coordinates. Constrained and null space: round-off. Reparametrized:
// the momenta drift by what Newton's residual test leaves (its scale, (2/Δt)‖M qₙ‖∞, 1e-16 of
// which is above the increments' round-off), 8·10⁻¹³ of |p| in 100 steps, the same at 100 m as at
// the origin; before, the child's difference made it 9.5·10⁻¹¹ at 100 m (7.3·10⁻¹³ at the origin).
namespace {

// Two bodies on a spherical joint, flying free, moved by `offset` along (1, 1, 1).
std::string bodies_on_a_joint(double offset) {
  const auto at = [&](double x, double y, double z) {
    return "[" + std::to_string(x + offset) + ", " + std::to_string(y + offset) + ", " +
           std::to_string(z + offset) + "]";
  };
  return "name: far\nsolver: {dt: 0.01, t_end: 1}\nbodies:\n"
         "  - {name: upper, mass: 1.0, inertia: [0.01, 0.08, 0.09], position: " +
         at(0.5, 0, 0) +
         ",\n     angular_velocity: [0.3, 0.2, 1.0], velocity: [0.1, 0.5, 0]}\n"
         "  - {name: lower, mass: 2.0, inertia: [0.02, 0.1, 0.11], position: " +
         at(1.5, 0, 0) +
         ",\n     angular_velocity: [0, 0.5, -1.0], velocity: [0, -0.2, 0.3]}\n"
         "joints:\n  - {name: elbow, type: spherical, body_a: upper, body_b: lower, point: " +
         at(1, 0, 0) + "}\n";
}

}  // namespace

TEST(StepIncrements, BodiesOnAJointFarFromTheOriginDriftAsAtTheOrigin) {
  const auto model = bodies_on_a_joint;
  using F = model::Formulation;
  for (const F f : {F::constrained, F::nullspace}) {
    const Drift d = drift_after(model(100), 100, f);
    EXPECT_LT(d.linear, 1e-14) << model::to_string(f);
    EXPECT_LT(d.angular, 1e-14) << model::to_string(f);
    EXPECT_LT(d.energy, 5e-12) << model::to_string(f);
  }
  const Drift near = drift_after(model(0), 100, F::reparametrized);
  const Drift far = drift_after(model(100), 100, F::reparametrized);
  EXPECT_LT(near.linear, 2e-12);
  EXPECT_LT(far.linear, 2.0 * near.linear + 1e-15);
  EXPECT_LT(far.energy, 5e-12);
}

// The joint's reactions (the step's multipliers, EnergyMomentumIntegrator::step_multipliers) from
// vₙ₊₁ = (2/Δt) Δq − vₙ with the step's increment, as the Newton residual has it: reparametrized,
// the same 100 m from the origin as at it, step by step. From q_{n+1} − qₙ they differed by
// 4.8·10⁻¹⁰ of reactions up to 0.73 N (the rounding of the coordinates, ε·100 m / Δt). The tree
// recursion (the default here) and the block path (ReducedNewtonMatrix::multipliers) alike.
TEST(StepIncrements, JointReactionsFarFromTheOriginAreThoseAtTheOrigin) {
  for (const auto how : {integrate::ReducedSolve::automatic, integrate::ReducedSolve::blocks}) {
    const auto run = [how](double offset) {
      model::Model m = io::read_model_string(bodies_on_a_joint(offset), "far.yaml");
      m.solver.formulation = model::Formulation::reparametrized;
      const auto sys = system::System::compile(m);
      integrate::EnergyMomentumIntegrator integ(sys, m.solver, how);
      integ.set_joint_reactions(true);
      auto s = integ.initial_state();
      std::vector<VecX> out;
      for (int i = 0; i < 100; ++i) {
        integ.step(s);
        out.push_back(s.lambda);
      }
      return out;
    };
    const std::vector<VecX> near = run(0.0), far = run(100.0);
    double worst = 0.0, size = 0.0;
    for (std::size_t k = 0; k < near.size(); ++k) {
      ASSERT_GT(near[k].size(), 0);
      ASSERT_EQ(far[k].size(), near[k].size());
      worst = std::max(worst, (far[k] - near[k]).lpNorm<Eigen::Infinity>());
      size = std::max(size, near[k].lpNorm<Eigen::Infinity>());
    }
    EXPECT_GT(size, 0.1);
    EXPECT_LT(worst, 1e-12 * size) << (how == integrate::ReducedSolve::blocks ? "blocks" : "tree");
  }
}
