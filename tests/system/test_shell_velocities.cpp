// Initial velocities of shell nodes (model::NodeVelocities on `shells` and `kl_shells`): a rigid
// field v + ω × (x − p) is admissible as given — a director node takes ḋ = ω × d (the spin about
// d moves nothing), a control point the velocity of its position (NURBS are affine invariant, so
// the whole surface moves rigidly) — starts with the rigid kinetic energy, keeps it in a load-free
// run, and per-node values replace the field at their nodes.
#include <gtest/gtest.h>

#include <string>

#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/io/model_error.hpp"
#include "isoflex/io/model_reader.hpp"
#include "isoflex/system/system.hpp"

using namespace isoflex;

namespace {

// A free 2 × 1 plate in the xy-plane (4 × 2 elements), h = 0.01, ρ = 1000: m = 20.
std::string director_plate(const std::string& extra) {
  return "name: spin\nsolver: {dt: 0.005, t_end: 1}\nshells:\n"
         "  - name: p\n"
         "    plate: {corners: [[0, 0, 0], [2, 0, 0], [2, 1, 0], [0, 1, 0]], elements: [4, 2]}\n"
         "    material: {E: 1.0e6, nu: 0.3, thickness: 0.01, density: 1000}\n" +
         extra;
}

// The same plate as a free biquadratic Kirchhoff–Love patch.
std::string kl_plate(const std::string& extra) {
  return "name: spin\nsolver: {dt: 0.005, t_end: 1}\n"
         "surfaces:\n"
         "  - {name: s, builtin: {type: rectangle, size: [2, 1]},\n"
         "     refine: {elevate: [1, 1], knots_per_span: [1, 1]}}\n"
         "kl_shells:\n"
         "  - name: p\n    surface: s\n"
         "    material: {E: 1.0e6, nu: 0.3, thickness: 0.01, density: 1000}\n" +
         extra;
}

// ω = (0.3, 0, 1) about the plate's centre plus v = (0.1, 0, 0): T = ½ m |v|² + ½ ωᵀ J ω with
// J = m diag(b²/12, a²/12, (a² + b²)/12) (a = 2, b = 1) — the rotational inertia of the thin
// plate about its centre (the director shell's through-thickness inertia m h²/12 adds
// ½ (m h²/12) |ω_∥|² for the in-plane part of ω, 1.7·10⁻⁶ of T here).
constexpr double kMass = 20.0;
const std::string kField =
    "    velocity: [0.1, 0, 0]\n    angular_velocity: [0.3, 0, 1]\n"
    "    velocity_point: [1, 0.5, 0]\n";
double rigid_kinetic_energy(double h) {
  const double a = 2, b = 1, wx = 0.3, wz = 1.0;
  return 0.5 * kMass * 0.01 +
         0.5 * kMass * (b * b / 12 * wx * wx + (a * a + b * b) / 12 * wz * wz) +
         0.5 * kMass * h * h / 12 * wx * wx;
}

void expect_rigid_start_and_conservation(const std::string& yaml, double h) {
  const model::Model m = io::read_model_string(yaml, "spin.yaml");
  const auto sys = system::System::compile(m);
  EXPECT_LT(sys.initial_velocity_projection_error(), 1e-15);  // admissible as given
  integrate::EnergyMomentumIntegrator integ(sys, m.solver);
  auto s = integ.initial_state();
  const integrate::Snapshot first = integ.snapshot(s, {}, {});
  const double T = rigid_kinetic_energy(h);
  EXPECT_NEAR(first.kinetic_energy, T, 1e-12 * T);
  EXPECT_LT((first.linear_momentum - Vec3(kMass * 0.1, 0, 0)).norm(), 1e-13 * kMass);
  for (int i = 0; i < 40; ++i) integ.step(s);
  const integrate::Snapshot last = integ.snapshot(s, {}, {});
  EXPECT_NEAR(last.total_energy, first.total_energy, 1e-12 * T);
  EXPECT_LT((last.linear_momentum - first.linear_momentum).norm(), 1e-13 * kMass);
  EXPECT_LT((last.angular_momentum - first.angular_momentum).norm(),
            1e-12 * first.angular_momentum.norm());
}

}  // namespace

TEST(ShellVelocities, DirectorShellRigidFieldIsAdmissibleAndKept) {
  expect_rigid_start_and_conservation(director_plate(kField), 0.01);
  // Every node: φ̇ = v + ω × (x − p), ḋ = ω × d.
  const model::Model m = io::read_model_string(director_plate(kField), "spin.yaml");
  const auto sys = system::System::compile(m);
  const Vec3 v(0.1, 0, 0), w(0.3, 0, 1), p(1, 0.5, 0);
  for (int i : sys.shells()[0].nodes) {
    const int o = sys.q_offset(i);
    const Vec3 x = sys.q0().segment<3>(o), d = sys.q0().segment<3>(o + 3);
    EXPECT_LT((sys.v0().segment<3>(o) - (v + w.cross(x - p))).norm(), 1e-15) << i;
    EXPECT_LT((sys.v0().segment<3>(o + 3) - w.cross(d)).norm(), 1e-15) << i;
  }
}

TEST(ShellVelocities, KirchhoffLoveRigidFieldIsAdmissibleAndKept) {
  expect_rigid_start_and_conservation(kl_plate(kField), 0.0);
}

TEST(ShellVelocities, NodeValuesReplaceTheField) {
  const model::Model m = io::read_model_string(
      director_plate(kField + "    node_velocities: [{node: 14, velocity: [0, 0, 2]}]\n"),
      "spin.yaml");
  const auto sys = system::System::compile(m);
  const int corner = sys.shells()[0].nodes[14], next = sys.shells()[0].nodes[13];
  EXPECT_LT((sys.v0().segment<3>(sys.q_offset(corner)) - Vec3(0, 0, 2)).norm(), 1e-15);
  EXPECT_LT(sys.v0().segment<3>(sys.q_offset(corner) + 3).norm(), 1e-15);  // ω = 0 there
  const Vec3 x13 = sys.q0().segment<3>(sys.q_offset(next));
  EXPECT_LT((sys.v0().segment<3>(sys.q_offset(next)) -
             (Vec3(0.1, 0, 0) + Vec3(0.3, 0, 1).cross(x13 - Vec3(1, 0.5, 0))))
                .norm(),
            1e-15);

  const model::Model k = io::read_model_string(
      kl_plate(kField + "    node_velocities: [{node: 0, velocity: [0, 0, 3]}]\n"), "spin.yaml");
  const auto ks = system::System::compile(k);
  const int cp0 = ks.kl_patches()[0].nodes[0];
  EXPECT_LT((ks.v0().segment<3>(ks.q_offset(cp0)) - Vec3(0, 0, 3)).norm(), 1e-15);
}

TEST(ShellVelocities, ReaderLocatesBadNodes) {
  try {
    io::read_model_string(director_plate("    node_velocities: [{node: 15}]\n"), "spin.yaml");
    FAIL() << "no error";
  } catch (const io::ModelError& e) {
    EXPECT_EQ(e.key(), "shells[0].node_velocities[0].node");
    EXPECT_EQ(e.message(), "shell \"p\" has nodes 0 … 14");
  }
  try {
    io::read_model_string(kl_plate("    node_velocities: [{node: 16}]\n"), "spin.yaml");
    FAIL() << "no error";
  } catch (const io::ModelError& e) {
    EXPECT_EQ(e.key(), "kl_shells[0].node_velocities[0].node");
    EXPECT_EQ(e.message(), "kl_shell \"p\" has nodes 0 … 15");
  }
}
