// The spatial slider-crank of DNSM-III §5.2 (examples/slider_crank_flexible): the counts of the
// paper, energy conservation to round-off once the load is off (t > 2), constraints at round-off
// at every time node, and the same motion from the constrained and the reparametrized schemes.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/io/model_reader.hpp"
#include "support/sanitizers.hpp"
#include "support/trajectory.hpp"

using namespace isoflex;
using F = model::Formulation;

namespace {
const std::string kModel = ISOFLEX_SOURCE_DIR "/examples/slider_crank_flexible/model.yaml";

test::Trajectory simulate(F f) {
  return test::simulate(io::read_model(kModel), f);
}

// max |E(t) − E(2)| / |E(2)| over t ≥ 2, when f(t) = 0 (DNSM-III (70)).
double drift_after_load(const test::Trajectory& r) {
  const auto& s = r.snapshots;
  const std::size_t i2 = r.first_at(2.0);
  double d = 0.0;
  for (std::size_t i = i2; i < s.size(); ++i)
    d = std::max(d,
                 std::abs(s[i].total_energy - s[i2].total_energy) / std::abs(s[i2].total_energy));
  return d;
}

double max_violation(const test::Trajectory& r) {
  double v = 0.0;
  for (const auto& s : r.snapshots) v = std::max(v, s.constraint_violation);
  return v;
}
}  // namespace

// DNSM-III §5.2: n = 468, m = 254, so the constrained scheme solves n + m = 722 unknowns and
// the reparametrized one n − m = 214 (no loop-closing constraint: beams are elastic, not joints).
TEST(SliderCrankFlexible, CountsOfThePaper) {
  const auto m = io::read_model(kModel);
  const auto sys = system::System::compile(m);
  EXPECT_EQ(sys.n(), 468);
  EXPECT_EQ(sys.m_selected(), 254);
  EXPECT_TRUE(sys.redundant_rows().empty());
  EXPECT_TRUE(sys.cut_rows().empty());
  auto s = m.solver;
  for (auto [f, unknowns] : {std::pair{F::constrained, 722}, std::pair{F::nullspace, 468},
                             std::pair{F::reparametrized, 214}}) {
    s.formulation = f;
    EXPECT_EQ(integrate::EnergyMomentumIntegrator(sys, s).unknowns(), unknowns)
        << model::to_string(f);
  }
}

// What a user sees: `isoflex check` prints the same counts.
TEST(SliderCrankFlexible, CheckPrintsTheCounts) {
  const std::string cmd = std::string(ISOFLEX_BINARY) + " check " + kModel + " 2>&1";
  std::FILE* p = popen(cmd.c_str(), "r");
  ASSERT_NE(p, nullptr);
  std::string out;
  char buf[512];
  while (std::fgets(buf, sizeof buf, p)) out += buf;
  EXPECT_EQ(pclose(p), 0) << out;
  EXPECT_NE(out.find("n                468"), std::string::npos) << out;
  EXPECT_NE(out.find("m                254"), std::string::npos) << out;
  EXPECT_NE(out.find("constrained 722, nullspace 468, reparametrized 214"), std::string::npos)
      << out;
}

// The whole 10 s run with both schemes (Δt = 0.01, Newton increment tolerance 1e-12).
TEST(SliderCrankFlexible, ConservesEnergyAfterTheLoadAndBothSchemesAgree) {
  ISOFLEX_SKIP_LONG_RUN_UNDER_ASAN();
  const test::Trajectory rep = simulate(F::reparametrized);
  const test::Trajectory con = simulate(F::constrained);
  EXPECT_EQ(rep.unknowns, 214);
  EXPECT_EQ(con.unknowns, 722);
  // The load does work (energy ≈ 4.45e3 at t = 2), then the system is conservative.
  EXPECT_GT(rep.snapshots[200].total_energy, 1e3);
  EXPECT_LT(drift_after_load(rep), 1e-10);
  EXPECT_LT(drift_after_load(con), 1e-10);
  // Constraints (internal and joints) at round-off at every time node: coordinates are O(5).
  EXPECT_LT(max_violation(rep), 1e-13);
  EXPECT_LT(max_violation(con), 1e-13);
  // The same motion: the path of the connection point, max over all time nodes.
  const std::vector<Vec3> a = rep.probe("connection"), b = con.probe("connection");
  ASSERT_EQ(a.size(), b.size());
  double diff = 0.0, travel = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    diff = std::max(diff, (a[i] - b[i]).norm());
    travel = std::max(travel, (a[i] - a[0]).norm());
  }
  EXPECT_LT(diff, 1e-6);
  EXPECT_GT(travel, 1.0);  // it does move: the crank swings (Fig. 5)
}

// While the drive pushes (t ≤ 2), the energy grows by exactly the drive's work: with W the
// history's external_work, f_ext(q_{n+½}, t_{n+½})·Δq summed over the steps, E − W stays E(0) to
// round-off in every formulation (measured 3e-14 relative over the 10 s run).
TEST(SliderCrankFlexible, TheLoadsWorkClosesTheEnergyBalance) {
  model::Model m = io::read_model(kModel);
  m.solver.t_end = 1.0;
  for (const F f : {F::reparametrized, F::constrained, F::nullspace}) {
    const test::Trajectory r = test::simulate(m, f);
    double worst = 0.0;
    for (const auto& s : r.snapshots)
      worst = std::max(
          worst, std::abs(s.total_energy - s.external_work - r.snapshots.front().total_energy));
    const double E = r.snapshots.back().total_energy;
    std::printf("  [slider-crank] %s: E(1) %.6g, W(1) %.6g, max |E - W - E0| / E(1) %.2e\n",
                model::to_string(f), E, r.snapshots.back().external_work, worst / E);
    EXPECT_GT(E, 100.0);
    EXPECT_LT(worst / E, 1e-12);
  }
}
