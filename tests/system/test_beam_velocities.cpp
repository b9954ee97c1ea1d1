// Initial velocities of beam nodes (model::Beam velocity, angular_velocity, velocity_point,
// node_velocities): a free straight beam 2 long spun about its midpoint, ω = e_z, starts with the
// kinetic energy of that rigid rotation, T = ½ A_ρ ω² ∫s² ds + ½ M_ρ² |ω × d₂|² L (exact for the
// linear elements: φ̇ is linear along the beam, ḋ₂ constant), keeps it (no joints, no loads), and
// a per-node value replaces the field at its node.
#include <gtest/gtest.h>

#include <string>

#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/io/model_reader.hpp"
#include "isoflex/system/system.hpp"

using namespace isoflex;

namespace {

std::string spinning_beam(const std::string& extra = "") {
  return "name: spin\nsolver: {dt: 0.01, t_end: 1}\nbeams:\n"
         "  - name: b\n    points: [[0, 0, 0], [2, 0, 0]]\n    elements: 8\n    d1: [0, 0, 1]\n"
         "    section: {EA: 1.0e4, GA: 1.0e4, EI: 10, GJ: 10, A_rho: 3, M_rho: 0.01}\n"
         "    angular_velocity: [0, 0, 1]\n    velocity_point: [1, 0, 0]\n" +
         extra;
}

}  // namespace

TEST(BeamVelocities, RigidFieldGivesTheRigidKineticEnergyAndKeepsIt) {
  const model::Model m = io::read_model_string(spinning_beam(), "spin.yaml");
  const auto sys = system::System::compile(m);
  EXPECT_EQ(sys.initial_velocity_projection_error(), 0.0);  // admissible as given
  integrate::EnergyMomentumIntegrator integ(sys, m.solver);
  auto s = integ.initial_state();
  const double T = 0.5 * 3.0 * (2.0 / 3.0) + 0.5 * 0.01 * 2.0;  // A_ρ ∫s² ds, M_ρ² L |ḋ₂|²
  const integrate::Snapshot first = integ.snapshot(s, {}, {});
  EXPECT_NEAR(first.kinetic_energy, T, 1e-13 * T);
  EXPECT_LT(first.linear_momentum.norm(), 1e-14);
  for (int i = 0; i < 100; ++i) integ.step(s);
  const integrate::Snapshot last = integ.snapshot(s, {}, {});
  EXPECT_NEAR(last.total_energy, first.total_energy, 1e-12 * T);
  EXPECT_LT((last.angular_momentum - first.angular_momentum).norm(),
            1e-12 * first.angular_momentum.norm());
}

TEST(BeamVelocities, NodeValuesReplaceTheField) {
  const model::Model m = io::read_model_string(
      spinning_beam("    node_velocities: [{node: 8, velocity: [0, 5, 0], angular_velocity: [0, "
                    "0, 1]}]\n"),
      "spin.yaml");
  const auto sys = system::System::compile(m);
  integrate::EnergyMomentumIntegrator integ(sys, m.solver);
  const auto s = integ.initial_state();
  const int tip = sys.beams()[0].nodes.back(), mid = sys.beams()[0].nodes[4];
  EXPECT_LT((s.v.segment<3>(sys.q_offset(tip)) - Vec3(0, 5, 0)).norm(), 1e-14);
  EXPECT_LT(s.v.segment<3>(sys.q_offset(mid)).norm(), 1e-14);  // the field's centre
  EXPECT_THROW(
      io::read_model_string(spinning_beam("    node_velocities: [{node: 9}]\n"), "spin.yaml"),
      io::ModelError);
}
