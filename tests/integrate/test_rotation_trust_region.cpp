// The trust region of the reparametrized Newton corrections (solver.max_rotation_correction,
// docs/theory/schemes.md §6): which coordinates turn something, and what the limit does on the
// thin plates of DNSM-III §5.3 (examples/intersecting_shells/README.md).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/io/model_reader.hpp"
#include "support/models.hpp"

using namespace isoflex;

namespace {
model::Model example(const std::string& name) {
  return io::read_model(std::string(ISOFLEX_SOURCE_DIR) + "/examples/" + name + "/model.yaml");
}
}  // namespace

TEST(RotationTrustRegion, MarksTheCoordinatesThatTurn) {
  // A free frame: φ̇ then ω among its six velocities.
  const auto flip = system::System::compile(test::free_body_flip());
  ASSERT_EQ(flip.k(), 6);
  EXPECT_EQ(flip.rotation_tree_coordinates(), (std::vector<int>{3, 4, 5}));
  // Tree joints: the revolute crank bearing turns, the prismatic slider guide does not.
  const auto crank = system::System::compile(example("slider_crank_rigid"));
  int prismatic = 0;
  for (const auto& J : crank.joints())
    if (J.tree && J.type == "prismatic") {
      ++prismatic;
      for (int i : crank.rotation_tree_coordinates()) EXPECT_NE(i, J.nu_offset);
    }
  EXPECT_EQ(prismatic, 1);
  EXPECT_EQ(static_cast<int>(crank.rotation_tree_coordinates().size()), crank.k() - prismatic);
  // Free director nodes: two rotation increments each, after their position (the hub plate: the
  // hub's ω, 80 free director nodes, 5 rigid joints without velocities).
  const auto hub = system::System::compile(example("shell_plate_on_hub"));
  ASSERT_EQ(hub.k(), 6 + 5 * 80);
  EXPECT_EQ(static_cast<int>(hub.rotation_tree_coordinates().size()), 3 + 2 * 80);
  for (std::size_t r = 1; r < hub.roots().size(); ++r) {
    const int at = hub.root_nu_offsets()[r];
    EXPECT_TRUE(std::find(hub.rotation_tree_coordinates().begin(),
                          hub.rotation_tree_coordinates().end(),
                          at + 4) != hub.rotation_tree_coordinates().end());
  }
}

// Without the limit, Newton from the start values of the late steps makes corrections of 1–80 rad
// on the 2 mm plates, the exp map wraps them around the sphere, and the start fails; whole steps
// fail and are halved. With it (the default 0.1 rad) a start almost never fails. Measured with
// the exact tangent (solver.mixed_tangent: false): the mixed one leaves the trust region little
// to do before t = 6 (examples/intersecting_shells/README.md).
TEST(RotationTrustRegion, KeepsNewtonOnTheThinPlatesFromFailing) {
  int iterations[2] = {0, 0}, failed[2] = {0, 0}, parts[2] = {0, 0};
  for (int limit = 0; limit < 2; ++limit) {
    auto m = example("intersecting_shells");
    if (limit == 0) m.solver.max_rotation_correction = 0.0;
    m.solver.mixed_tangent = false;
    const auto sys = system::System::compile(m);
    integrate::EnergyMomentumIntegrator integ(sys, m.solver);
    auto s = integ.initial_state();
    for (int i = 0; i < 300; ++i) {  // to t = 6
      const auto st = integ.step(s);
      iterations[limit] += st.iterations;
      failed[limit] += st.failed_starts;
      parts[limit] += st.substeps;
    }
    std::printf("  [limit %s] %d iterations, %d failed starts, %d parts of steps\n",
                limit ? "0.1" : "off", iterations[limit], failed[limit], parts[limit]);
  }
  // Measured: off 2541 iterations, 27 failed starts, 308 parts; 0.1 rad 2291, 3, 300.
  EXPECT_GT(failed[0], 20);
  EXPECT_LE(failed[1], 3);
  EXPECT_GT(parts[0], 300);
  EXPECT_EQ(parts[1], 300);
  EXPECT_LT(iterations[1], 0.95 * iterations[0]);
}
