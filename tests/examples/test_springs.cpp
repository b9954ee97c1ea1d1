// Spring–dampers between material points (elements/point_spring_damper.hpp, model `springs`):
// the free flight of two rigid bodies and a Kirchhoff–Love plate linked by springs
// (examples/springs_free_flight) conserves energy and both momenta to round-off in all three
// energy–momentum formulations, which agree; with dampers the energy lost is the dissipated
// work, momenta still kept; the reader's located errors.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "isoflex/elements/point_spring_damper.hpp"
#include "isoflex/integrate/static_equilibrium.hpp"
#include "isoflex/io/model_reader.hpp"
#include "isoflex/system/system.hpp"
#include "support/cli.hpp"
#include "support/examples.hpp"
#include "support/files.hpp"
#include "support/models.hpp"
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
  EXPECT_NE(
      reader_error(head + "  - {a: {body: a}, b: {body: ground, point: [1, 0, 0]}}\n")
          .find("springs[0]: give stiffness, damping (or stiffness_law, damping_law), actuator or "
                "several"),
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
                      "free_length, stiffness_law, damping_law, actuator)"),
            std::string::npos);
}

// Through the CLI: check lists the springs; forces.csv has one row per spring and snapshot with
// N = k (ζ − L) + c ζ̇, and history.csv the dissipated energy when a spring damps.
TEST(SpringsFreeFlight, CliListsTheSpringsAndWritesTheirForces) {
  const test::TempDir dir(test::temp_dir("isoflex_", "springs_cli"));
  const std::string model = (dir.path() / "m.yaml").string();
  test::write_text(model, test::replaced(test::replaced(example(), "t_end: 2", "t_end: 0.1"),
                                         "stiffness: 50\n", "stiffness: 50\n    damping: 0.5\n"));
  const auto c = test::run_isoflex("check " + model);
  ASSERT_EQ(c.code, 0) << c.out;
  EXPECT_NE(c.out.find("spring           a_plate: stiffness 200, damping 0, free length 0.4, "
                       "length at t = 0 0.559017"),
            std::string::npos)
      << c.out;
  EXPECT_NE(c.out.find("spring           a_b: stiffness 50, damping 0.5, free length 2"),
            std::string::npos);
  const auto r = test::run_isoflex("run " + model + " -o " + (dir.path() / "out").string());
  ASSERT_EQ(r.code, 0) << r.out;
  std::istringstream forces(test::read_text((dir.path() / "out" / "forces.csv").string()));
  std::string line;
  std::getline(forces, line);
  EXPECT_EQ(line, "t,spring,length,elongation,rate,force");
  int rows = 0;
  while (std::getline(forces, line)) {
    std::istringstream f(line);
    std::string t, name, length, elongation, rate, force;
    std::getline(f, t, ',');
    std::getline(f, name, ',');
    std::getline(f, length, ',');
    std::getline(f, elongation, ',');
    std::getline(f, rate, ',');
    std::getline(f, force, ',');
    const double k = name == "a_plate" ? 200 : name == "plate_b" ? 150 : 50;
    const double c = name == "a_b" ? 0.5 : 0.0;
    const double L = name == "a_plate" ? 0.4 : name == "plate_b" ? 0.5 : 2.0;
    EXPECT_NEAR(std::stod(length) - L, std::stod(elongation), 1e-14) << line;
    EXPECT_NEAR(std::stod(force), k * std::stod(elongation) + c * std::stod(rate), 1e-12) << line;
    ++rows;
  }
  EXPECT_EQ(rows, 3 * 11);  // 3 springs, the start and 10 steps
  const std::string history = test::read_text((dir.path() / "out" / "history.csv").string());
  EXPECT_NE(history.find(",residual,dissipated_energy\n"), std::string::npos);
}

namespace {

// A cantilever (beam_roll_up's section, L = 12, 32 elements) with a tip force F_z = 1 in a linear
// static analysis, optionally a spring from its tip to the ground point 1 below it (unstretched):
// the tip's u_z.
double cantilever_tip(const std::string& spring) {
  const std::string text = test::cantilever_yaml(32, "[0, 0, \"t\"]", spring);
  const model::Model m = io::read_model_string(text, "m.yaml");
  const auto sys = system::System::compile(m);
  integrate::StaticEquilibrium eq(sys, m.solver);
  const VecX q = eq.solve().x.head(sys.n());
  const auto& p = sys.probes().front();
  return (sys.probe_point(q, p) - sys.probe_point(sys.q0(), p)).z();
}

}  // namespace

// In a linear static analysis an unstretched spring along z adds k to the tip's stiffness in z
// exactly (its transverse stiffness k (1 − L/ζ) is 0): u = F / (F/u₀ + k) with u₀ the tip
// displacement without it, whatever the beam's discretization. To 10⁻⁹ of u: the two linear
// solves' round-off reached 1.1·10⁻¹⁰ on an AVX-512 machine (OpenBLAS, under CHOLMOD, picks its
// kernels at run time), against below 10⁻¹⁰ on the machines before.
TEST(SpringsStatic, SpringAtACantileverTipAddsItsStiffness) {
  const double u0 = cantilever_tip("");
  EXPECT_NEAR(u0, 12.0 * 12.0 * 12.0 / 300.0, 0.01 * 5.76);  // F L³/(3 EI), shear and h aside
  for (const double k : {0.05, 0.5, 5.0}) {
    const double u = cantilever_tip(fmt::format(
        "springs:\n  - {{a: {{body: \"beam[32]\"}}, b: {{body: ground, point: [12, 0, -1]}}, "
        "stiffness: {}}}\n",
        k));
    EXPECT_NEAR(u, 1.0 / (1.0 / u0 + k), 1e-9 * std::abs(u)) << k;
  }
}
