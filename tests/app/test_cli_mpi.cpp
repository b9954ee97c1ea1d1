// `mpirun -n 2 isoflex run --static MODEL` (docs/theory/solvers.md §6): the Kirchhoff–Love
// patches' elements cut between two ranks, the Newton matrix summed and solved by PETSc on MPI's
// world, the outputs written by rank 0 alone, the results those of the serial run to the solver's
// tolerance; and the runs that are not distributed stop with a message. Each rank runs in its own
// working directory (mpirun's -wdir, one app context per rank) with the same relative output
// folder, so that whatever rank 1 writes is seen. Skipped without mpirun; the PETSc module is
// required as in the other PETSc tests (support/petsc.hpp). As root Open MPI also needs
// OMPI_ALLOW_RUN_AS_ROOT(_CONFIRM), set in the command.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "support/cli.hpp"
#include "support/examples.hpp"
#include "support/files.hpp"
#include "support/petsc.hpp"

namespace fs = std::filesystem;

namespace {
using isoflex::test::CliResult;
using isoflex::test::read_text;
using isoflex::test::replaced;
using isoflex::test::replaced_all;
using isoflex::test::run_shell;

#define ISOFLEX_REQUIRE_MPIRUN()                                               \
  do {                                                                         \
    if (run_shell("command -v mpirun").code != 0) GTEST_SKIP() << "no mpirun"; \
  } while (false)

// The whole Scordelis–Lo roof of bench/large_shells at `knots` per span (10: 531 unknowns; 36:
// 4 639, two multigrid levels), linear or nonlinear (5× the self-weight in two load steps), with a
// VTK file per step.
std::string roof(const std::string& solver, bool nonlinear, int knots = 10) {
  std::string m = read_text(ISOFLEX_SOURCE_DIR "/bench/large_shells/scordelis_lo_whole.yaml");
  m = replaced(m, "knots_per_span: [40, 40]",
               "knots_per_span: [" + std::to_string(knots) + ", " + std::to_string(knots) + "]");
  m = replaced(m, "linear_solver: cg_multigrid", "linear_solver: " + solver);
  m = replaced(m, "output: {vtk_every: 0}", "output: {vtk_every: 1}");
  if (nonlinear) {
    m = replaced(m, "  linear: true", "  linear: false");
    m = replaced(m, "  dt: 1\n", "  dt: 0.5\n");
    m = replaced(m, "-90*t", "-450*t");
  }
  return m;
}

// A model of bench/large_shells at `knots` per span on every patch, with a VTK file per step.
std::string bench_model(const std::string& file, int knots) {
  const std::string m = read_text(ISOFLEX_SOURCE_DIR "/bench/large_shells/" + file);
  const std::string k = std::to_string(knots);
  return replaced(
      replaced_all(m, "knots_per_span: [40, 40]", "knots_per_span: [" + k + ", " + k + "]"),
      "output: {vtk_every: 0}", "output: {vtk_every: 1}");
}

struct Runs {
  isoflex::test::TempDir dir;
  fs::path model;
  explicit Runs(const std::string& name, const std::string& text)
      : dir(fs::temp_directory_path() /
            ("isoflex_mpi_" + name + "_" + std::to_string(::getpid()))) {
    model = dir.path() / "m.yaml";
    std::ofstream(model) << text;
    fs::create_directories(dir.path() / "rank0");
    fs::create_directories(dir.path() / "rank1");
  }
  // isoflex run --static on one process, into serial/.
  CliResult serial() const {
    return run_shell("cd " + dir.path().string() + " && " ISOFLEX_BINARY " run --static " +
                     model.string() + " -o serial");
  }
  // The same on two ranks, each in its own folder rank0/, rank1/, into out/ there.
  CliResult two_ranks() const {
    const std::string run =
        std::string(ISOFLEX_BINARY) + " run --static " + model.string() + " -o out";
    return run_shell(
        "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 timeout 300 mpirun "
        "--oversubscribe -n 1 -wdir " +
        (dir.path() / "rank0").string() + " " + run + " : -n 1 -wdir " +
        (dir.path() / "rank1").string() + " " + run);
  }
  fs::path serial_out() const { return dir.path() / "serial"; }
  fs::path rank_out(int rank) const { return dir.path() / ("rank" + std::to_string(rank)) / "out"; }
};

// The numbers of a CSV file, row by row (the header and text fields left out).
std::vector<std::vector<double>> csv_numbers(const fs::path& p) {
  std::vector<std::vector<double>> rows;
  std::istringstream in(read_text(p));
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    std::vector<double> row;
    std::istringstream fields(line);
    std::string f;
    while (std::getline(fields, f, ','))
      if (!f.empty() && (std::isdigit(static_cast<unsigned char>(f[0])) || f[0] == '-'))
        row.push_back(std::stod(f));
    rows.push_back(row);
  }
  return rows;
}

// The number after `"key": ` in summary.json (NaN if the key is not there).
double summary_number(const fs::path& summary, const std::string& key) {
  const std::string s = read_text(summary);
  const auto p = s.find("\"" + key + "\": ");
  return p == std::string::npos ? std::nan("") : std::stod(s.substr(p + key.size() + 4));
}

// probes.csv and history.csv's energies of the two-rank run equal the serial run's to `rtol` of
// each column's largest value (the Krylov solves' tolerance; the sums are in another order), the
// same number of load steps and Newton iterations; rank 1 wrote nothing.
void expect_serial_results(const Runs& runs, double rtol) {
  const fs::path one = runs.serial_out(), two = runs.rank_out(0);
  for (const char* file : {"probes.csv", "history.csv"}) {
    const auto a = csv_numbers(one / file), b = csv_numbers(two / file);
    ASSERT_EQ(a.size(), b.size()) << file;
    ASSERT_GE(a.size(), 2u) << file;
    double worst = 0.0;
    for (std::size_t c = 0; c < a.front().size(); ++c) {
      if (std::string(file) == "history.csv" && c + 2 >= a.front().size()) continue;  // residual
      double scale = 0.0;
      for (const auto& row : a) scale = std::max(scale, std::abs(row[c]));
      for (std::size_t r = 0; r < a.size(); ++r) {
        ASSERT_EQ(a[r].size(), b[r].size());
        const double d = std::abs(a[r][c] - b[r][c]);
        worst = std::max(worst, scale > 0.0 ? d / scale : d);
      }
    }
    EXPECT_LE(worst, rtol) << file;
    std::printf("[ info ] %s: two ranks vs one, largest difference %.3g (relative)\n", file, worst);
  }
  const fs::path s1 = one / "summary.json", s2 = two / "summary.json";
  EXPECT_EQ(summary_number(s2, "mpi_ranks"), 2.0);
  EXPECT_TRUE(std::isnan(summary_number(s1, "mpi_ranks")));
  EXPECT_EQ(summary_number(s2, "steps"), summary_number(s1, "steps"));
  EXPECT_EQ(summary_number(s2, "newton_iterations_total"),
            summary_number(s1, "newton_iterations_total"));
  EXPECT_NEAR(summary_number(s2, "energy_final"), summary_number(s1, "energy_final"),
              rtol * std::abs(summary_number(s1, "energy_final")));
  EXPECT_EQ(summary_number(s2, "linear_solver_fallbacks"), 0.0);
  EXPECT_TRUE(fs::exists(two / "results.pvd"));
  EXPECT_TRUE(fs::is_empty(runs.dir.path() / "rank1")) << "rank 1 wrote outputs";
}

// `text` run on one process and on two ranks, both to the end, with the same results (1e-8);
// with `more_cg` ≥ 0, the two ranks' CG iterations at most that many more than the serial run's.
void expect_two_ranks_as_serial(const std::string& name, const std::string& text,
                                double more_cg = -1.0) {
  const Runs runs(name, text);
  const CliResult s = runs.serial();
  ASSERT_EQ(s.code, 0) << s.out;
  const CliResult p = runs.two_ranks();
  ASSERT_EQ(p.code, 0) << p.out;
  expect_serial_results(runs, 1e-8);
  if (more_cg < 0.0) return;
  const double one = summary_number(runs.serial_out() / "summary.json", "krylov_iterations_total"),
               two = summary_number(runs.rank_out(0) / "summary.json", "krylov_iterations_total");
  EXPECT_LE(two, one + more_cg) << "CG iterations on one process " << one;
  std::printf("[ info ] CG iterations: %g on one process, %g on two ranks\n", one, two);
}

}  // namespace

TEST(CliMpi, TwoRanksGiveTheSerialNonlinearSolution) {
  ISOFLEX_REQUIRE_PETSC();
  ISOFLEX_REQUIRE_MPIRUN();
  // Large enough for a multigrid level below the fine one (the interpolations distributed).
  const Runs runs("nonlinear", roof("cg_multigrid", true, 36));
  const CliResult s = runs.serial();
  ASSERT_EQ(s.code, 0) << s.out;
  const CliResult p = runs.two_ranks();
  ASSERT_EQ(p.code, 0) << p.out;
  // Rank 0 alone prints: one summary line.
  std::size_t lines = 0;
  for (auto at = p.out.find("results in"); at != std::string::npos;
       at = p.out.find("results in", at + 1))
    ++lines;
  EXPECT_EQ(lines, 1u) << p.out;
  expect_serial_results(runs, 1e-8);
}

TEST(CliMpi, TwoRanksGiveTheSerialLinearSolutionWithEachPetscSolver) {
  ISOFLEX_REQUIRE_PETSC();
  ISOFLEX_REQUIRE_MPIRUN();
  for (const char* solver : {"cg_gamg", "cg_hypre", "mumps"}) {
    SCOPED_TRACE(solver);
    expect_two_ranks_as_serial(solver, roof(solver, false));
  }
}

// `direct` under mpirun stops before anything is written (the user named a sequential solver);
// `auto` picks geometric multigrid and says so.
TEST(CliMpi, DirectStopsAndAutoSaysWhatItPicks) {
  ISOFLEX_REQUIRE_PETSC();
  ISOFLEX_REQUIRE_MPIRUN();
  const Runs direct("direct", roof("direct", false));
  const CliResult d = direct.two_ranks();
  EXPECT_NE(d.code, 0) << d.out;
  EXPECT_NE(d.out.find("error: 2 MPI ranks: solver.linear_solver direct (CHOLMOD) runs on one "
                       "process only: choose cg_multigrid, cg_gamg, cg_hypre or mumps (or auto)"),
            std::string::npos)
      << d.out;
  EXPECT_FALSE(fs::exists(direct.rank_out(0)));
  EXPECT_FALSE(fs::exists(direct.rank_out(1)));
  const Runs automatic("auto", roof("auto", false));
  const CliResult a = automatic.two_ranks();
  ASSERT_EQ(a.code, 0) << a.out;
  EXPECT_NE(a.out.find("note: 2 MPI ranks: solver.linear_solver auto solves with cg_multigrid"),
            std::string::npos)
      << a.out;
  EXPECT_NE(
      read_text(automatic.rank_out(0) / "summary.json").find("\"linear_solver\": \"cg_multigrid\""),
      std::string::npos);
}

// The quarter roof's symmetry rows (homogeneous support rows) are tied on every rank alike, as
// in the serial run: the two-rank run is the serial one, by CG with geometric multigrid on the
// tied unknowns (two levels at k = 36: 4 800 coordinates).
TEST(CliMpi, TwoRanksTieTheSymmetryRowsAndGiveTheSerialSolution) {
  ISOFLEX_REQUIRE_PETSC();
  ISOFLEX_REQUIRE_MPIRUN();
  expect_two_ranks_as_serial("quarter", bench_model("scordelis_lo_quarter.yaml", 36));
}

// p-multigrid (solver.multigrid_coarsening: degree, docs/theory/solvers.md §4) on two ranks: the
// first transfer, a local projection onto degree 2 and not nested, distributed like the knots'
// (k = 36: 4 485 unknowns, 16 CG on one process and on two).
TEST(CliMpi, TwoRanksLowerTheDegreeAsOneProcessDoes) {
  ISOFLEX_REQUIRE_PETSC();
  ISOFLEX_REQUIRE_MPIRUN();
  expect_two_ranks_as_serial(
      "degree",
      replaced(bench_model("scordelis_lo_quarter.yaml", 36), "  linear_solver: cg_multigrid\n",
               "  linear_solver: cg_multigrid\n  multigrid_coarsening: degree\n"),
      1.0);
}

// AF-D's G¹ rows tie coordinates of the two-patch roof (and the symmetry rows at its interface
// that they imply are dropped with the other tied rows): reduced on every rank alike.
TEST(CliMpi, TwoRanksReduceTheModelsTiedCoordinates) {
  ISOFLEX_REQUIRE_PETSC();
  ISOFLEX_REQUIRE_MPIRUN();
  expect_two_ranks_as_serial("two_patch", bench_model("scordelis_lo_two_patch.yaml", 24));
}

// The two-patch roof coupled by a bending strip
// (bench/large_shells/scordelis_lo_bending_strip.yaml, k = 48: 15 504 unknowns):
// the patches' elements cut between the ranks, the strip's summed by rank 0 alone
// (System::partition_kl_patches) — summed by both it would count twice. The ranks' rows end off
// the strip on every level, and so do their smoothers' blocks (solve/row_cuts.hpp): CG takes the
// serial run's iterations (19 and 19; 22 with equal shares on the coarse levels, 159 with equal
// shares on every level). With the strip counted twice the results differ by 3.4·10⁻⁸ and
// 1.3·10⁻⁷.
TEST(CliMpi, TwoRanksSumTheBendingStripOnce) {
  ISOFLEX_REQUIRE_PETSC();
  ISOFLEX_REQUIRE_MPIRUN();
  expect_two_ranks_as_serial("strip", bench_model("scordelis_lo_bending_strip.yaml", 48), 1.0);
}

// What is not distributed stops with the reason, before anything is written: a dynamic run, the
// supports' rows kept as multipliers (support_rows: multipliers), a weak prescribed displacement.
TEST(CliMpi, WhatIsNotDistributedStopsWithTheReason) {
  ISOFLEX_REQUIRE_PETSC();
  ISOFLEX_REQUIRE_MPIRUN();
  const std::string dynamic =
      "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 timeout "
      "300 mpirun --oversubscribe -n 2 " ISOFLEX_BINARY " run " +
      std::string(ISOFLEX_SOURCE_DIR) + "/examples/double_pendulum_3d/model.yaml -o /dev/null/x";
  const CliResult d = run_shell(dynamic);
  EXPECT_NE(d.code, 0) << d.out;
  EXPECT_NE(d.out.find("error: 2 MPI ranks: dynamic analyses run on one process only"),
            std::string::npos)
      << d.out;
  const std::string quarter = bench_model("scordelis_lo_quarter.yaml", 6);
  const Runs multipliers("multipliers", replaced(quarter, "  linear: true\n",
                                                 "  linear: true\n  support_rows: multipliers\n"));
  const CliResult q = multipliers.two_ranks();
  EXPECT_NE(q.code, 0) << q.out;
  EXPECT_NE(q.out.find("error: 2 MPI ranks: solver.support_rows: multipliers keeps the supports' "),
            std::string::npos)
      << q.out;
  EXPECT_NE(q.out.find("solved on one process only"), std::string::npos) << q.out;
  EXPECT_FALSE(fs::exists(multipliers.rank_out(0)));
  const Runs weak("weak", replaced(quarter, "fixed: [x, y]}",
                                   "fixed: [x, y]}\n  - {shell: roof, edge: u0, displacement: "
                                   "[0, \"-0.01*t\", 0]}"));
  const CliResult w = weak.two_ranks();
  EXPECT_NE(w.code, 0) << w.out;
  EXPECT_NE(w.out.find("error: 2 MPI ranks: the supports have "), std::string::npos) << w.out;
  EXPECT_NE(w.out.find("rows with a prescribed value or a weak condition (the first: "),
            std::string::npos)
      << w.out;
  EXPECT_FALSE(fs::exists(weak.rank_out(0)));
}

// A failure of rank 0 alone (it alone writes) ends every rank, instead of leaving the others
// waiting for it in a sum: an output folder it cannot create, and a VTK folder it cannot make
// (a file of that name in the way). The runs end with rank 0's message, not by the timeout (124).
TEST(CliMpi, AnOutputFailureOfRankZeroEndsEveryRank) {
  ISOFLEX_REQUIRE_PETSC();
  ISOFLEX_REQUIRE_MPIRUN();
  const Runs runs("output", roof("cg_hypre", false));
  const CliResult folder = run_shell(
      "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 timeout 120 mpirun "
      "--oversubscribe -n 2 " ISOFLEX_BINARY " run --static " +
      runs.model.string() + " -o /proc/isoflex_no_such_folder/out");
  EXPECT_NE(folder.code, 0) << folder.out;
  EXPECT_NE(folder.code, 124) << "a rank did not end: " << folder.out;
  EXPECT_NE(folder.out.find("cannot create output directory"), std::string::npos) << folder.out;
  fs::create_directories(runs.rank_out(0));
  std::ofstream(runs.rank_out(0) / "vtk") << "in the way\n";
  const CliResult vtk = runs.two_ranks();
  EXPECT_NE(vtk.code, 0) << vtk.out;
  EXPECT_NE(vtk.code, 124) << "a rank did not end: " << vtk.out;
  EXPECT_NE(vtk.out.find("vtk"), std::string::npos) << vtk.out;
}
