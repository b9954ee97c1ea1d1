// The PETSc solvers as a user meets them (solver.linear_solver, docs/theory/solvers.md §2): what
// `check` prints, what summary.json records, and the warning when a model's Newton matrix is one
// the PETSc solvers do not take.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "support/cli.hpp"
#include "support/examples.hpp"
#include "support/files.hpp"
#include "support/petsc.hpp"

namespace fs = std::filesystem;

namespace {
using isoflex::test::read_text;
using isoflex::test::replaced;
using isoflex::test::run_isoflex;

fs::path model_file(const isoflex::test::TempDir& d, const std::string& text) {
  std::ofstream(d.path() / "m.yaml") << text;
  return d.path() / "m.yaml";
}

isoflex::test::TempDir temp(const std::string& name) {
  return isoflex::test::TempDir(fs::temp_directory_path() /
                                ("isoflex_petsc_" + name + "_" + std::to_string(::getpid())));
}

// The integer after `"key": ` in summary.json, −1 if the key is not there.
int summary_integer(const std::string& summary, const std::string& key) {
  const auto p = summary.find("\"" + key + "\": ");
  return p == std::string::npos ? -1 : std::stoi(summary.substr(p + key.size() + 4));
}
// A run into `out` by the PETSc solver `method` that needed no fallback: no warning, and
// summary.json names the solver and counts its iterations.
void expect_petsc_run(const isoflex::test::CliResult& r, const fs::path& out,
                      const std::string& method) {
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(r.out.find("warning"), std::string::npos) << r.out;
  const std::string summary = read_text(out / "summary.json");
  EXPECT_NE(summary.find("\"linear_solver\": \"" + method + "\""), std::string::npos) << summary;
  EXPECT_GT(summary_integer(summary, "krylov_iterations_total"), 0) << summary;
  EXPECT_EQ(summary_integer(summary, "linear_solver_fallbacks"), 0) << summary;
}

}  // namespace

TEST(CliPetsc, CheckAndSummarySayWhichSolverAndHowManyIterations) {
  ISOFLEX_REQUIRE_PETSC();
  const auto d = temp("roof");
  const fs::path m = model_file(
      d, replaced(read_text(ISOFLEX_SOURCE_DIR "/bench/large_shells/scordelis_lo_whole.yaml"),
                  "knots_per_span: [40, 40]", "knots_per_span: [30, 30]"));
  const auto c = run_isoflex("check " + m.string());
  ASSERT_EQ(c.code, 0) << c.out;
  EXPECT_NE(c.out.find("linear solver    cg_multigrid  (PETSc; docs/theory/solvers.md)"),
            std::string::npos)
      << c.out;
  const auto r = run_isoflex("run " + m.string() + " -o " + (d.path() / "o").string());
  expect_petsc_run(r, d.path() / "o", "cg_multigrid");
}

// The quarter roof's symmetry supports are multiplier rows: the PETSc solver takes its saddle
// point (docs/theory/solvers.md §5), no warning, and summary.json says which solver and how many
// (FGMRES) iterations.
TEST(CliPetsc, AMatrixWithMultiplierRowsIsSolvedByThePetscSolver) {
  ISOFLEX_REQUIRE_PETSC();
  const auto d = temp("quarter");
  const fs::path m =
      model_file(d, replaced(read_text(ISOFLEX_SOURCE_DIR "/examples/scordelis_lo/kl_shell.yaml"),
                             "  linear: true", "  linear: true\n  linear_solver: cg_multigrid"));
  const auto r = run_isoflex("run " + m.string() + " -o " + (d.path() / "o").string());
  expect_petsc_run(r, d.path() / "o", "cg_multigrid");
  EXPECT_NE(r.out.find("-0.3005"), std::string::npos) << r.out;  // the probe's u_y
}

// A saddle-point solve that fails (here: PETSC_OPTIONS leave the augmented block without a
// preconditioner, and FGMRES does not converge in its 5000 iterations) falls back to the direct
// solver: the same displacement, the warning once, the fallback counted in summary.json.
TEST(CliPetsc, AFailedSaddlePointSolveFallsBackToTheDirectSolver) {
  ISOFLEX_REQUIRE_PETSC();
  const auto d = temp("quarter_fallback");
  const fs::path m =
      model_file(d, replaced(read_text(ISOFLEX_SOURCE_DIR "/examples/scordelis_lo/kl_shell.yaml"),
                             "  linear: true", "  linear: true\n  linear_solver: mumps"));
  const auto r = isoflex::test::run_shell(
      "PETSC_OPTIONS='-isoflex_fieldsplit_primal_ksp_type preonly "
      "-isoflex_fieldsplit_primal_pc_type none' " ISOFLEX_BINARY " run " +
      m.string() + " -o " + (d.path() / "o").string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("warning: load step 1: mumps failed (PETSc FGMRES"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("solved by the direct solver"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("-0.3005"), std::string::npos) << r.out;
  const std::string summary = read_text(d.path() / "o" / "summary.json");
  EXPECT_EQ(summary_integer(summary, "linear_solver_fallbacks"), 1) << summary;
}
