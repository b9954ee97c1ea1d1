// The `isoflex` executable end to end: exit codes, messages, output files.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <tuple>

#include "support/cli.hpp"
#include "support/files.hpp"
#include "support/pendulum_yaml.hpp"

namespace fs = std::filesystem;

namespace {
using Result = isoflex::test::CliResult;

Result run(const std::string& args) {
  return isoflex::test::run_isoflex(args);
}

fs::path temp_dir(const std::string& name) {
  return isoflex::test::temp_dir("isoflex_cli_", name);
}

std::string read(const fs::path& p) {
  return isoflex::test::read_text(p);
}

const std::string kGood =
    isoflex::test::pendulum_yaml("{dt: 0.01, t_end: 0.2}", "probes:\n  - {name: bob, body: bob}\n");

std::string with(std::string text, const std::string& from, const std::string& to) {
  const auto p = text.find(from);
  EXPECT_NE(p, std::string::npos) << from;
  return text.replace(p, from.size(), to);
}
}  // namespace

TEST(Cli, Version) {
  const auto r = run("--version");
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("isoflex 0."), std::string::npos);
}

TEST(Cli, RunWritesHistorySummaryProbesAndVtk) {
  const fs::path d = temp_dir("run");
  std::ofstream(d / "m.yaml") << kGood;
  const auto r = run("run " + (d / "m.yaml").string() + " -o " + (d / "out").string() +
                     " --formulation constrained");
  ASSERT_EQ(r.code, 0) << r.out;
  const std::string h = read(d / "out/history.csv");
  EXPECT_EQ(h.rfind("t,kinetic_energy,potential_energy,total_energy,px,py,pz,Lx,Ly,Lz,constraint_"
                    "violation,newton_iterations,residual\n",
                    0),
            0u);
  EXPECT_EQ(std::count(h.begin(), h.end(), '\n'), 22);  // header + initial + 20 steps
  const std::string s = read(d / "out/summary.json");
  EXPECT_NE(s.find("\"n_coordinates\": 12"), std::string::npos) << s;
  EXPECT_NE(s.find("\"n_constraints\": 9"), std::string::npos);
  EXPECT_NE(s.find("\"n_unknowns\": 21"), std::string::npos);
  EXPECT_NE(s.find("\"formulation\": \"constrained\""), std::string::npos);
  EXPECT_NE(s.find("\"steps\": 20"), std::string::npos);
  EXPECT_NE(s.find("\"bob\": {\"position\""), std::string::npos);
  EXPECT_TRUE(fs::exists(d / "out/results.pvd"));
  EXPECT_TRUE(fs::exists(d / "out/probes.csv"));
}

// --set KEY=VALUE sets model values over the file's (repeatable; io/model_overrides.hpp), run and
// check alike; summary.json lists them; a bad one is exit code 2 with a located message.
TEST(Cli, SetOverridesModelValues) {
  const fs::path d = temp_dir("set");
  std::ofstream(d / "m.yaml") << kGood;
  const auto r =
      run("run " + (d / "m.yaml").string() + " -o " + (d / "out").string() +
          " --set solver.t_end=0.05 --set 'bodies[bob].mass=2' --set output.vtk_every=0");
  ASSERT_EQ(r.code, 0) << r.out;
  const std::string s = read(d / "out/summary.json");
  EXPECT_NE(s.find("\"steps\": 5,"), std::string::npos) << s;
  EXPECT_NE(s.find("\"set\": [\"solver.t_end=0.05\", \"bodies[bob].mass=2\", "
                   "\"output.vtk_every=0\"],"),
            std::string::npos)
      << s;
  EXPECT_FALSE(fs::exists(d / "out/results.pvd"));
  const auto c = run("check " + (d / "m.yaml").string() + " --set 'bodies[0].mass=-1'");
  EXPECT_EQ(c.code, 2);
  EXPECT_NE(c.out.find("bodies[0].mass: must be > 0, got -1 (the value of --set "
                       "bodies[0].mass=-1)"),
            std::string::npos)
      << c.out;
  const auto bad = run("run " + (d / "m.yaml").string() + " --set solver.dt");
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.out.find("error: --set \"solver.dt\": expected KEY=VALUE"), std::string::npos)
      << bad.out;
  fs::remove_all(d);
}

// A rerun into the same folder removes the earlier run's VTK series (results.pvd, vtk/*.vtu), so
// that ParaView never shows steps of another run; other files in vtk/ are left alone.
TEST(Cli, ARerunRemovesTheEarlierVtkSeries) {
  const fs::path d = temp_dir("rerun");
  const fs::path out = d / "out";
  std::ofstream(d / "long.yaml") << kGood;
  std::ofstream(d / "short.yaml") << with(kGood, "t_end: 0.2", "t_end: 0.05");
  std::ofstream(d / "none.yaml") << with(kGood, "solver: {dt: 0.01, t_end: 0.2}",
                                         "solver: {dt: 0.01, t_end: 0.2}\noutput: {vtk_every: 0}");
  const auto count_vtu = [&] {
    int n = 0;
    for (const auto& e : fs::directory_iterator(out / "vtk")) n += e.path().extension() == ".vtu";
    return n;
  };
  ASSERT_EQ(run("run " + (d / "long.yaml").string() + " -o " + out.string()).code, 0);
  const int long_run = count_vtu();
  std::ofstream(out / "vtk" / "notes.txt") << "mine";
  ASSERT_EQ(run("run " + (d / "short.yaml").string() + " -o " + out.string()).code, 0);
  const int short_run = count_vtu();
  EXPECT_EQ(long_run, 21);  // t = 0, 0.01, …, 0.2
  EXPECT_EQ(short_run, 6);
  EXPECT_EQ(read(out / "results.pvd").find("step_000006"), std::string::npos);
  ASSERT_EQ(run("run " + (d / "none.yaml").string() + " -o " + out.string()).code, 0);
  EXPECT_EQ(count_vtu(), 0);
  EXPECT_FALSE(fs::exists(out / "results.pvd"));
  EXPECT_TRUE(fs::exists(out / "vtk" / "notes.txt"));
  fs::remove_all(d);
}

// --threads on a model without Kirchhoff–Love patches (the only elements assembled on threads) is
// said on stderr and in summary.json, not silently ignored; without the flag nothing is said.
TEST(Cli, ThreadsThatCannotBeUsedAreSaid) {
  const fs::path d = temp_dir("threads");
  std::ofstream(d / "m.yaml") << kGood;
  const auto r =
      run("run " + (d / "m.yaml").string() + " -o " + (d / "out").string() + " --threads 2");
  ASSERT_EQ(r.code, 0) << r.out;
  const std::string note =
      "--threads 2: only Kirchhoff-Love shells assemble on threads; this "
      "model has none, it ran on 1";
  EXPECT_NE(r.out.find("note: " + note), std::string::npos) << r.out;
  const std::string s = read(d / "out/summary.json");
  EXPECT_NE(s.find("\"threads\": 1,\n  \"threads_note\": \"" + note + "\""), std::string::npos)
      << s;
  const auto plain = run("run " + (d / "m.yaml").string() + " -o " + (d / "out2").string());
  ASSERT_EQ(plain.code, 0) << plain.out;
  EXPECT_EQ(plain.out.find("note:"), std::string::npos) << plain.out;
  EXPECT_EQ(read(d / "out2/summary.json").find("threads_note"), std::string::npos);
  fs::remove_all(d);
}

// `history: false` writes no time histories (history.csv, probes.csv) and `vtk_every: 0` no VTK;
// summary.json, with the probes' final values, is always written.
TEST(Cli, OutputSwitches) {
  const fs::path d = temp_dir("switches");
  std::ofstream(d / "m.yaml") << with(kGood, "solver: {dt: 0.01, t_end: 0.2}",
                                      "solver: {dt: 0.01, t_end: 0.2}\noutput: {history: false, "
                                      "vtk_every: 0}");
  const auto r = run("run " + (d / "m.yaml").string() + " -o " + (d / "out").string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_FALSE(fs::exists(d / "out/history.csv"));
  EXPECT_FALSE(fs::exists(d / "out/probes.csv"));
  EXPECT_FALSE(fs::exists(d / "out/results.pvd"));
  EXPECT_NE(read(d / "out/summary.json").find("\"bob\": {\"position\""), std::string::npos);
  fs::remove_all(d);
}

TEST(Cli, CheckPrintsCountsAndForest) {
  const auto r = run("check " + std::string(ISOFLEX_SOURCE_DIR) + "/examples/four_bar/model.yaml");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("n                36"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("m                35"), std::string::npos);
  EXPECT_NE(r.out.find("redundant        3  (dropped: B (3 rows)"), std::string::npos);
  EXPECT_NE(r.out.find("dof              1"), std::string::npos);
  EXPECT_NE(r.out.find("cut   B"), std::string::npos);
}

// Bad model files: one error line naming file, line and key; exit code 2; nothing written.
TEST(Cli, BadModelsGiveLocatedErrorsAndExitCode2) {
  const fs::path d = temp_dir("bad");
  const std::string f = (d / "m.yaml").string();
  const struct {
    std::string text, expected;
  } cases[] = {
      {with(kGood, "    mass: 1.0\n", ""), f + ":5: bodies[0].mass: missing required key"},
      {with(kGood, "type: spherical", "type: hinge"),
       f + ":10: joints[0].type: unknown joint type \"hinge\""},
      {with(kGood, "body_b: bob, point", "body_b: bobby, point"),
       f + ":10: joints[0].body_b: no body named \"bobby\""},
      {with(kGood, "mass: 1.0", "mass: -1.0"), f + ":6: bodies[0].mass:"},
      {with(kGood, "    position: [1, 0, 0]\n",
            "    position: [1, 0, 0]\n    orientation: [[1, 0, 0], [0, 1, 0], [0, 1, 0]]\n"),
       f + ":9: bodies[0].orientation: orientation is not an orthonormal right-handed triad"},
      {std::string(kGood) + "loads:\n  - {body: bob, force: [\"sin(t\", 0, 0]}\n",
       f + ":14: loads[0].force[0]: invalid expression"},
  };
  for (const auto& c : cases) {
    std::ofstream(f) << c.text;
    const auto r = run("run " + f + " -o " + (d / "out").string());
    EXPECT_EQ(r.code, 2) << r.out;
    EXPECT_NE(r.out.find("error: " + c.expected), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(d / "out")) << "nothing is written for a bad model";
    const auto k = run("check " + f);
    EXPECT_EQ(k.code, 2);
  }
  const auto missing = run("check " + (d / "nope.yaml").string());
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.out.find("cannot open model file"), std::string::npos);
  EXPECT_EQ(run("run").code, 2);
  EXPECT_EQ(run("run " + f + " --formulation fancy").code, 2);
}

// A step count that cannot be run (issue #15, found by tests/fuzz): exit 2 with a located
// message, nothing written. Before, dt: 1e-30 ran 0 steps (lround overflowed) and exited 0
// "completed". The same for --dt/--t-end on the command line.
TEST(Cli, StepCountOutOfRangeIsExitCode2) {
  const fs::path d = temp_dir("steps");
  const std::string f = (d / "m.yaml").string();
  std::ofstream(f) << isoflex::test::pendulum_yaml("{dt: 1.0e-30, t_end: 0.2}");
  auto r = run("run " + f + " -o " + (d / "out").string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("error: " + f + ":3: solver.t_end: t_end / dt = 0.2 / 1e-30"),
            std::string::npos)
      << r.out;
  EXPECT_FALSE(fs::exists(d / "out")) << "nothing is written for a bad model";
  EXPECT_EQ(run("check " + f).code, 2);
  std::ofstream(f) << kGood;
  r = run("run " + f + " -o " + (d / "out").string() + " --dt 1e-30");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("error: --dt, --t-end: t_end / dt = 0.2 / 1e-30"), std::string::npos)
      << r.out;
  r = run("run " + f + " -o " + (d / "out").string() + " --t-end 0.001");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("error: --dt, --t-end: t_end = 0.001 is shorter than half a time step"),
            std::string::npos)
      << r.out;
  r = run("run " + f + " -o " + (d / "out").string() + " --t-end 0.25 --dt 0.1");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("error: --dt, --t-end: t_end = 0.25 is not a whole multiple of dt = 0.1"),
            std::string::npos)
      << r.out;
  EXPECT_FALSE(fs::exists(d / "out"));
}

// `check` lists the model's surfaces with their findings; a bad surface is a located error, exit 2.
TEST(Cli, CheckListsSurfacesAndRejectsBadOnes) {
  const fs::path d = temp_dir("surfaces");
  fs::copy_file(
      std::string(ISOFLEX_SOURCE_DIR) + "/tests/data/cad/l_angle_plate_2patch_L10_b1_b3_deg1.igs",
      d / "plate.igs");
  const std::string surfaces = std::string(kGood) + R"(surfaces:
  - name: web
    cad: {file: plate.igs, patch: 1}
  - name: roof
    builtin: {type: cylinder_sector, radius: 1, length: 2, angle: 90}
    refine: {elevate: [1, 1], knots_per_span: [3, 3]}
)";
  std::ofstream(d / "m.yaml") << surfaces;
  const auto r = run("check " + (d / "m.yaml").string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("surface          web: cad \"plate.igs\" patch 1 \"patch 1\"; degrees 1 x "
                       "1, control points 2 x 2 = 4, elements 1 x 1 = 1\n"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("  warning        degree 1 in u"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("                 fix: elevate the degree in u"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("surface          roof: builtin cylinder_sector; degrees 3 x 2, control "
                       "points 7 x 6 = 42, elements 4 x 4 = 16 (refined: elevate [1, 1], knots "
                       "per span [3, 3])\n"),
            std::string::npos)
      << r.out;

  const std::string f = (d / "bad.yaml").string();
  for (const auto& [from, to, expected] :
       {std::tuple<std::string, std::string, std::string>{
            "patch: 1", "patch: 7",
            ":15: surfaces[0].cad.patch: patch 7 out of range: \"plate.igs\" holds 2 patches (0 "
            "… 1)"},
        {"plate.igs", "missing.igs",
         ":15: surfaces[0].cad.file: cannot read CAD file \"" + (d / "missing.igs").string() +
             "\": no such file"},
        {"cylinder_sector", "cone", ":17: surfaces[1].builtin.type: unknown builtin type"}}) {
    std::ofstream(f) << with(surfaces, from, to);
    const auto k = run("check " + f);
    EXPECT_EQ(k.code, 2) << k.out;
    EXPECT_NE(k.out.find("error: " + f + expected), std::string::npos) << k.out;
    EXPECT_EQ(k.out.find("surface "), std::string::npos) << k.out;
    const auto r2 = run("run " + f + " -o " + (d / "out").string());
    EXPECT_EQ(r2.code, 2) << r2.out;
    EXPECT_FALSE(fs::exists(d / "out")) << "nothing is written for a bad model";
  }
}

// A Newton failure stops the run with the step and residual, keeps the results so far, exit 3.
TEST(Cli, NewtonFailureKeepsResultsAndSaysWhere) {
  const fs::path d = temp_dir("diverge");
  std::ofstream(d / "m.yaml") << with(kGood, "solver: {dt: 0.01, t_end: 0.2}",
                                      "solver: {dt: 0.01, t_end: 0.2, max_iterations: 1}");
  const auto r = run("run " + (d / "m.yaml").string() + " -o " + (d / "out").string() +
                     " --max-subdivisions 0");
  EXPECT_EQ(r.code, 3) << r.out;
  EXPECT_NE(r.out.find("step 1 (t = 0.01): Newton did not converge; residual"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find(" after 1 iterations (tolerance"), std::string::npos) << r.out;
  // The message says what to change.
  EXPECT_NE(r.out.find("; to get further: a smaller time step (solver.dt or --dt), more halvings "
                       "of a failing step (solver.max_subdivisions or --max-subdivisions, now 0, "
                       "at most 20), or more Newton iterations (solver.max_iterations, now 1)"),
            std::string::npos)
      << r.out;
  EXPECT_NE(read(d / "out/summary.json").find("\"status\": \"failed\""), std::string::npos);
  EXPECT_TRUE(fs::exists(d / "out/history.csv"));
  // By default a failing step is halved (up to 6 times): one iteration then suffices.
  const auto halved = run("run " + (d / "m.yaml").string() + " -o " + (d / "out").string());
  EXPECT_EQ(halved.code, 0) << halved.out;
  const std::string summary = read(d / "out/summary.json");
  EXPECT_NE(summary.find("\"status\": \"completed\""), std::string::npos);
  // summary.json says how many steps were halved, and counts the failed attempts' iterations.
  const auto count = [&](const std::string& key) {
    const auto at = summary.find("\"" + key + "\": ");
    return at == std::string::npos ? -1 : std::stoi(summary.substr(at + key.size() + 4));
  };
  EXPECT_GT(count("subdivided_steps"), 0) << summary;
  EXPECT_LE(count("subdivided_steps"), 20) << summary;
  EXPECT_GT(count("newton_iterations_total"), 2 * count("subdivided_steps")) << summary;
  EXPECT_EQ(run("run " + (d / "m.yaml").string() + " --max-subdivisions 21").code, 2);
}

// The plot scripts read what a run writes (history.csv, probes.csv, resultants.csv) and write
// their PNGs; bad input gives exit code 2.
TEST(Cli, PlotScriptsReadTheOutputs) {
  const fs::path d = temp_dir("plots");
  const std::string model = ISOFLEX_SOURCE_DIR "/examples/slider_crank_flexible/model.yaml";
  ASSERT_EQ(run("run " + model + " --t-end 0.05 -o " + d.string()).code, 0);
  const std::string tools = ISOFLEX_SOURCE_DIR "/tools/";
  const auto script = [&](const std::string& args) {
    const std::string cmd = "/usr/bin/python3 " + tools + args + " > /dev/null 2>&1";
    const int status = std::system(cmd.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  };
  EXPECT_EQ(script("plot_history.py " + (d / "history.csv").string() + " --reference-time 0.02"),
            0);
  EXPECT_EQ(script("plot_probes.py " + d.string() + " --probe connection"), 0);
  EXPECT_EQ(script("plot_resultants.py " + d.string() + " --element crank:10"), 0);
  for (const char* png :
       {"energy.png", "momentum.png", "constraints.png", "probe_connection.png",
        "probe_connection_components.png", "resultants.png", "resultants_norm.png"})
    EXPECT_GT(fs::file_size(d / png), 1000u) << png;
  EXPECT_EQ(script("plot_probes.py " + d.string() + " --probe no_such_probe"), 2);
  EXPECT_EQ(script("plot_resultants.py " + d.string() + " --element crank:99"), 2);
  EXPECT_EQ(script("plot_history.py " + (d / "missing.csv").string()), 2);
  fs::remove_all(d);
}

// Initial velocities that the joints do not admit are projected; `run` says so (it used to say
// nothing; only `check` did) and summary.json records the relative change, 0 when admissible.
TEST(Cli, RunWarnsOfProjectedInitialVelocities) {
  const fs::path d = temp_dir("v0");
  const std::string radial = with(kGood, "    position: [1, 0, 0]\n",
                                  "    position: [1, 0, 0]\n    velocity: [1, 0, 2]\n");
  for (const bool admissible : {false, true}) {
    std::ofstream(d / "m.yaml") << (admissible ? kGood : radial);
    const auto r = run("run " + (d / "m.yaml").string() + " -o " + (d / "out").string());
    ASSERT_EQ(r.code, 0) << r.out;
    const std::string s = read(d / "out/summary.json");
    const std::string key = "\"initial_velocity_projection\": ";
    const auto k = s.find(key);
    ASSERT_NE(k, std::string::npos) << s;
    const double change = std::stod(s.substr(k + key.size()));
    if (admissible) {
      EXPECT_EQ(change, 0.0);
      EXPECT_EQ(r.out.find("warning"), std::string::npos) << r.out;
      continue;
    }
    EXPECT_GT(change, 0.1);  // the radial velocity 1 of |v| = √5 removed (measured 0.775)
    char printed[32];
    std::snprintf(printed, sizeof printed, "%.3g", change);
    EXPECT_NE(r.out.find("warning: the initial velocities violate the joints; the run starts from "
                         "the nearest admissible ones (relative change " +
                         std::string(printed) + ", summary.json initial_velocity_projection)"),
              std::string::npos)
        << r.out;
  }
}
