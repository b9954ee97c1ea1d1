// SIGINT and SIGTERM end `isoflex run` after the step in progress: summary.json says
// "interrupted", results.pvd lists exactly the .vtu files written, history.csv has complete rows,
// results.h5 ends with the state of the last step done, no temporary file is left, and the exit
// code is 128 + the signal (130, 143). Dynamic runs (time steps) and static ones (load steps).
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "isoflex/io/hdf5_results.hpp"
#include "support/child_process.hpp"
#include "support/examples.hpp"
#include "support/files.hpp"
#include "support/pendulum_yaml.hpp"
#include "support/run_outputs.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using isoflex::test::read_text;

namespace {

// A pendulum for a million steps: far longer than the test waits.
const std::string kLongPendulum = isoflex::test::pendulum_yaml(
    "{dt: 0.001, t_end: 1000}\noutput: {vtk_every: 10}", "probes:\n  - {name: bob, body: bob}\n");

// Starts `isoflex ARGS` writing to `out`, sends `sig` (`copies` times in a row, as a process-group
// kill and a supervisor's forwarding deliver it) once history.csv has `rows` rows, and checks the
// exit code and what the run left behind.
void interrupt_run(std::vector<std::string> args, const fs::path& out, int sig, int code,
                   int copies = 1, int rows = 20) {
  args.insert(args.end(), {"-o", out.string()});
  const fs::path log = out.parent_path() / "log.txt";
  isoflex::test::IsoflexChild child(args, log);
  ASSERT_TRUE(child.started());
  const bool running = isoflex::test::poll_until(
      [&] { return isoflex::test::csv_rows(out / "history.csv") >= rows; }, 30s);
  ASSERT_TRUE(running) << "history.csv did not grow: " << read_text(log);
  for (int i = 0; i < copies; ++i) {
    child.send(sig);
    std::this_thread::sleep_for(10ms);  // delivered one by one, not merged while pending
  }
  const isoflex::test::ChildEnd end = child.wait(10s);
  ASSERT_TRUE(end.exited) << "not ended by exit; killed by signal " << end.signal;
  EXPECT_EQ(end.code, code) << read_text(log);
  EXPECT_NE(
      read_text(log).find(std::string("interrupted by ") + (sig == SIGINT ? "SIGINT" : "SIGTERM")),
      std::string::npos)
      << read_text(log);

  // One history row per snapshot: the initial one and one per step.
  isoflex::test::expect_complete_history(out / "history.csv");
  const int steps = isoflex::test::csv_rows(out / "history.csv") - 1;
  const std::string summary = read_text(out / "summary.json");
  EXPECT_NE(summary.find("\"status\": \"interrupted\""), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"steps\": " + std::to_string(steps) + ","), std::string::npos)
      << summary;
  // The series ends with the last step done, whether or not it was a multiple of vtk_every.
  const auto listed = isoflex::test::expect_consistent_vtk_series(out);
  ASSERT_FALSE(listed.empty());
  // (vtk/step_N.vtu for bodies, vtk/<shell>_N.vtu for a Kirchhoff–Love patch.)
  char last[32];
  std::snprintf(last, sizeof last, "_%06d.vtu", steps);
  const std::string& back = listed.back();
  EXPECT_TRUE(back.size() > 11 && back.compare(back.size() - 11, 11, last) == 0) << back;
}

}  // namespace

TEST(CliInterrupt, SigtermEndsATimeStepRunWithCode143) {
  const isoflex::test::TempDir d(fs::temp_directory_path() /
                                 ("isoflex_cli_sigterm_" + std::to_string(::getpid())));
  std::ofstream(d.path() / "m.yaml") << kLongPendulum;
  interrupt_run({"run", (d.path() / "m.yaml").string()}, d.path() / "out", SIGTERM, 143);
}

// `kill -- -PGID` on `timeout 600 isoflex run …` delivers SIGTERM twice within microseconds (the
// group kill, and timeout's forwarded copy): with the handler reset after the first, the copy
// killed the run before it wrote summary.json (4 of 12 tries).
// The copies come while the step in progress runs: a finer kl_free_plate, ~0.1 s per step.
TEST(CliInterrupt, ADuplicateSigtermDoesNotUndoTheOrderlyEnd) {
  const isoflex::test::TempDir d(fs::temp_directory_path() /
                                 ("isoflex_cli_sigterm_twice_" + std::to_string(::getpid())));
  std::ofstream(d.path() / "m.yaml")
      << isoflex::test::replaced(isoflex::test::example_text("kl_free_plate", "model.yaml"),
                                 "knots_per_span: [7, 3]", "knots_per_span: [15, 7]");
  interrupt_run({"run", (d.path() / "m.yaml").string()}, d.path() / "out", SIGTERM, 143, 3, 4);
}

TEST(CliInterrupt, SigintEndsATimeStepRunWithCode130) {
  const isoflex::test::TempDir d(fs::temp_directory_path() /
                                 ("isoflex_cli_sigint_" + std::to_string(::getpid())));
  std::ofstream(d.path() / "m.yaml") << kLongPendulum;
  interrupt_run({"run", (d.path() / "m.yaml").string()}, d.path() / "out", SIGINT, 130);
}

// results.h5 with every 7th state: closed as at the end of a run, with the state of the last
// step done, whatever its number, the one to restart from.
TEST(CliInterrupt, SigintLeavesAResultsFileEndingWithTheLastStep) {
  const isoflex::test::TempDir d(fs::temp_directory_path() /
                                 ("isoflex_cli_sigint_hdf5_" + std::to_string(::getpid())));
  std::ofstream(d.path() / "m.yaml") << isoflex::test::pendulum_yaml(
      "{dt: 0.001, t_end: 1000}\noutput: {vtk_every: 10, hdf5: true, hdf5_state_every: 7}",
      "probes:\n  - {name: bob, body: bob}\n");
  const fs::path out = d.path() / "out";
  interrupt_run({"run", (d.path() / "m.yaml").string()}, out, SIGINT, 130);
  const std::string history = read_text(out / "history.csv");
  const int steps = isoflex::test::csv_rows(out / "history.csv") - 1;
  const std::vector<int> saved = isoflex::io::saved_steps(out / "results.h5");
  ASSERT_GE(saved.size(), 2u);
  EXPECT_EQ(saved.back(), steps);
  EXPECT_EQ(saved[1], 7);
  // Its t is that of the last history row.
  const std::string last_row = history.substr(history.rfind('\n', history.size() - 2) + 1);
  char t[32];
  std::snprintf(t, sizeof t, "%.17g,",
                isoflex::io::read_saved_state(out / "results.h5", steps).state.t);
  EXPECT_EQ(last_row.rfind(t, 0), 0u) << last_row;
}

// A static run stops between load steps (10 000 of them here).
TEST(CliInterrupt, SigintEndsAStaticRunBetweenLoadSteps) {
  const isoflex::test::TempDir d(fs::temp_directory_path() /
                                 ("isoflex_cli_sigint_static_" + std::to_string(::getpid())));
  interrupt_run({"run", "--static", ISOFLEX_SOURCE_DIR "/examples/beam_roll_up/model_90.yaml",
                 "--dt", "0.0001"},
                d.path() / "out", SIGINT, 130);
}
