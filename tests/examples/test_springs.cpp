// Spring–dampers between material points (elements/point_spring_damper.hpp, model `springs`):
// the free flight of two rigid bodies and a Kirchhoff–Love plate linked by springs
// (examples/springs_free_flight) conserves energy and both momenta to round-off in all three
// energy–momentum formulations, which agree; with dampers the energy lost is the dissipated
// work, momenta still kept; the reader's located errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "isoflex/elements/point_spring_damper.hpp"
#include "isoflex/io/model_reader.hpp"
#include "isoflex/system/system.hpp"
#include "support/examples.hpp"
#include "support/trajectory.hpp"

using namespace isoflex;
using F = model::Formulation;

namespace {

std::string example() {
  return test::example_text("springs_free_flight", "model.yaml");
}

model::Model flight(const std::string& text, double t_end) {
  model::Model m = io::read_model_string(text, "model.yaml");
  m.solver.t_end = t_end;
  return m;
}

std::string reader_error(const std::string& text) {
  try {
    io::read_model_string(text, "m.yaml");
  } catch (const std::exception& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace

TEST(SpringsFreeFlight, CompilesThreeSpringsOnTheirPoints) {
  const auto sys = system::System::compile(flight(example(), 2.0));
  ASSERT_EQ(sys.springs().size(), 3u);
  const auto& s = sys.springs()[0];
  EXPECT_EQ(s.name, "a_plate");
  const auto& e = dynamic_cast<const elements::PointSpringDamper&>(
      *sys.elements()[static_cast<std::size_t>(s.element_index)]);
  // Body a's point (0.1, 0, 0) at (−0.5, 0, 0), the plate's corner at (0, −0.25, 0).
  EXPECT_NEAR(e.length(sys.stacked(sys.q0(), e.nodes())), std::hypot(0.5, 0.25), 1e-14);
  EXPECT_DOUBLE_EQ(e.law().free_length, 0.4);
  EXPECT_DOUBLE_EQ(e.law().stiffness, 200.0);
  EXPECT_FALSE(e.viscous());
}

TEST(SpringsFreeFlight, ConservesEnergyAndMomentaInEveryFormulation) {
  const model::Model m = flight(example(), 2.0);
  std::vector<std::vector<Vec3>> corner;
  for (F f : {F::reparametrized, F::constrained, F::nullspace}) {
    const test::Trajectory r = test::simulate(m, f);
    const test::Drift d = test::drift_after(r, 0.0);
    EXPECT_LT(d.energy, 1e-12) << static_cast<int>(f);
    EXPECT_LT(d.p, 1e-11) << static_cast<int>(f);
    EXPECT_LT(d.L, 1e-11) << static_cast<int>(f);
    // The springs do work: the potential energy changes by most of the total.
    double vmin = 1e300, vmax = -1e300;
    for (const auto& s : r.snapshots) {
      vmin = std::min(vmin, s.potential_energy);
      vmax = std::max(vmax, s.potential_energy);
    }
    EXPECT_GT(vmax - vmin, 0.5 * r.snapshots.front().total_energy);
    corner.push_back(r.probe("plate_corner"));
  }
  for (std::size_t k = 1; k < corner.size(); ++k)
    for (std::size_t i = 0; i < corner[0].size(); ++i)
      EXPECT_LT((corner[k][i] - corner[0][i]).norm(), 1e-8) << k << " " << i;
}

TEST(SpringsFreeFlight, DampersDissipateWhatTheEnergyLosesAndKeepMomenta) {
  std::string text = example();
  for (const char* k : {"stiffness: 200\n", "stiffness: 150\n", "stiffness: 50\n"})
    text = test::replaced(text, k, std::string(k) + "    damping: 3\n");
  const model::Model m = flight(text, 2.0);
  for (F f : {F::reparametrized, F::constrained}) {
    const test::Trajectory r = test::simulate(m, f);
    const auto& s = r.snapshots;
    const double E0 = s.front().total_energy;
    EXPECT_GT(s.back().dissipated_energy, 0.3 * E0);
    for (const auto& x : s)
      EXPECT_LT(std::abs(x.total_energy + x.dissipated_energy - E0) / E0, 1e-12) << x.t;
    const test::Drift d = test::drift_after(r, 0.0);
    EXPECT_LT(d.p, 1e-11);
    EXPECT_LT(d.L, 1e-11);
  }
}

TEST(SpringsReader, LocatedErrors) {
  const std::string head = R"(name: s
bodies:
  - {name: a, mass: 1, inertia: [1, 1, 1], position: [0, 0, 0]}
springs:
)";
  EXPECT_NE(reader_error(head + "  - {a: {body: ground, point: [0, 0, 0]}, b: {body: ground, "
                                "point: [1, 0, 0]}, stiffness: 1}\n")
                .find("m.yaml:5: springs[0]: both ends are on the ground"),
            std::string::npos);
  EXPECT_NE(reader_error(head + "  - {a: {body: a}, b: {body: ground, point: [1, 0, 0]}}\n")
                .find("springs[0]: give stiffness, damping or both"),
            std::string::npos);
  EXPECT_NE(reader_error(head + "  - {a: {body: a}, b: {body: ground, point_local: [1, 0, 0]}, "
                                "stiffness: 1}\n")
                .find("springs[0].b.point_local: the ground has no body coordinates"),
            std::string::npos);
  EXPECT_NE(reader_error(head +
                         "  - {a: {body: a}, b: {body: ground, point: [1, 0, 0]}, stiffness: -1}\n")
                .find("springs[0].stiffness: must be ≥ 0"),
            std::string::npos);
  EXPECT_NE(reader_error(head + "  - {a: {body: c}, b: {body: ground, point: [1, 0, 0]}, "
                                "stiffness: 1}\n")
                .find("springs[0].a.body: no body named \"c\""),
            std::string::npos);
  EXPECT_NE(reader_error(head + "  - {a: {body: a}, b: {body: ground, point: [1, 0, 0]}, "
                                "stiffness: 1, length: 2}\n")
                .find("springs[0].length: unknown key (valid keys: name, a, b, stiffness, damping, "
                      "free_length)"),
            std::string::npos);
}
