// SIGINT and SIGTERM end `isoflex run` after the step in progress: summary.json says
// "interrupted", results.pvd lists exactly the .vtu files written, history.csv has complete rows,
// no temporary file is left, and the exit code is 128 + the signal (130, 143). Dynamic runs (time
// steps) and static ones (load steps).
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "support/child_process.hpp"
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

// Starts `isoflex ARGS` writing to `out`, sends `sig` once history.csv has 20 rows, and checks
// the exit code and what the run left behind.
void interrupt_run(std::vector<std::string> args, const fs::path& out, int sig, int code) {
  args.insert(args.end(), {"-o", out.string()});
  const fs::path log = out.parent_path() / "log.txt";
  isoflex::test::IsoflexChild child(args, log);
  ASSERT_TRUE(child.started());
  const bool running = isoflex::test::poll_until(
      [&] { return isoflex::test::csv_rows(out / "history.csv") >= 20; }, 10s);
  ASSERT_TRUE(running) << "history.csv did not grow: " << read_text(log);
  child.send(sig);
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
  char last[32];
  std::snprintf(last, sizeof last, "vtk/step_%06d.vtu", steps);
  EXPECT_EQ(listed.back(), last);
}

}  // namespace

TEST(CliInterrupt, SigtermEndsATimeStepRunWithCode143) {
  const isoflex::test::TempDir d(fs::temp_directory_path() /
                                 ("isoflex_cli_sigterm_" + std::to_string(::getpid())));
  std::ofstream(d.path() / "m.yaml") << kLongPendulum;
  interrupt_run({"run", (d.path() / "m.yaml").string()}, d.path() / "out", SIGTERM, 143);
}

TEST(CliInterrupt, SigintEndsATimeStepRunWithCode130) {
  const isoflex::test::TempDir d(fs::temp_directory_path() /
                                 ("isoflex_cli_sigint_" + std::to_string(::getpid())));
  std::ofstream(d.path() / "m.yaml") << kLongPendulum;
  interrupt_run({"run", (d.path() / "m.yaml").string()}, d.path() / "out", SIGINT, 130);
}

// A static run stops between load steps (10 000 of them here).
TEST(CliInterrupt, SigintEndsAStaticRunBetweenLoadSteps) {
  const isoflex::test::TempDir d(fs::temp_directory_path() /
                                 ("isoflex_cli_sigint_static_" + std::to_string(::getpid())));
  interrupt_run({"run", "--static", ISOFLEX_SOURCE_DIR "/examples/beam_roll_up/model_90.yaml",
                 "--dt", "0.0001"},
                d.path() / "out", SIGINT, 130);
}
