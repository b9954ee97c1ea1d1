// The spatial slider-crank of DNSM-III §5.2 (examples/slider_crank_flexible): the counts of the
// paper, energy conservation to round-off once the load is off (t > 2), constraints at round-off
// at every time node, and the same motion from the constrained and the reparametrized schemes.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/io/model_reader.hpp"

using namespace isoflex;
using F = model::Formulation;

namespace {
const std::string kModel = ISOFLEX_SOURCE_DIR "/examples/slider_crank_flexible/model.yaml";

struct Trajectory {
  std::vector<double> t, energy;
  std::vector<Vec3> connection;  // path of the rigid connection point (probe "connection")
  double max_violation = 0.0;
  int unknowns = 0;
};

Trajectory simulate(F f) {
  auto m = io::read_model(kModel);
  m.solver.formulation = f;
  const auto sys = system::System::compile(m);
  const integrate::EnergyMomentumIntegrator integ(sys, m.solver);
  auto s = integ.initial_state();
  Trajectory r;
  r.unknowns = integ.unknowns();
  const int steps = static_cast<int>(std::lround(m.solver.t_end / m.solver.dt));
  for (int i = 0; i <= steps; ++i) {
    const auto st = i == 0 ? integrate::StepStats{} : integ.step(s);
    const auto snap = integ.snapshot(s, st, {});
    r.t.push_back(snap.t);
    r.energy.push_back(snap.total_energy);
    r.max_violation = std::max(r.max_violation, snap.constraint_violation);
    for (const auto& p : snap.probes)
      if (p.name == "connection") r.connection.push_back(p.position);
  }
  return r;
}

// max |E(t) − E(2)| / |E(2)| over t ≥ 2, when f(t) = 0 (DNSM-III (70)).
double drift_after_load(const Trajectory& r) {
  std::size_t i2 = 0;
  while (r.t[i2] < 2.0 - 1e-9) ++i2;
  double d = 0.0;
  for (std::size_t i = i2; i < r.t.size(); ++i)
    d = std::max(d, std::abs(r.energy[i] - r.energy[i2]) / std::abs(r.energy[i2]));
  return d;
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
  const Trajectory rep = simulate(F::reparametrized);
  const Trajectory con = simulate(F::constrained);
  EXPECT_EQ(rep.unknowns, 214);
  EXPECT_EQ(con.unknowns, 722);
  // The load does work (energy ≈ 4.45e3 at t = 2), then the system is conservative.
  EXPECT_GT(rep.energy[200], 1e3);
  EXPECT_LT(drift_after_load(rep), 1e-10);
  EXPECT_LT(drift_after_load(con), 1e-10);
  // Constraints (internal and joints) at round-off at every time node: coordinates are O(5).
  EXPECT_LT(rep.max_violation, 1e-13);
  EXPECT_LT(con.max_violation, 1e-13);
  // The same motion: the path of the connection point, max over all time nodes.
  ASSERT_EQ(rep.connection.size(), con.connection.size());
  double diff = 0.0, travel = 0.0;
  for (std::size_t i = 0; i < rep.connection.size(); ++i) {
    diff = std::max(diff, (rep.connection[i] - con.connection[i]).norm());
    travel = std::max(travel, (rep.connection[i] - rep.connection[0]).norm());
  }
  EXPECT_LT(diff, 1e-6);
  EXPECT_GT(travel, 1.0);  // it does move: the crank swings (Fig. 5)
}
