// io::read_cad on malformed files (tests/data/cad/malformed/, made from the quarter cylinder of
// the shared CAD data; README there): OpenCASCADE's crashes stay in the reading child process and
// become located errors, non-positive weights are errors, bare exception names are wrapped.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "isoflex/io/cad/cad_reader.hpp"
#include "isoflex/io/model_reader.hpp"
#include "support/model_errors.hpp"
#include "support/sanitizers.hpp"

using namespace isoflex;

namespace {

const std::string kData = ISOFLEX_SOURCE_DIR "/tests/data/cad/";
const std::string kBad = kData + "malformed/";

// The message of the CadError read_cad throws for `file`.
std::string cad_error(const std::string& file) {
  try {
    io::read_cad(file);
  } catch (const io::CadError& e) {
    EXPECT_EQ(e.file(), file);
    return e.message();
  }
  return "(no error)";
}

bool contains(const std::string& text, const std::string& what) {
  return text.find(what) != std::string::npos;
}

}  // namespace

// A STEP file with the line of one CARTESIAN_POINT deleted: OCCT 7.6 dereferences the missing
// point during the transfer (SIGSEGV), which took the whole process down. The tests accept any
// signal: under AddressSanitizer the same crash is reported and ends in SIGABRT.
TEST(CadMalformed, StepCrashInOpenCascadeIsALocatedError) {
  const std::string m = cad_error(kBad + "step_cartesian_point_12_deleted.stp");
  EXPECT_TRUE(contains(m, "OpenCASCADE crashed (SIG")) << m;
  EXPECT_TRUE(contains(m, ") while translating the STEP entities into shapes")) << m;
}

// IGES entity 128 with degree 100 in u (the knot and weight counts then no longer match).
TEST(CadMalformed, IgesDegree100CrashIsALocatedError) {
  const std::string m = cad_error(kBad + "iges_128_degree_100.igs");
  EXPECT_TRUE(contains(m, "OpenCASCADE crashed (SIG")) << m;
  EXPECT_TRUE(contains(m, "while parsing the IGES file")) << m;
}

// The process reading a model goes on after a crash of the reader, and reads good files again.
TEST(CadMalformed, ReadingGoesOnAfterACrash) {
  EXPECT_NE(cad_error(kBad + "step_cartesian_point_12_deleted.stp"), "(no error)");
  const io::CadModel m = io::read_cad(kData + "quarter_cylinder_R1_L2_deg2_fullprec.stp");
  ASSERT_EQ(m.patches.size(), 1u);
  EXPECT_EQ(m.patches[0].surface.n_u() * m.patches[0].surface.n_v(), 9);
}

// The same crash through a model file's surfaces[].cad.file: a ModelError at the key.
TEST(CadMalformed, CrashThroughAModelFileIsAModelError) {
  const std::string file = kBad + "step_cartesian_point_12_deleted.stp";
  const std::string e = test::error_of(
      "surfaces:\n"
      "  - name: roof\n"
      "    cad: {file: " +
      file + "}\n");
  EXPECT_TRUE(contains(e, "m.yaml:3: surfaces[0].cad.file: cannot read CAD file \"" + file +
                              "\": OpenCASCADE crashed (SIG"))
      << e;
}

// A read that does not finish: a FIFO nobody writes to blocks OCCT's open for ever. With a time
// limit of 0.3 s the child is stopped and the error says so and where.
TEST(CadMalformed, ReadBeyondTheTimeLimitIsStopped) {
  const std::string fifo =
      ::testing::TempDir() + "isoflex_cad_fifo_" + std::to_string(::getpid()) + ".igs";
  std::filesystem::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  try {
    io::read_cad(fifo, {.time_limit_s = 0.3});
    ADD_FAILURE() << "no error";
  } catch (const io::CadError& e) {
    EXPECT_EQ(e.message().rfind("OpenCASCADE did not finish within 0.3 s while parsing the IGES "
                                "file",
                                0),
              0u)
        << e.message();
  }
  std::filesystem::remove(fifo);
}

// OCCT's IGES parser replaced the weights of such a surface by 1 ("non-rational, fit for a
// Kirchhoff–Love shell": a different surface); its STEP transfer dropped the face ("holds no
// faces").
TEST(CadMalformed, NonPositiveWeightsAreLocatedErrors) {
  EXPECT_EQ(cad_error(kBad + "iges_128_weight_zero.igs"),
            "IGES entity 128 (D3): weight of control point (i, j) = (2, 0) (i along u, from 0) is "
            "0; NURBS weights must be positive");
  EXPECT_EQ(cad_error(kBad + "iges_128_weight_negative.igs"),
            "IGES entity 128 (D3): weight of control point (i, j) = (2, 0) (i along u, from 0) is "
            "-1; NURBS weights must be positive");
  // OCCT's parser sets all weights to 1 below 1e-9, so a tiny positive weight is refused too.
  EXPECT_EQ(cad_error(kBad + "iges_128_weight_1e-12.igs"),
            "IGES entity 128 (D3): weight of control point (i, j) = (2, 0) (i along u, from 0) is "
            "1e-12; OpenCASCADE's IGES reader would replace all weights of the surface by 1 "
            "(weights below 1e-9)");
  const std::string zero = cad_error(kBad + "step_weight_zero.stp");
  EXPECT_EQ(zero.rfind("STEP #32 (surface of face #", 0), 0u) << zero;
  EXPECT_TRUE(contains(zero,
                       "): weight of control point (i, j) = (1, 1) (i along u, from 0) is 0; "
                       "NURBS weights must be positive"))
      << zero;
  const std::string negative = cad_error(kBad + "step_weight_negative.stp");
  EXPECT_TRUE(
      contains(negative, "weight of control point (i, j) = (1, 2) (i along u, from 0) is -1;"))
      << negative;
}

// A count of 2·10⁹ control points: the message was only "std::bad_alloc".
TEST(CadMalformed, OutOfMemorySaysWhatWasRead) {
#if defined(ISOFLEX_TEST_ASAN)
  // ASan's throwing operator new cannot throw: a failed 48 GB request aborts the reading child.
  GTEST_SKIP() << "operator new aborts instead of throwing std::bad_alloc under AddressSanitizer";
#endif
  const std::string m = cad_error(kBad + "iges_128_count_2e9.igs");
  EXPECT_EQ(m.rfind("out of memory (std::bad_alloc) while parsing the IGES file", 0), 0u) << m;
}

// The time limit from the environment must be a positive number of seconds.
TEST(CadMalformed, BadTimeLimitInTheEnvironment) {
  ::setenv("ISOFLEX_CAD_TIME_LIMIT", "soon", 1);
  const std::string m = cad_error(kData + "quarter_cylinder_R1_L2_deg2.igs");
  ::unsetenv("ISOFLEX_CAD_TIME_LIMIT");
  EXPECT_EQ(m, "ISOFLEX_CAD_TIME_LIMIT='soon' is not a positive number of seconds");
}
