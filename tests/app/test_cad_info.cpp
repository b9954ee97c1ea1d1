// `isoflex cad-info`: app::cad_info_command on the shared CAD files, and the executable end to end.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "isoflex/app/cad_info.hpp"

namespace {

const std::string kData = ISOFLEX_SOURCE_DIR "/tests/data/cad/";

struct Output {
  int code;
  std::string out, err;
};

Output cad_info(const std::string& file) {
  std::ostringstream out, err;
  const int code = isoflex::app::cad_info_command(file, out, err);
  return {code, out.str(), err.str()};
}

bool contains(const std::string& text, const std::string& what) {
  return text.find(what) != std::string::npos;
}

TEST(CadInfo, QuarterCylinder) {
  const auto r = cad_info(kData + "quarter_cylinder_R1_L2_deg2_fullprec.stp");
  EXPECT_EQ(r.code, 0);
  EXPECT_EQ(r.err, "");
  for (const char* line :
       {"format          STEP, length unit millimetre", "patches         1\n",
        "patch 0  \"patch 0\"  (STEP #", "surface         B-spline, untrimmed, face forward\n",
        "degrees         2 x 2\n", "control points  3 x 3 = 9\n", "knots u         0^3 1^3\n",
        "knots v         0^3 1^3\n", "rational        yes, weights 0.7071067812 .. 1\n",
        "bounding box    [0, 1] x [0, 1] x [0, 2]", "findings        none",
        "summary         1 patch: 0 errors, 0 warnings, 0 notes\n"})
    EXPECT_TRUE(contains(r.out, line)) << "missing: " << line << "\nin:\n" << r.out;
}

TEST(CadInfo, TwoPatchAnglePlateHasDegreeFindings) {
  const auto r = cad_info(kData + "l_angle_plate_2patch_L10_b1_b3_deg1.igs");
  EXPECT_EQ(r.code, 0);
  EXPECT_EQ(r.err, "");
  EXPECT_TRUE(contains(r.out, "format          IGES, length unit millimetre")) << r.out;
  EXPECT_TRUE(contains(r.out, "patches         2\n")) << r.out;
  EXPECT_TRUE(contains(r.out, "patch 1  \"patch 1\"  (IGES entity 128 (D9))")) << r.out;
  EXPECT_TRUE(contains(r.out, "degrees         1 x 1\n")) << r.out;
  EXPECT_TRUE(contains(r.out, "control points  2 x 2 = 4\n")) << r.out;
  EXPECT_TRUE(contains(r.out, "knots u         0^2 1^2\n")) << r.out;
  EXPECT_TRUE(contains(r.out, "rational        no, weights 1 .. 1\n")) << r.out;
  EXPECT_TRUE(contains(r.out, "bounding box    [1, 1] x [0, 10] x [-3, 0]")) << r.out;
  EXPECT_TRUE(contains(r.out, "warning  degree 1 in u")) << r.out;
  EXPECT_TRUE(contains(r.out, "fix: elevate the degree in u")) << r.out;
  EXPECT_TRUE(contains(r.out, "summary         2 patches: 0 errors, 4 warnings, 0 notes\n"))
      << r.out;
}

TEST(CadInfo, MissingFileIsExitCode2WithOneLine) {
  const std::string file = "/no/such/dir/part.stp";
  const auto r = cad_info(file);
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(r.err, "error: " + file + ": no such file\n");
}

// --- The executable ------------------------------------------------------------------------------

// Runs `ENV isoflex ARGS` (ENV: assignments such as "X=1 "), keeping stdout and stderr apart
// (stderr through a temporary file).
Output run(const std::string& args, const std::string& env = "") {
  // One file per process: ctest runs the tests of this suite in parallel processes.
  const std::string err_file =
      ::testing::TempDir() + "isoflex_cad_info_stderr_" + std::to_string(::getpid()) + ".txt";
  const std::string cmd = env + std::string(ISOFLEX_BINARY) + " " + args + " 2>" + err_file;
  Output r{-1, {}, {}};
  FILE* p = popen(cmd.c_str(), "r");
  std::array<char, 4096> buf;
  while (fgets(buf.data(), buf.size(), p)) r.out += buf.data();
  const int status = pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (FILE* e = std::fopen(err_file.c_str(), "r")) {
    while (fgets(buf.data(), buf.size(), e)) r.err += buf.data();
    std::fclose(e);
  }
  std::remove(err_file.c_str());
  return r;
}

TEST(CadInfoBinary, PrintsOnlyTheReport) {
  const auto r = run("cad-info " + kData + "l_angle_plate_2patch_L10_b1_b3_deg1.stp");
  EXPECT_EQ(r.code, 0);
  EXPECT_EQ(r.err, "");
  // No OCCT transfer statistics before or around the report.
  EXPECT_EQ(r.out.rfind("file            ", 0), 0u) << r.out;
  EXPECT_TRUE(contains(r.out, "degrees         1 x 1\n")) << r.out;
  EXPECT_TRUE(contains(r.out, "control points  2 x 2 = 4\n")) << r.out;
}

TEST(CadInfoBinary, MissingFile) {
  const auto r = run("cad-info /no/such/part.igs");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(r.err, "error: /no/such/part.igs: no such file\n");
}

TEST(CadInfoBinary, MalformedFile) {
  const std::string file = ::testing::TempDir() + "isoflex_cad_info_garbage.stp";
  std::ofstream(file) << "this is not a STEP file\n";
  const auto r = run("cad-info " + file);
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(r.err.rfind("error: " + file + ": cannot be read as STEP", 0), 0u) << r.err;
  std::remove(file.c_str());
}

// A file that crashes OpenCASCADE (one CARTESIAN_POINT line deleted) took the process down with
// SIGSEGV; it is an error naming the file and what was being read, exit code 2.
TEST(CadInfoBinary, CrashOfOpenCascadeIsExitCode2) {
  const std::string file = kData + "malformed/step_cartesian_point_12_deleted.stp";
  const auto r = run("cad-info " + file);
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.out, "");
  // SIGSEGV here; SIGABRT under AddressSanitizer, which reports the crash first.
  const std::string head = "error: " + file + ": OpenCASCADE crashed (SIG";
  const std::string tail =
      ") while translating the STEP entities into shapes (the file is probably malformed; the "
      "crash was contained in a child process)\n";
  EXPECT_EQ(r.err.rfind(head, 0), 0u) << r.err;
  ASSERT_GE(r.err.size(), tail.size()) << r.err;
  EXPECT_EQ(r.err.substr(r.err.size() - tail.size()), tail) << r.err;
}

// A read that does not end (a FIFO nobody writes to) is stopped at $ISOFLEX_CAD_TIME_LIMIT.
TEST(CadInfoBinary, TimeLimitFromTheEnvironment) {
  const std::string fifo =
      ::testing::TempDir() + "isoflex_cad_info_fifo_" + std::to_string(::getpid()) + ".stp";
  std::remove(fifo.c_str());
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const auto r = run("cad-info " + fifo, "ISOFLEX_CAD_TIME_LIMIT=0.3 ");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(r.err.rfind("error: " + fifo +
                            ": OpenCASCADE did not finish within 0.3 s while parsing the STEP "
                            "file",
                        0),
            0u)
      << r.err;
  std::remove(fifo.c_str());
}

}  // namespace
