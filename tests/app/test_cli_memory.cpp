// Memory (issue #15): a model the machine cannot hold is refused by `check` and `run` before it
// is compiled, with a located message naming the estimate and the limit; running out of memory
// all the same is a message with what was being done, never an uncaught std::bad_alloc. The
// limits here are small (--max-memory, ulimit -v) so that the tests stay fast and light.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

#include "isoflex/app/commands.hpp"
#include "isoflex/io/model_reader.hpp"
#include "isoflex/system/memory_estimate.hpp"
#include "support/cli.hpp"
#include "support/examples.hpp"
#include "support/files.hpp"

namespace fs = std::filesystem;

// AddressSanitizer reserves terabytes of shadow address space: no address-space limit under it
// (GCC defines __SANITIZE_ADDRESS__, clang has __has_feature(address_sanitizer)).
#include "support/sanitizers.hpp"

namespace {
using isoflex::test::read_text;
using isoflex::test::run_isoflex;

const std::string kExamples = ISOFLEX_SOURCE_DIR "/examples/";

fs::path model_file(const isoflex::test::TempDir& d, const std::string& name,
                    const std::string& text) {
  std::ofstream(d.path() / name) << text;
  return d.path() / name;
}

isoflex::test::TempDir temp(const std::string& name) {
  return isoflex::test::TempDir(fs::temp_directory_path() /
                                ("isoflex_memory_" + name + "_" + std::to_string(::getpid())));
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// The free-flying beam with 10⁶ elements: the reader accepts it (up to 10⁷), `check` took 5.5 GB
// and `run` ended in an uncaught std::bad_alloc.
std::string million_beam_elements() {
  return isoflex::test::replaced(read_text(kExamples + "free_flying_beam/model.yaml"),
                                 "elements: 6 ", "elements: 1000000 ");
}

// The Scordelis–Lo roof (Kirchhoff–Love) refined to 300 × 300 knot spans: 4.3 GB in `check`.
std::string roof_300() {
  return isoflex::test::replaced(read_text(kExamples + "scordelis_lo/kl_shell.yaml"),
                                 "knots_per_span: [3, 3]", "knots_per_span: [300, 300]");
}

// The line of `key` in `text` (1-based).
int line_of(const std::string& text, const std::string& key) {
  const auto p = text.find(key);
  return p == std::string::npos
             ? 0
             : 1 + static_cast<int>(std::count(text.begin(), text.begin() + p, '\n'));
}
}  // namespace

TEST(CliMemory, CheckRefusesAMillionBeamElementsBeforeCompiling) {
  const auto d = temp("beam");
  const std::string text = million_beam_elements();
  const fs::path m = model_file(d, "m.yaml", text);
  const auto c = run_isoflex("check " + m.string() + " --max-memory 256M");
  EXPECT_EQ(c.code, 2) << c.out;
  // model.yaml:LINE: beams[0]: this model needs about … GB (…), --max-memory is 256 MB
  EXPECT_TRUE(contains(c.out, m.string() + ":" + std::to_string(line_of(text, "- name: beam")) +
                                  ": beams[0]: this model needs about "))
      << c.out;
  EXPECT_TRUE(contains(c.out, "1.0 M elements")) << c.out;
  EXPECT_TRUE(contains(c.out, "--max-memory is 256 MB (--max-memory to change)")) << c.out;
  // run refuses the same way, before anything is written.
  const auto r = run_isoflex("run " + m.string() + " -o " + (d.path() / "out").string() +
                             " --max-memory 256M");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_TRUE(contains(r.out, "beams[0]: this model needs about")) << r.out;
  EXPECT_FALSE(fs::exists(d.path() / "out" / "summary.json"));
}

TEST(CliMemory, CheckRefusesAFineKirchhoffLovePatch) {
  const auto d = temp("kl");
  const std::string text = roof_300();
  const fs::path m = model_file(d, "m.yaml", text);
  const auto c = run_isoflex("check " + m.string() + " --max-memory 1G");
  EXPECT_EQ(c.code, 2) << c.out;
  EXPECT_TRUE(contains(c.out, m.string() + ":" +
                                  std::to_string(line_of(text, "- name: roof\n    surface")) +
                                  ": kl_shells[0]: this model needs about "))
      << c.out;
  EXPECT_TRUE(contains(c.out, "305 x 305 control points")) << c.out;
  EXPECT_TRUE(contains(c.out, "sparse LU")) << c.out;
}

// A director-shell plate of 10⁴ × 10⁴ elements: the reader builds its 10⁸ nodes itself, so the
// limit is checked there, at the key.
TEST(CliMemory, ReaderRefusesAHugeShellMeshBeforeBuildingIt) {
  const auto d = temp("plate");
  const std::string text =
      isoflex::test::replaced(read_text(kExamples + "intersecting_shells/model.yaml"),
                              "elements: [10, 1]", "elements: [10000, 10000]");
  const fs::path m = model_file(d, "m.yaml", text);
  const auto c = run_isoflex("check " + m.string() + " --max-memory 2G");
  EXPECT_EQ(c.code, 2) << c.out;
  EXPECT_TRUE(contains(c.out, "shells[0].plate.elements: this shell needs about")) << c.out;
  EXPECT_TRUE(contains(c.out, "--max-memory is 2.0 GB (--max-memory to change)")) << c.out;
}

TEST(CliMemory, CheckPrintsTheEstimateAndRejectsABadSize) {
  const auto c = run_isoflex("check " + kExamples + "scordelis_lo/kl_shell.yaml --max-memory 4G");
  EXPECT_EQ(c.code, 0) << c.out;
  EXPECT_TRUE(contains(c.out, "memory           about ")) << c.out;
  EXPECT_TRUE(contains(c.out, "to run")) << c.out;
  EXPECT_TRUE(contains(c.out, "--max-memory is 4.0 GB")) << c.out;
  const auto bad = run_isoflex("check " + kExamples + "scordelis_lo/kl_shell.yaml --max-memory 2Q");
  EXPECT_EQ(bad.code, 2) << bad.out;
  EXPECT_TRUE(contains(bad.out, "--max-memory: \"2Q\" is not a memory size")) << bad.out;
}

// Out of memory although the estimate fitted (here: the address space limited by ulimit -v,
// the estimate told a large --max-memory): a message saying what was being done, exit 2 in
// check, exit 3 with summary.json in run; never "std::bad_alloc" alone or an abort. ASan
// reserves terabytes of shadow address space, so ulimit -v cannot be used under it.
TEST(CliMemory, AnAllocationFailureIsAMessage) {
#if defined(ISOFLEX_TEST_ASAN)
  GTEST_SKIP() << "ulimit -v and AddressSanitizer do not mix";
#endif
  const auto d = temp("bad_alloc");
  const fs::path m = model_file(d, "m.yaml", million_beam_elements());
  const std::string limit = "ulimit -v 400000; ";  // 400 MB of address space
  const std::string bin = ISOFLEX_BINARY;
  auto sh = [&](const std::string& args) {
    return isoflex::test::run_shell(limit + bin + " " + args);
  };
  const auto c = sh("check " + m.string() + " --max-memory 100G");
  EXPECT_EQ(c.code, 2) << c.out;
  EXPECT_TRUE(contains(c.out, "out of memory while compiling the model")) << c.out;
  EXPECT_TRUE(contains(c.out, "--max-memory is 100 GB")) << c.out;
  EXPECT_FALSE(contains(c.out, "std::bad_alloc")) << c.out;
  const fs::path out = d.path() / "out";
  const auto r = sh("run " + m.string() + " -o " + out.string() + " --max-memory 100G");
  EXPECT_EQ(r.code, 3) << r.out;
  EXPECT_TRUE(contains(r.out, "out of memory while compiling the model")) << r.out;
  ASSERT_TRUE(fs::exists(out / "summary.json")) << r.out;
  const std::string summary = read_text((out / "summary.json").string());
  EXPECT_TRUE(contains(summary, "\"status\": \"failed\"")) << summary;
  EXPECT_TRUE(contains(summary, "out of memory while compiling the model")) << summary;
}

TEST(MemorySize, ParsesWhatMaxMemoryTakes) {
  using isoflex::app::parse_memory_size;
  EXPECT_EQ(parse_memory_size("2G"), 2.0 * (1 << 30));
  EXPECT_EQ(parse_memory_size("512M"), 512.0 * (1 << 20));
  EXPECT_EQ(parse_memory_size("1.5GB"), 1.5 * (1 << 30));
  EXPECT_EQ(parse_memory_size("64k"), 64.0 * 1024);
  EXPECT_EQ(parse_memory_size("3000000000"), 3e9);
  for (const char* bad : {"", "G", "2Q", "-1G", "0", "2GG", "nan", "inf"})
    EXPECT_FALSE(parse_memory_size(bad).has_value()) << bad;
}

// The estimate comes from the model alone: unknowns and the stiffness pattern's size from the
// refined surface, the factorization the largest term of a fine patch.
TEST(MemoryEstimate, CountsAKirchhoffLovePatchFromTheModel) {
  const auto m = isoflex::io::read_model_string(roof_300(), "roof.yaml");
  const isoflex::system::MemoryEstimate e = isoflex::system::estimate_memory(m);
  ASSERT_EQ(e.parts.size(), 1u);
  const isoflex::system::MemoryPart& p = *e.largest();
  EXPECT_EQ(p.what, "kl_shells[0]");
  EXPECT_EQ(p.unknowns, 3.0 * 305 * 305);
  EXPECT_GT(p.factor_bytes, p.matrix_bytes);
  EXPECT_LT(e.compile(), e.total());
  EXPECT_GT(e.total(), 10.0 * (1 << 30));  // ~19 GB: more than a 2-core CI machine has
  EXPECT_EQ(isoflex::system::format_bytes(4.3 * (1 << 30)), "4.3 GB");
  EXPECT_EQ(isoflex::system::format_bytes(31.2 * (1 << 30)), "31 GB");
}

// The PETSc path (docs/memory.md "The PETSc path"): an iterative solver factorizes nothing of
// the model's size, so the estimate has no sparse LU — asked for, or chosen by `auto` for one
// patch held by `fixed` supports from 50 000 unknowns on; a model with symmetry rows keeps the
// direct solver's estimate.
TEST(CliMemory, ThePetscPathIsEstimatedWithoutAFactorization) {
  const std::string whole = isoflex::test::replaced(
      read_text(ISOFLEX_SOURCE_DIR "/bench/large_shells/scordelis_lo_whole.yaml"),
      "knots_per_span: [40, 40]", "knots_per_span: [150, 150]");
  const auto estimate = [](const std::string& text) {
    return isoflex::system::estimate_memory(isoflex::io::read_model_string(text, "roof.yaml"));
  };
  const auto multigrid = estimate(whole);
  const auto automatic = estimate(
      isoflex::test::replaced(whole, "linear_solver: cg_multigrid", "linear_solver: auto"));
  const auto direct = estimate(
      isoflex::test::replaced(whole, "linear_solver: cg_multigrid", "linear_solver: direct"));
  EXPECT_GE(multigrid.unknowns(), 50000);
  EXPECT_TRUE(contains(multigrid.breakdown(), "sparse matrices and preconditioner"))
      << multigrid.breakdown();
  EXPECT_EQ(automatic.breakdown(), multigrid.breakdown());
  EXPECT_TRUE(contains(direct.breakdown(), "sparse LU")) << direct.breakdown();
  EXPECT_LT(multigrid.total(), 0.6 * direct.total());
  // Symmetry supports are multiplier rows: the direct solvers, and their estimate.
  const auto quarter =
      estimate(isoflex::test::replaced(read_text(kExamples + "scordelis_lo/kl_shell.yaml"),
                                       "knots_per_span: [3, 3]", "knots_per_span: [150, 150]"));
  EXPECT_TRUE(contains(quarter.breakdown(), "sparse LU")) << quarter.breakdown();
}
