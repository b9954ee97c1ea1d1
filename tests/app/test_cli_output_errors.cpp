// An output file that cannot be written (a directory in its place, a full disk, a folder without
// write permission) ends `isoflex run` with exit code 4 and one error line naming the file and
// the cause; what was written stays valid (complete history rows, a results.pvd listing only
// complete .vtu files) and summary.json says "output_error" where its folder can be written.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "support/cli.hpp"
#include "support/files.hpp"
#include "support/pendulum_yaml.hpp"
#include "support/run_outputs.hpp"

namespace fs = std::filesystem;
using isoflex::test::read_text;

namespace {

const std::string kPendulum = isoflex::test::pendulum_yaml();

fs::path temp_dir(const std::string& name) {
  return isoflex::test::temp_dir("isoflex_cli_output_", name);
}

std::string summary_status(const fs::path& out) {
  const std::string s = read_text(out / "summary.json");
  const auto at = s.find("\"status\": \"");
  if (at == std::string::npos) return "(no status) " + s;
  const auto begin = at + 11;
  return s.substr(begin, s.find('"', begin) - begin);
}

}  // namespace

// A directory where an output file goes: the file cannot be opened (also for root, unlike a
// folder without write permission).
TEST(CliOutputErrors, AnOutputFileThatCannotBeOpenedEndsTheRunWithCode4) {
  for (const char* name : {"history.csv", "results.pvd"}) {
    const fs::path d = temp_dir("open");
    std::ofstream(d / "m.yaml") << kPendulum;
    fs::create_directories(d / "out" / name);
    const auto r = isoflex::test::run_isoflex("run " + (d / "m.yaml").string() + " -o " +
                                              (d / "out").string());
    EXPECT_EQ(r.code, 4) << r.out;
    const std::string expected =
        "error: cannot write " + (d / "out" / name).string() + ": Is a directory";
    EXPECT_NE(r.out.find(expected), std::string::npos) << r.out;
    EXPECT_EQ(summary_status(d / "out"), "output_error");
    EXPECT_NE(read_text(d / "out/summary.json").find(name), std::string::npos)
        << "summary.json's message names the file";
    for (const auto& e : fs::recursive_directory_iterator(d / "out"))
      EXPECT_NE(e.path().extension(), ".tmp") << e.path();
    fs::remove_all(d);
  }
}

// A full disk in the middle of the run, when step 10's .vtu is written (a symbolic link to
// /dev/full in place of its temporary file): the series lists steps 0 … 9, all complete.
TEST(CliOutputErrors, AFullDiskMidRunKeepsTheSeriesValid) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  const fs::path d = temp_dir("full");
  std::ofstream(d / "m.yaml") << kPendulum;
  fs::create_directories(d / "out/vtk");
  fs::create_symlink("/dev/full", d / "out/vtk/step_000010.vtu.tmp");
  const auto r =
      isoflex::test::run_isoflex("run " + (d / "m.yaml").string() + " -o " + (d / "out").string());
  EXPECT_EQ(r.code, 4) << r.out;
  EXPECT_NE(r.out.find("error: cannot write " + (d / "out/vtk/step_000010.vtu").string() +
                       ": No space left on device"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("results up to t = 0.1,"), std::string::npos) << r.out;
  EXPECT_EQ(summary_status(d / "out"), "output_error");
  EXPECT_NE(read_text(d / "out/summary.json").find("\"steps\": 10,"), std::string::npos);
  isoflex::test::expect_complete_history(d / "out/history.csv");
  EXPECT_EQ(isoflex::test::csv_rows(d / "out/history.csv"), 11);  // t = 0 and 10 steps
  const auto listed = isoflex::test::expect_consistent_vtk_series(d / "out");
  ASSERT_EQ(listed.size(), 10u);
  EXPECT_EQ(listed.back(), "vtk/step_000009.vtu");
  fs::remove_all(d);
}

// A disk that fills up while history.csv grows, simulated by a file size limit (ulimit -f, which
// holds for root too): the write that fails may have put part of a row on disk; the file is cut
// back to its last complete row.
TEST(CliOutputErrors, AFullDiskLeavesHistoryWithCompleteRows) {
  const fs::path d = temp_dir("fsize");
  std::ofstream(d / "m.yaml") << kPendulum << "output: {vtk_every: 0}\n";
  // 8 blocks of 512 bytes (dash; bash counts 1024): summary.json fits, 100 history rows do not.
  // SIGXFSZ ignored, so that the write fails with EFBIG instead of killing the process.
  const std::string cmd = "sh -c \"trap '' XFSZ; ulimit -f 8; exec " + std::string(ISOFLEX_BINARY) +
                          " run " + (d / "m.yaml").string() + " -o " + (d / "out").string() +
                          " --t-end 1\" 2>&1";
  std::string out;
  FILE* p = popen(cmd.c_str(), "r");
  ASSERT_NE(p, nullptr);
  for (char buf[4096]; fgets(buf, sizeof buf, p);) out += buf;
  const int status = pclose(p);
  ASSERT_TRUE(WIFEXITED(status)) << out;
  EXPECT_EQ(WEXITSTATUS(status), 4) << out;
  EXPECT_NE(
      out.find("error: cannot write " + (d / "out/history.csv").string() + ": File too large"),
      std::string::npos)
      << out;
  isoflex::test::expect_complete_history(d / "out/history.csv");
  const int rows = isoflex::test::csv_rows(d / "out/history.csv");
  EXPECT_GT(rows, 1);
  EXPECT_LT(rows, 101);
  EXPECT_EQ(summary_status(d / "out"), "output_error");
  fs::remove_all(d);
}

// A folder without write permission (not for root, who may write anyway): nothing can be written,
// summary.json neither; both are reported.
TEST(CliOutputErrors, AReadOnlyOutputFolderIsReported) {
  if (::geteuid() == 0) GTEST_SKIP() << "root writes into read-only folders";
  const fs::path d = temp_dir("readonly");
  std::ofstream(d / "m.yaml") << kPendulum;
  fs::create_directories(d / "out");
  fs::permissions(d / "out", fs::perms::owner_read | fs::perms::owner_exec);
  const auto r =
      isoflex::test::run_isoflex("run " + (d / "m.yaml").string() + " -o " + (d / "out").string());
  fs::permissions(d / "out", fs::perms::owner_all);
  EXPECT_EQ(r.code, 4) << r.out;
  EXPECT_NE(
      r.out.find("error: cannot write " + (d / "out/history.csv").string() + ": Permission denied"),
      std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("error: cannot write " + (d / "out/summary.json").string()),
            std::string::npos)
      << r.out;
  EXPECT_TRUE(fs::is_empty(d / "out"));
  fs::remove_all(d);
}

// results.h5 (output.hdf5) fails like the other outputs: a directory in its place, a disk that
// fills up (ulimit -f; SIGXFSZ ignored so that the write fails with EFBIG) end the run with exit
// code 4 and one line naming the file and the cause (and no crash at exit: HDF5 closing the file
// that failed again).
TEST(CliOutputErrors, AResultsFileThatCannotBeWrittenEndsTheRunWithCode4) {
  const fs::path d = temp_dir("output_error");
  std::ofstream(d / "m.yaml") << isoflex::test::pendulum_yaml("{dt: 0.001, t_end: 2}",
                                                              "output: {hdf5: true}\n");
  fs::create_directories(d / "dir/results.h5");
  const auto r =
      isoflex::test::run_isoflex("run " + (d / "m.yaml").string() + " -o " + (d / "dir").string());
  EXPECT_EQ(r.code, 4) << r.out;
  EXPECT_NE(
      r.out.find("error: cannot write " + (d / "dir/results.h5").string() + ": Is a directory"),
      std::string::npos)
      << r.out;

  const auto full = isoflex::test::run_shell(
      "sh -c \"trap '' XFSZ; ulimit -f 1000; exec " + std::string(ISOFLEX_BINARY) + " run " +
      (d / "m.yaml").string() + " --set output.vtk_every=0 -o " + (d / "full").string() + "\"");
  EXPECT_EQ(full.code, 4) << full.out;
  EXPECT_NE(
      full.out.find("error: cannot write " + (d / "full/results.h5").string() + ": File too large"),
      std::string::npos)
      << full.out;
  EXPECT_NE(read_text(d / "full/summary.json").find("\"status\": \"output_error\""),
            std::string::npos);
  fs::remove_all(d);
}
