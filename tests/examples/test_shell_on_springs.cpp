// A Kirchhoff–Love plate on four spring–dampers on a rigid frame that slides on a prismatic guide
// (examples/shell_on_springs): without dampers energy is conserved to round-off in the
// formulations, with them total + dissipated energy; the guide's reaction has no component along
// its axis and a moment from the plate's tilt.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <regex>
#include <string>

#include "isoflex/io/model_reader.hpp"
#include "support/examples.hpp"
#include "support/trajectory.hpp"

using namespace isoflex;
using F = model::Formulation;

namespace {

model::Model shell_on_springs(bool dampers, double t_end) {
  std::string text = test::example_text("shell_on_springs", "model.yaml");
  if (!dampers) text = std::regex_replace(text, std::regex("damping: [0-9]+"), "damping: 0");
  model::Model m = io::read_model_string(text, "model.yaml");
  m.solver.t_end = t_end;
  return m;
}

}  // namespace

TEST(ShellOnSprings, WithoutDampersEnergyIsConservedInTheFormulations) {
  const model::Model m = shell_on_springs(false, 0.5);
  for (F f : {F::reparametrized, F::constrained, F::nullspace}) {
    const test::Trajectory r = test::simulate(m, f);
    double drift = 0.0, vmax = 0.0;
    const double E0 = r.snapshots.front().total_energy;
    for (const auto& s : r.snapshots) {
      drift = std::max(drift, std::abs(s.total_energy - E0) / E0);
      vmax = std::max(vmax, s.potential_energy);
      EXPECT_EQ(s.dissipated_energy, 0.0);
    }
    EXPECT_LT(drift, 1e-12) << static_cast<int>(f);
    EXPECT_GT(vmax, 0.3 * E0);  // the springs and the plate take up energy
  }
}

TEST(ShellOnSprings, DampersDissipateAndTheGuideCarriesNoAxialForce) {
  const test::Trajectory r = test::simulate(shell_on_springs(true, 1.0), F::reparametrized);
  const auto& s = r.snapshots;
  const double E0 = s.front().total_energy;
  EXPECT_GT(s.back().dissipated_energy, 0.5 * E0);
  double balance = 0.0, axial = 0.0, lateral = 0.0, moment = 0.0;
  for (const auto& x : s) {
    balance = std::max(balance, std::abs(x.total_energy + x.dissipated_energy - E0) / E0);
    for (const auto& g : x.reactions) {
      ASSERT_EQ(g.joint, "guide");
      axial = std::max(axial, std::abs(g.force.z()));
      lateral = std::max(lateral, g.force.head<2>().norm());
      moment = std::max(moment, g.moment.norm());
    }
  }
  EXPECT_LT(balance, 1e-12);
  EXPECT_LT(axial, 1e-12 * std::max(1.0, moment));
  EXPECT_GT(moment, 1.0);  // the plate tilts on the uneven mounts
  EXPECT_GT(lateral, 0.1);
}
