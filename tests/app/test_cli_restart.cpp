// results.h5 (output.hdf5) and `isoflex run --restart FILE --from-step N`: a run restarted from
// a saved step continues bit for bit like the run that was not interrupted — the same text in
// every CSV row after step N and the same final state — for the energy–momentum formulations, the
// DAE schemes (their q̈, auxiliary acceleration and qₙ₋₁, vₙ₋₁ are in the state), a
// Kirchhoff–Love patch and a subdivided step; and a file that cannot serve is refused with exit
// code 2 and a message naming it, before anything is written.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "isoflex/io/hdf5_results.hpp"
#include "support/cli.hpp"
#include "support/files.hpp"
#include "support/pendulum_yaml.hpp"

namespace fs = std::filesystem;
using isoflex::test::read_text;

namespace {

using Result = isoflex::test::CliResult;

const std::string kExamples = ISOFLEX_SOURCE_DIR "/examples/";
const std::string kSliderCrank = kExamples + "slider_crank_flexible/model.yaml";

fs::path temp_dir(const std::string& name) {
  return isoflex::test::temp_dir("isoflex_cli_restart_", name);
}

Result run(const std::string& args) {
  return isoflex::test::run_isoflex(args);
}

// The lines of a text file.
std::vector<std::string> lines(const fs::path& p) {
  std::vector<std::string> out;
  std::ifstream in(p);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

// `restarted`'s rows (after its header) are the last rows of `full`, character for character, and
// the headers agree.
void expect_same_tail(const fs::path& full, const fs::path& restarted) {
  const auto a = lines(full), b = lines(restarted);
  ASSERT_FALSE(b.empty()) << restarted;
  ASSERT_LE(b.size(), a.size()) << restarted;
  EXPECT_EQ(a.front(), b.front()) << restarted;
  const std::size_t offset = a.size() - b.size();
  for (std::size_t k = 1; k < b.size(); ++k)
    ASSERT_EQ(a[offset + k], b[k]) << restarted << " row " << k;
}

// Every field of two states, exactly.
void expect_same_state(const isoflex::integrate::State& a, const isoflex::integrate::State& b) {
  EXPECT_EQ(a.step, b.step);
  EXPECT_EQ(a.t, b.t);
  EXPECT_EQ(a.grid_start, b.grid_start);
  EXPECT_EQ(a.grid_dt, b.grid_dt);
  EXPECT_EQ(a.grid_steps, b.grid_steps);
  EXPECT_EQ(a.last_dt, b.last_dt);
  EXPECT_EQ(a.last_start, b.last_start);
  EXPECT_EQ(a.dissipated, b.dissipated);
  EXPECT_EQ(a.external_work, b.external_work);
  EXPECT_EQ(a.driver_work, b.driver_work);
  for (const auto& [name, x, y] :
       {std::tuple{"q", &a.q, &b.q}, std::tuple{"v", &a.v, &b.v},
        std::tuple{"last_unknowns", &a.last_unknowns, &b.last_unknowns},
        std::tuple{"a", &a.a, &b.a}, std::tuple{"aux", &a.aux, &b.aux},
        std::tuple{"lambda", &a.lambda, &b.lambda}, std::tuple{"q_prev", &a.q_prev, &b.q_prev},
        std::tuple{"v_prev", &a.v_prev, &b.v_prev}}) {
    ASSERT_EQ(x->size(), y->size()) << name;
    for (Eigen::Index i = 0; i < x->size(); ++i)
      ASSERT_EQ((*x)(i), (*y)(i)) << name << "[" << i << "]";
  }
}

struct Case {
  const char* name;
  std::string model;
  std::string options;  // --set … of both runs
  int from_step;
};

std::ostream& operator<<(std::ostream& os, const Case& c) {
  return os << c.name;
}

class CliRestart : public ::testing::TestWithParam<Case> {};

}  // namespace

TEST_P(CliRestart, ContinuesBitForBitLikeTheUninterruptedRun) {
  const Case& c = GetParam();
  const fs::path d = temp_dir(c.name);
  const std::string common =
      c.model + " --set output.hdf5=true --set output.vtk_every=0 " + c.options;
  const Result full = run("run " + common + " -o " + (d / "full").string());
  ASSERT_EQ(full.code, 0) << full.out;
  const fs::path source = d / "full/results.h5";
  const std::vector<int> saved = isoflex::io::saved_steps(source);
  ASSERT_FALSE(saved.empty());
  const int last = saved.back();

  const Result restarted =
      run("run " + common + " -o " + (d / "restarted").string() + " --restart " + source.string() +
          " --from-step " + std::to_string(c.from_step));
  ASSERT_EQ(restarted.code, 0) << restarted.out;
  EXPECT_NE(restarted.out.find("restart: step " + std::to_string(c.from_step)), std::string::npos)
      << restarted.out;
  // The restarted history starts with step N's row, the same row as in the full run.
  EXPECT_EQ(lines(d / "restarted/history.csv").size(),
            lines(d / "full/history.csv").size() - static_cast<std::size_t>(c.from_step));
  for (const char* csv :
       {"history.csv", "probes.csv", "reactions.csv", "resultants.csv", "forces.csv"})
    if (fs::exists(d / "full" / csv)) expect_same_tail(d / "full" / csv, d / "restarted" / csv);

  const fs::path again = d / "restarted/results.h5";
  const std::vector<int> continued = isoflex::io::saved_steps(again);
  ASSERT_FALSE(continued.empty());
  EXPECT_EQ(continued.front(), c.from_step);
  EXPECT_EQ(continued.back(), last);
  expect_same_state(isoflex::io::read_saved_state(source, last).state,
                    isoflex::io::read_saved_state(again, last).state);
  // The file's step N and the restarted run's first state are the same state.
  expect_same_state(isoflex::io::read_saved_state(source, c.from_step).state,
                    isoflex::io::read_saved_state(again, c.from_step).state);

  const std::string summary = read_text(d / "restarted/summary.json");
  EXPECT_NE(summary.find("\"restart\": {\"file\": \"" + source.string() +
                         "\", \"from_step\": " + std::to_string(c.from_step) + "}"),
            std::string::npos)
      << summary;
  // The energy reference stays that of t = 0.
  const auto energy_initial = [](const std::string& s) {
    const auto at = s.find("\"energy_initial\": ");
    return s.substr(at, s.find(',', at) - at);
  };
  EXPECT_EQ(energy_initial(summary), energy_initial(read_text(d / "full/summary.json")));
  fs::remove_all(d);
}

INSTANTIATE_TEST_SUITE_P(
    Schemes, CliRestart,
    ::testing::Values(
        Case{"reparametrized", kSliderCrank, "--set solver.t_end=0.3", 13},
        Case{"constrained", kSliderCrank, "--set solver.t_end=0.2 --formulation constrained", 9},
        Case{"nullspace", kExamples + "four_bar/model.yaml",
             "--set solver.t_end=0.5 --formulation nullspace", 21},
        Case{"generalized_alpha", kSliderCrank,
             "--set solver.t_end=0.3 --set solver.integrator=generalized_alpha", 13},
        Case{"bdf2", kSliderCrank, "--set solver.t_end=0.3 --set solver.integrator=bdf2", 13},
        // A Kirchhoff–Love plate (AF-D interface rows) by generalized-α.
        Case{"kl_patch", kExamples + "kl_hinged_plate/model.yaml", "--set solver.t_end=0.2", 9},
        // Steps that fail with 3 iterations are halved: step 11 ends a grid of dt / 8 steps.
        Case{"subdivided", kSliderCrank,
             "--set solver.t_end=1 --set solver.dt=0.05 --set solver.max_iterations=3", 11},
        // From step 0 of a run that starts from the static equilibrium (not found again), with
        // Kelvin–Voigt damping (State::dissipated).
        Case{"from_equilibrium", kExamples + "viscoelastic_beam_release/model.yaml",
             "--set solver.t_end=0.2", 0},
        // The energy–momentum step with numerical dissipation needs qₙ₋₁ (State::q_prev).
        Case{"numerical_dissipation", kExamples + "intersecting_shells/model.yaml",
             "--set solver.t_end=0.3 --set solver.numerical_dissipation=0.05", 7},
        // Every 4th state and the last one.
        Case{"state_every", kSliderCrank, "--set solver.t_end=0.3 --set output.hdf5_state_every=4",
             8}),
    [](const ::testing::TestParamInfo<Case>& info) { return std::string(info.param.name); });

// The saved step of the subdivided case lies inside a halved step's grid: the restart has to
// carry it (State::grid_*, last_dt), or its times would differ in the last digits.
TEST(CliRestartFile, TheSubdividedCaseRestartsInsideAFinerGrid) {
  const fs::path d = temp_dir("grid");
  const Result r = run("run " + kSliderCrank +
                       " --set output.hdf5=true --set output.vtk_every=0 --set solver.t_end=1 "
                       "--set solver.dt=0.05 --set solver.max_iterations=3 -o " +
                       (d / "out").string());
  ASSERT_EQ(r.code, 0) << r.out;
  const isoflex::integrate::State s = isoflex::io::read_saved_state(d / "out/results.h5", 11).state;
  EXPECT_LT(s.last_dt, 0.05);
  fs::remove_all(d);
}

namespace {

// A run that would write `out` given `args`: exit code 2, the message, and no output folder.
void expect_refused(const std::string& args, const fs::path& out, const std::string& message) {
  const Result r = run(args + " -o " + out.string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find(message), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(out)) << "nothing is written for bad input";
}

}  // namespace

TEST(CliRestartFile, AFileThatCannotServeIsRefusedWithExitCode2) {
  const fs::path d = temp_dir("refused");
  const Result r = run("run " + kSliderCrank +
                       " --set output.hdf5=true --set output.vtk_every=0 --set solver.t_end=0.3 "
                       "--set output.hdf5_state_every=4 -o " +
                       (d / "src").string());
  ASSERT_EQ(r.code, 0) << r.out;
  const std::string file = (d / "src/results.h5").string();
  const fs::path out = d / "out";
  const std::string run_crank = "run " + kSliderCrank + " --set output.vtk_every=0";

  expect_refused(run_crank + " --restart " + (d / "none.h5").string() + " --from-step 4", out,
                 "error: --restart: " + (d / "none.h5").string() + ": no such file");
  expect_refused(run_crank + " --restart " + kSliderCrank + " --from-step 4", out,
                 "error: --restart: " + kSliderCrank + ": not an HDF5 file");
  // Steps 0, 4, …, 28 and the last, 30.
  expect_refused(run_crank + " --restart " + file + " --from-step 3", out,
                 "error: --restart: " + file +
                     ": no state of step 3 saved; the file has the states of steps 0 to 28 every "
                     "4, and 30");
  // Another model: its sizes, with the dataset.
  std::ofstream(d / "pendulum.yaml") << isoflex::test::pendulum_yaml("{dt: 0.01, t_end: 0.3}");
  expect_refused("run " + (d / "pendulum.yaml").string() + " --restart " + file + " --from-step 8",
                 out,
                 "error: --restart: " + file + ": /steps/000000008/q: 468 entries, the model " +
                     (d / "pendulum.yaml").string() + " needs 12");
  expect_refused(run_crank + " --restart " + file + " --from-step 8 --set solver.t_end=0.05", out,
                 "is at t = 0.080000000000000002, t_end is 0.050000000000000003: no step left");
  // Both options or neither.
  expect_refused(run_crank + " --restart " + file, out, "--restart requires --from-step");
  expect_refused(run_crank + " --from-step 8", out, "--from-step requires --restart");
  // A static run is not continued.
  const Result statics = run("run --static " + kExamples +
                             "beam_roll_up/model_90.yaml --set output.hdf5=true "
                             "--set output.vtk_every=0 -o " +
                             (d / "static").string());
  ASSERT_EQ(statics.code, 0) << statics.out;
  const std::string roll_up = kExamples + "beam_roll_up/model_90.yaml";
  expect_refused("run " + roll_up + " --restart " + file + " --from-step 8", out,
                 "error: --restart: continues a dynamic run; this is a static analysis");
  expect_refused("run " + roll_up + " --set solver.analysis=dynamic --restart " +
                     (d / "static/results.h5").string() + " --from-step 1",
                 out, "holds a static run; only dynamic runs can be continued");
  fs::remove_all(d);
}

// Restarting into the folder of the file itself with results.h5 on would truncate the file being
// read: refused, the file unchanged. Without results.h5 the run goes there like any other and
// leaves the file alone.
TEST(CliRestartFile, TheFileItReadsIsNotOverwritten) {
  const fs::path d = temp_dir("same_folder");
  const std::string args = "run " + kSliderCrank +
                           " --set output.vtk_every=0 --set solver.t_end=0.2 -o " +
                           (d / "out").string();
  ASSERT_EQ(run(args + " --set output.hdf5=true").code, 0);
  const fs::path file = d / "out/results.h5";
  const auto size = fs::file_size(file);
  const auto time = fs::last_write_time(file);

  const Result same =
      run(args + " --set output.hdf5=true --restart " + file.string() + " --from-step 10");
  EXPECT_EQ(same.code, 2) << same.out;
  EXPECT_NE(same.out.find("error: --restart " + file.string() +
                          ": this run would write its results.h5 over it; give another output "
                          "folder (-o)"),
            std::string::npos)
      << same.out;
  EXPECT_EQ(fs::file_size(file), size);
  EXPECT_EQ(fs::last_write_time(file), time);

  const Result csv_only = run(args + " --restart " + file.string() + " --from-step 10");
  EXPECT_EQ(csv_only.code, 0) << csv_only.out;
  EXPECT_EQ(fs::last_write_time(file), time);
  EXPECT_EQ(isoflex::io::saved_steps(file).size(), 21u);
  fs::remove_all(d);
}
