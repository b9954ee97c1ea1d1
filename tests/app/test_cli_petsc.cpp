// The PETSc solvers as a user meets them (solver.linear_solver, docs/theory/solvers.md §2): what
// `check` prints, what summary.json records, and the warning when a model's Newton matrix is one
// the PETSc solvers do not take.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
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
// solver: the same displacement, the warning once, the fallback counted in summary.json. (The
// symmetry rows kept as multipliers, `support_rows: multipliers`: tied, there is no saddle point.)
TEST(CliPetsc, AFailedSaddlePointSolveFallsBackToTheDirectSolver) {
  ISOFLEX_REQUIRE_PETSC();
  const auto d = temp("quarter_fallback");
  const fs::path m = model_file(
      d, replaced(read_text(ISOFLEX_SOURCE_DIR "/examples/scordelis_lo/kl_shell.yaml"),
                  "  linear: true",
                  "  linear: true\n  linear_solver: mumps\n  support_rows: multipliers"));
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

namespace {
// u_z of probe `ref` in summary.json (NaN if it is not there).
double probe_uz(const std::string& summary) {
  const auto at = summary.find("\"ref\": {\"position\"");
  const auto d = at == std::string::npos ? at : summary.find("\"displacement\": [", at);
  double ux = 0, uy = 0, uz = 0;
  if (d == std::string::npos ||
      std::sscanf(summary.c_str() + d, "\"displacement\": [%lf, %lf, %lf]", &ux, &uy, &uz) != 3)
    return std::nan("");
  return uz;
}
}  // namespace

// The pinched cylinder of bench/large_shells (bench/large_shells.md, "Pinched cylinder"), at 32 ×
// 32 elements (k = 31: 3704 coordinates, two multigrid levels) through `isoflex run --static`:
// its symmetry rows tied (docs/theory/solvers.md §7), cg_multigrid without a fallback; u_z under
// the load within
// 0.5 % of the model's converged value −1.8283e-5 (examples/pinched_cylinder/README.md; measured
// −1.82313e-5, −0.28 %), and equal to examples/pinched_cylinder/kl_shell.yaml at the same degree
// and refinement (p = 3, k = 31; the direct solver) to 10⁻⁸ relative.
TEST(CliPetsc, PinchedCylinderBenchModelGivesTheExampleValue) {
  ISOFLEX_REQUIRE_PETSC();
  const auto d = temp("pinched_cylinder");
  const fs::path bench = d.path() / "bench.yaml";
  std::ofstream(bench) << replaced(
      read_text(ISOFLEX_SOURCE_DIR "/bench/large_shells/pinched_cylinder.yaml"),
      "knots_per_span: [40, 40]", "knots_per_span: [31, 31]");
  const auto r = run_isoflex("run --static " + bench.string() + " -o " + (d.path() / "b").string());
  expect_petsc_run(r, d.path() / "b", "cg_multigrid");
  const double u = probe_uz(read_text(d.path() / "b" / "summary.json"));
  EXPECT_LT(std::abs(u / -1.8283e-5 - 1.0), 0.005) << u;
  const fs::path example = d.path() / "example.yaml";
  std::ofstream(example) << replaced(
      read_text(ISOFLEX_SOURCE_DIR "/examples/pinched_cylinder/kl_shell.yaml"),
      "refine: {elevate: [2, 3], knots_per_span: [15, 15]}",
      "refine: {elevate: [1, 2], knots_per_span: [31, 31]}");
  const auto e =
      run_isoflex("run --static " + example.string() + " -o " + (d.path() / "e").string());
  ASSERT_EQ(e.code, 0) << e.out;
  const double ue = probe_uz(read_text(d.path() / "e" / "summary.json"));
  EXPECT_LT(std::abs(u / ue - 1.0), 1e-8) << u << " " << ue;
}
