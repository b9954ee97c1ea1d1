// `solver.integrator` end to end: the DAE schemes run a model through `isoflex run`, report
// their name and the size of their Newton system (n + m: 12 coordinates and 6 + 3 rows for the
// heavy top), keep the rows; a step that does not converge ends the run with exit code 3, the
// located message and the outputs up to the last converged step, as with the energy–momentum
// schemes.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "support/cli.hpp"
#include "support/files.hpp"
#include "support/run_outputs.hpp"

namespace fs = std::filesystem;
using isoflex::test::read_text;
using isoflex::test::run_isoflex;

namespace {

// The heavy top example with its formulation line replaced by `solver_lines`.
fs::path top_with(const isoflex::test::TempDir& d, const std::string& solver_lines) {
  std::string text = read_text(ISOFLEX_SOURCE_DIR "/examples/heavy_top/model.yaml");
  const std::string from = "  formulation: reparametrized\n";
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos);
  text.replace(at, from.size(), solver_lines);
  std::ofstream(d.path() / "top.yaml") << text;
  return d.path() / "top.yaml";
}

}  // namespace

TEST(CliIntegrators, DaeSchemesRunAndSayWhatTheyAre) {
  for (const char* scheme : {"generalized_alpha", "bdf1", "bdf2"}) {
    const isoflex::test::TempDir d(
        fs::temp_directory_path() /
        (std::string("isoflex_cli_dae_") + scheme + "_" + std::to_string(::getpid())));
    const fs::path m = top_with(d, std::string("  integrator: ") + scheme + "\n");
    const auto c = run_isoflex("check " + m.string());
    ASSERT_EQ(c.code, 0) << c.out;
    EXPECT_NE(c.out.find(std::string("unknowns         21 (") + scheme +
                         (std::string(scheme) == "generalized_alpha" ? ", rho_infinity 0.8" : "") +
                         ", scaled)\n"),
              std::string::npos)
        << c.out;
    const auto r =
        run_isoflex("run " + m.string() + " --t-end 0.2 -o " + (d.path() / "o").string());
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_NE(r.out.find(std::string("20 steps, 21 unknowns (") + scheme + ")"), std::string::npos)
        << r.out;
    const std::string summary = read_text(d.path() / "o" / "summary.json");
    EXPECT_NE(summary.find(std::string("\"formulation\": \"") + scheme + "\""), std::string::npos)
        << summary;
    EXPECT_NE(summary.find("\"n_unknowns\": 21"), std::string::npos) << summary;
  }
}

// At 50 rad/s and Δt = 0.01 generalized-α goes unstable on the top (docs/theory/integrators.md
// §7): Newton stops converging at step 40.
TEST(CliIntegrators, ANonConvergingDaeStepEndsWithCode3AndKeepsTheOutputs) {
  const isoflex::test::TempDir d(fs::temp_directory_path() /
                                 ("isoflex_cli_dae_fail_" + std::to_string(::getpid())));
  const fs::path m = top_with(d, "  integrator: generalized_alpha\n");
  const auto r = run_isoflex("run " + m.string() + " --t-end 1 --max-subdivisions 0 -o " +
                             (d.path() / "o").string());
  EXPECT_EQ(r.code, 3) << r.out;
  EXPECT_NE(r.out.find("error: step 40 (t = 0.4): Newton did not converge; residual "),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("(results up to t = 0.39, are in "), std::string::npos) << r.out;
  EXPECT_EQ(isoflex::test::csv_rows(d.path() / "o" / "history.csv"), 40);  // t = 0 … 0.39
  EXPECT_NE(read_text(d.path() / "o" / "summary.json").find("\"status\": \"failed\""),
            std::string::npos);
}

// solver.numerical_dissipation (docs/theory/schemes.md §10): `check` says it is on, and a run
// writes the dissipated energy to history.csv and summary.json.
TEST(CliIntegrators, NumericalDissipationIsSaidAndItsWorkWritten) {
  const isoflex::test::TempDir d(fs::temp_directory_path() /
                                 ("isoflex_cli_dissipation_" + std::to_string(::getpid())));
  const std::string model =
      std::string(ISOFLEX_SOURCE_DIR) + "/examples/intersecting_shells/model.yaml";
  const std::string set = " --set solver.numerical_dissipation=0.05";
  const auto c = run_isoflex("check " + model + set);
  ASSERT_EQ(c.code, 0) << c.out;
  EXPECT_NE(c.out.find("dissipation      numerical, chi 0.05 on the strains of beams and shells"),
            std::string::npos)
      << c.out;
  EXPECT_EQ(run_isoflex("check " + model).out.find("dissipation      numerical"),
            std::string::npos);
  const auto r = run_isoflex("run " + model + set + " --t-end 0.1 --set output.vtk_every=0 -o " +
                             (d.path() / "o").string());
  ASSERT_EQ(r.code, 0) << r.out;
  const std::string history = read_text(d.path() / "o" / "history.csv");
  EXPECT_NE(history.substr(0, history.find('\n')).find("dissipated_energy"), std::string::npos)
      << history.substr(0, 200);
  EXPECT_NE(read_text(d.path() / "o" / "summary.json").find("\"dissipated_energy\": "),
            std::string::npos);
}
