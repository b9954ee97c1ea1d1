// Co-simulation (integrate/cosimulation.hpp, IGA-thesis §6.3.2 Fig. 6.8) on the free flight of
// two rigid bodies and a Kirchhoff–Love plate linked by springs (examples/springs_free_flight):
// the split (the plate and its hidden end probes in one part, the bodies in the other, the
// crossing springs in both with anchors); without crossing springs the parts are independent
// and the co-simulation is the monolithic run; with them its error against the monolithic run
// falls with the macro step H (first order with the constant hold, faster with the linear one),
// and so does its energy error, which the monolithic run does not have; the unsupported
// couplings are located errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "isoflex/integrate/cosimulation.hpp"
#include "isoflex/io/model_reader.hpp"
#include "support/cli.hpp"
#include "support/examples.hpp"
#include "support/files.hpp"
#include "support/trajectory.hpp"

using namespace isoflex;

namespace {

model::Model flight(double t_end, double dt) {
  model::Model m =
      io::read_model_string(test::example_text("springs_free_flight", "model.yaml"), "model.yaml");
  m.solver.t_end = t_end;
  m.solver.dt = dt;
  return m;
}

struct CoRun {
  std::vector<integrate::Snapshot> snapshots;  // at every macro step
};

CoRun cosimulate(model::Model m, double H, model::CoSimulationHold hold) {
  m.solver.cosimulation = model::CoSimulation{H, hold, 0};
  integrate::CoSimulation co(m);
  CoRun r;
  r.snapshots.push_back(co.snapshot({}));
  const int steps = static_cast<int>(std::lround(m.solver.t_end / H));
  for (int k = 0; k < steps; ++k) r.snapshots.push_back(co.snapshot(co.advance()));
  return r;
}

Vec3 probe(const integrate::Snapshot& s, const std::string& name) {
  for (const auto& p : s.probes)
    if (p.name == name) return p.position;
  ADD_FAILURE() << "no probe " << name;
  return Vec3::Zero();
}

double energy_error(const CoRun& r) {
  double e = 0.0;
  for (const auto& s : r.snapshots)
    e = std::max(e, std::abs(s.total_energy - r.snapshots.front().total_energy));
  return e / r.snapshots.front().total_energy;
}

}  // namespace

// max over the common times of the plate corner's and body a's distance from the monolithic run
// (H a multiple of the monolithic dt).
double position_error(const CoRun& r, const test::Trajectory& mono, int micro) {
  double e = 0.0;
  for (std::size_t k = 0; k < r.snapshots.size(); ++k) {
    const auto& s = mono.snapshots.at(k * static_cast<std::size_t>(micro));
    for (const char* name : {"plate_corner", "a_centre"}) {
      Vec3 x = Vec3::Zero();
      for (const auto& p : s.probes)
        if (p.name == name) x = p.position;
      e = std::max(e, (probe(r.snapshots[k], name) - x).norm());
    }
  }
  return e;
}

TEST(CoSimulation, ConvergesToTheMonolithicRunAsTheMacroStepFalls) {
  const double t_end = 0.25;
  for (const auto hold : {model::CoSimulationHold::constant, model::CoSimulationHold::linear}) {
    const bool linear = hold == model::CoSimulationHold::linear;
    std::vector<double> errors, energy;
    for (const double dt : {0.004, 0.002, 0.001, 0.0005}) {
      const model::Model m = flight(t_end, dt);
      const CoRun r = cosimulate(m, dt, hold);
      errors.push_back(position_error(r, test::simulate(m, model::Formulation::reparametrized), 1));
      energy.push_back(energy_error(r));
      std::printf("  [cosim] hold %s, H = dt = %g: position error %.3e, energy error %.3e\n",
                  linear ? "linear" : "constant", dt, errors.back(), energy.back());
    }
    for (std::size_t i = 0; i + 1 < errors.size(); ++i) {
      const double ratio = errors[i] / errors[i + 1];
      std::printf("  [cosim]   ratio %.2f\n", ratio);
      // linear: second order in H; constant: first order.
      EXPECT_GT(ratio, linear ? 3.4 : 1.7);
      EXPECT_LT(ratio, linear ? 4.6 : 2.3);
    }
    // The constant hold keeps the total energy: the serial exchange telescopes (each part keeps
    // its energy with its anchor held, and the crossing springs' energies cancel between the
    // two halves; docs/theory/coupling.md §11). The linear hold does not, and its error falls
    // with H.
    for (std::size_t i = 0; i < energy.size(); ++i) {
      if (linear) {
        EXPECT_GT(energy[i], 1e-6);
        if (i > 0) {
          EXPECT_LT(energy[i], 0.5 * energy[i - 1]);
        }
      } else {
        EXPECT_LT(energy[i], 1e-11);
      }
    }
  }
}

// A macro step of several micro steps: the error grows with H at fixed dt.
TEST(CoSimulation, ErrorGrowsWithTheMacroStepAtAFixedStep) {
  const double dt = 0.001;
  const model::Model m = flight(0.24, dt);
  const test::Trajectory mono = test::simulate(m, model::Formulation::reparametrized);
  double previous = 0.0;
  for (const int micro : {1, 2, 4, 8}) {
    const CoRun r = cosimulate(m, micro * dt, model::CoSimulationHold::linear);
    const double e = position_error(r, mono, micro);
    std::printf("  [cosim] linear, dt %g, H = %g: position error %.3e, energy error %.3e\n", dt,
                micro * dt, e, energy_error(r));
    EXPECT_GT(e, 2.0 * previous);
    previous = e;
  }
}

// Without springs across the split the two parts are independent: the co-simulation is the
// monolithic run.
TEST(CoSimulation, UncoupledPartsAreTheMonolithicRun) {
  model::Model m = flight(0.2, 0.01);
  std::erase_if(m.springs, [](const model::Spring& s) { return s.name != "a_b"; });
  const test::Trajectory mono = test::simulate(m, model::Formulation::reparametrized);
  const CoRun r = cosimulate(m, 0.04, model::CoSimulationHold::linear);
  const double e = position_error(r, mono, 4);
  std::printf("  [cosim] uncoupled: position difference %.2e\n", e);
  EXPECT_LT(e, 1e-13);
  EXPECT_NEAR(r.snapshots.back().total_energy, mono.snapshots.back().total_energy,
              1e-12 * mono.snapshots.back().total_energy);
}

TEST(CoSimulation, CouplingsOtherThanSpringsAreLocatedErrors) {
  const auto error = [](const std::string& extra) -> std::string {
    model::Model m = io::read_model_string(
        test::example_text("springs_free_flight", "model.yaml") + extra, "model.yaml");
    m.solver.cosimulation = model::CoSimulation{0.02, model::CoSimulationHold::linear, 3};
    try {
      integrate::CoSimulation co(m);
    } catch (const std::exception& e) {
      return e.what();
    }
    return "no error";
  };
  EXPECT_NE(error("joints:\n  - {name: pin, type: spherical, body_a: a, body_b: plate, point: "
                  "[0.5, 0, 0]}\n")
                .find("pin: a joint at a shell point couples the shell to the multibody part"),
            std::string::npos);
  EXPECT_NE(error("kl_supports:\n  - {shell: plate, edge: u0, fixed: all, body: a}\n")
                .find("the support attaches 'plate' to the body 'a'"),
            std::string::npos);
}

// What a user sees: `isoflex check` prints the split, `isoflex run` the co-simulated run with
// one history row per macro step and the crossing springs in forces.csv; an H that is not a
// multiple of dt is a located error of the file.
TEST(CoSimulation, CheckAndRunThroughTheCli) {
  const test::TempDir dir(test::temp_dir("isoflex_", "cosimulation_cli"));
  const std::string model = (dir.path() / "m.yaml").string();
  const std::string text =
      test::replaced(test::replaced(test::example_text("springs_free_flight", "model.yaml"),
                                    "t_end: 2", "t_end: 0.2"),
                     "solver:", "solver:\n  cosimulation: {macro_step: 0.02}");
  test::write_text(model, text);
  const auto check = test::run_isoflex("check " + model);
  ASSERT_EQ(check.code, 0) << check.out;
  EXPECT_NE(check.out.find("co-simulation    macro step 0.02 (2 steps of dt), hold linear: shell "
                           "part 72 unknowns, multibody part 12 unknowns, 2 springs across"),
            std::string::npos)
      << check.out;
  const auto run = test::run_isoflex("run " + model + " -o " + (dir.path() / "out").string());
  ASSERT_EQ(run.code, 0) << run.out;
  EXPECT_NE(run.out.find("10 steps, 84 unknowns (reparametrized, co-simulation (H = 0.02, hold "
                         "linear))"),
            std::string::npos)
      << run.out;
  const std::string history = test::read_text((dir.path() / "out" / "history.csv").string());
  EXPECT_EQ(std::count(history.begin(), history.end(), '\n'), 12);  // header, t = 0 … 0.2
  const std::string forces = test::read_text((dir.path() / "out" / "forces.csv").string());
  std::size_t at = forces.size() - 1;  // the last three rows: t = 0.2, the three springs
  for (int k = 0; k < 3; ++k) at = forces.rfind('\n', at - 1);
  const std::string last_rows = forces.substr(at + 1);
  for (const char* s : {",a_plate,", ",plate_b,", ",a_b,"})
    EXPECT_NE(last_rows.find(s), std::string::npos) << s << "\n" << last_rows;
  test::write_text(model, test::replaced(text, "macro_step: 0.02", "macro_step: 0.015"));
  const auto bad = test::run_isoflex("check " + model);
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.out.find("m.yaml:9: solver.cosimulation.macro_step: 0.015 is not a whole "
                         "multiple of solver.dt = 0.01"),
            std::string::npos)
      << bad.out;
}
