// `isoflex check` and `isoflex run --static` on a Kirchhoff–Love shell model end to end: the
// counts printed, the outputs written (summary.json probe, probes.csv, history.csv, VTU with the
// stress fields in either output.vtk_format, results.pvd), located errors with exit code 2 and a
// Newton failure with exit 3.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "support/cli.hpp"
#include "support/files.hpp"
#include "support/kl_plate_grid.hpp"
#include "support/run_outputs.hpp"
#include "support/vtu.hpp"

namespace fs = std::filesystem;

namespace {
using Result = isoflex::test::CliResult;

Result run(const std::string& args) {
  return isoflex::test::run_isoflex(args);
}

fs::path temp_dir(const std::string& name) {
  return isoflex::test::temp_dir("isoflex_klcli_", name);
}

std::string read(const fs::path& p) {
  return isoflex::test::read_text(p);
}

// A simply supported square plate a = 1, t = 0.01, E = 1e6, ν = 0.3, uniform q = 1 (p = 3, 8×8):
// centre deflection ≈ 0.00406235 q a⁴/D (references.md).
std::string plate(const std::string& extra = "") {
  return "name: plate\n"
         "solver: {analysis: static, dt: 0.5, t_end: 1, linear: true}\n"
         "surfaces:\n"
         "  - name: sq\n"
         "    builtin: {type: rectangle, size: [1, 1]}\n"
         "    refine: {elevate: [2, 2], knots_per_span: [7, 7]}\n"
         "kl_shells:\n"
         "  - name: plate\n"
         "    surface: sq\n"
         "    material: {E: 1e6, nu: 0.3, thickness: 0.01}\n"
         "kl_supports:\n"
         "  - {shell: plate, edge: u0, fixed: all}\n"
         "  - {shell: plate, edge: u1, fixed: all}\n"
         "  - {shell: plate, edge: v0, fixed: all}\n"
         "  - {shell: plate, edge: v1, fixed: all}\n"
         "kl_loads:\n"
         "  - {shell: plate, area_force: [0, 0, \"-t\"]}\n"
         "probes:\n"
         "  - {name: ref, shell: plate, point: [0.5, 0.5, 0]}\n" +
         extra;
}
}  // namespace

TEST(KLCli, CheckPrintsTheShellCounts) {
  const fs::path d = temp_dir("check");
  std::ofstream(d / "m.yaml") << plate();
  const Result r = run("check " + (d / "m.yaml").string());
  ASSERT_EQ(r.code, 0) << r.out;
  // p = 3 with 8 spans: 11 × 11 control points; the four edges fix 40 of them entirely.
  EXPECT_NE(r.out.find("control points   121 (3 coordinates each)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("dofs             363"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("eliminated       120"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("unknowns         243"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("64 elements, 1024 quadrature points (4 x 4 per element"), std::string::npos)
      << r.out;
}

TEST(KLCli, StaticRunWritesOutputsAndTheProbe) {
  const fs::path d = temp_dir("run");
  std::ofstream(d / "m.yaml") << plate();
  const Result r = run("run --static " + (d / "m.yaml").string() + " -o " + (d / "out").string());
  ASSERT_EQ(r.code, 0) << r.out;
  const double D = 1e6 * 1e-6 / (12 * (1 - 0.09));
  const double w = 0.00406235 / D;
  const std::string summary = read(d / "out" / "summary.json");
  const auto at = summary.find("\"displacement\": [");
  ASSERT_NE(at, std::string::npos) << summary;
  double ux, uy, uz;
  ASSERT_EQ(std::sscanf(summary.c_str() + at + 17, "%lf, %lf, %lf", &ux, &uy, &uz), 3) << summary;
  EXPECT_NEAR(-uz / w, 1.0, 5e-3);
  EXPECT_NEAR(ux, 0.0, 1e-12);
  // Two load steps, linear: the probe at t = 0.5 is half the final one.
  const std::string probes = read(d / "out" / "probes.csv");
  EXPECT_NE(probes.find("\n0.5,ref,"), std::string::npos) << probes;
  EXPECT_NE(read(d / "out" / "history.csv").find("\n1,"), std::string::npos);
  // The patch is part 1 of each step's ParaView data (part 0: bodies, beams, director shells).
  const std::string vtu = read(d / "out" / "vtk" / "plate_000002.vtu");
  for (const char* name : {"displacement", "\"n\"", "\"m\"", "sigma_top", "sigma_bottom",
                           "principal_top", "von_mises_top", "von_mises_bottom", "e1"})
    EXPECT_NE(vtu.find(name), std::string::npos) << name;
  // 1 024 quadrature points: one assembly thread whatever --threads asks (default: all cores).
  EXPECT_NE(summary.find("\"threads\": 1,"), std::string::npos) << summary;
  const std::string pvd = read(d / "out" / "results.pvd");
  EXPECT_NE(pvd.find("timestep=\"1\" group=\"\" part=\"1\" file=\"vtk/plate_000002.vtu\""),
            std::string::npos)
      << pvd;
}

// output.vtk_format: binary by default (every array appended raw), ascii when the file or
// `--set output.vtk_format=ascii` says so (no appended data), the same arrays either way; a value
// other than binary and ascii is a located error.
TEST(KLCli, VtkFormatIsBinaryByDefaultAndAsciiOnRequest) {
  const fs::path d = temp_dir("vtk_format");
  const std::string model = (d / "m.yaml").string();
  std::ofstream(d / "m.yaml") << plate();
  ASSERT_EQ(run("run --static " + model + " -o " + (d / "bin").string()).code, 0);
  const Result r = run("run --static " + model + " -o " + (d / "ascii").string() +
                       " --set output.vtk_format=ascii");
  ASSERT_EQ(r.code, 0) << r.out;
  const auto files = isoflex::test::expect_consistent_vtk_series(d / "bin");
  EXPECT_EQ(isoflex::test::expect_consistent_vtk_series(d / "ascii"), files);
  ASSERT_EQ(files.size(), 6u);  // the step file and the patch file of t = 0, 0.5, 1
  for (const auto& f : files) {
    SCOPED_TRACE(f);
    const std::string bin = read(d / "bin" / f), ascii = read(d / "ascii" / f);
    EXPECT_NE(bin.find("<AppendedData encoding=\"raw\">"), std::string::npos);
    EXPECT_EQ(bin.find("format=\"ascii\""), std::string::npos);
    EXPECT_EQ(ascii.find("AppendedData"), std::string::npos);
    EXPECT_EQ(ascii.find("format=\"appended\""), std::string::npos);
    const auto names = isoflex::test::data_array_names(bin, "VTKFile");
    EXPECT_EQ(isoflex::test::data_array_names(ascii, "VTKFile"), names);
    for (const auto& name : names)
      EXPECT_EQ(isoflex::test::data_array(ascii, name), isoflex::test::data_array(bin, name))
          << name;
  }
  EXPECT_EQ(
      isoflex::test::data_array(read(d / "bin" / "vtk" / "plate_000002.vtu"), "Points").size(),
      3u * 33 * 33);  // 8 × 8 elements, 4 × 4 quads each

  std::ofstream(d / "ascii.yaml") << plate() << "output: {vtk_format: ascii}\n";
  ASSERT_EQ(
      run("run --static " + (d / "ascii.yaml").string() + " -o " + (d / "file").string()).code, 0);
  EXPECT_EQ(read(d / "file" / "vtk" / "plate_000002.vtu"),
            read(d / "ascii" / "vtk" / "plate_000002.vtu"));

  std::ofstream(d / "bad.yaml") << plate() << "output:\n  vtk_format: raw\n";
  const Result bad =
      run("run --static " + (d / "bad.yaml").string() + " -o " + (d / "bad").string());
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.out.find("bad.yaml:21: output.vtk_format: unknown format \"raw\" (valid: binary, "
                         "ascii)"),
            std::string::npos)
      << bad.out;
  const Result set = run("check " + model + " --set output.vtk_format=raw");
  EXPECT_EQ(set.code, 2);
  EXPECT_NE(set.out.find("output.vtk_format: unknown format \"raw\" (valid: binary, ascii) (the "
                         "value of --set output.vtk_format=raw)"),
            std::string::npos)
      << set.out;
  fs::remove_all(d);
}

// --threads: the same results bit for bit on 1 and 3 threads (24 × 24 elements, 9 216 points:
// 3 threads are used), geometrically nonlinear so that Newton sees r and K of every iteration;
// summary.json says how many threads ran.
TEST(KLCli, ThreadsGiveTheSameResults) {
  const fs::path d = temp_dir("threads");
  std::string m = plate();
  const auto replace = [&m](const std::string& a, const std::string& b) {
    const auto at = m.find(a);
    ASSERT_NE(at, std::string::npos) << a;
    m.replace(at, a.size(), b);
  };
  replace("linear: true", "linear: false");
  replace("knots_per_span: [7, 7]", "knots_per_span: [23, 23]");
  replace("area_force: [0, 0, \"-t\"]", "area_force: [0, 0, \"-100 * t\"]");
  std::ofstream(d / "m.yaml") << m;
  for (const char* t : {"1", "3"}) {
    const Result r = run("run --static --threads " + std::string(t) + " " +
                         (d / "m.yaml").string() + " -o " + (d / t).string());
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_NE(read(d / t / "summary.json").find(std::string("\"threads\": ") + t),
              std::string::npos);
  }
  const std::string probes = read(d / "1" / "probes.csv");
  EXPECT_EQ(read(d / "3" / "probes.csv"), probes);
  EXPECT_EQ(read(d / "3" / "vtk" / "plate_000002.vtu"), read(d / "1" / "vtk" / "plate_000002.vtu"));
  // history.csv: Newton iterations and final residuals of every load step, the same too.
  EXPECT_EQ(read(d / "3" / "history.csv"), read(d / "1" / "history.csv"));
  EXPECT_NE(probes.find("\n1,ref,"), std::string::npos) << probes;
  EXPECT_EQ(run("run --static --threads -1 " + (d / "m.yaml").string()).code, 2);
}

TEST(KLCli, BadInputExitsWith2) {
  const fs::path d = temp_dir("bad");
  // Degree 1 geometry (no refine).
  std::string m = plate();
  const std::string refine = "    refine: {elevate: [2, 2], knots_per_span: [7, 7]}\n";
  m.replace(m.find(refine), refine.size(), "");
  std::ofstream(d / "deg1.yaml") << m;
  Result r = run("run --static " + (d / "deg1.yaml").string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("deg1.yaml:8: kl_shells[0].surface: surface \"sq\" has degrees (1, 1)"),
            std::string::npos)
      << r.out;
  // A load point off the surface.
  std::ofstream(d / "off.yaml") << plate("  - {name: off, shell: plate, point: [0.5, 0.5, 0.1]}\n");
  r = run("check " + (d / "off.yaml").string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("off.yaml:20: probes[1].point: the point (0.5, 0.5, 0.1) is not on surface "
                       "\"sq\""),
            std::string::npos)
      << r.out;
  // An unknown CAD patch.
  std::ofstream(d / "cad.yaml")
      << "surfaces:\n  - name: s\n    cad: {file: \"" ISOFLEX_SOURCE_DIR
         "/tests/data/cad/quarter_cylinder_R1_L2_deg2.igs\", patch: 7}\n"
         "kl_shells:\n  - {name: k, surface: s, material: {E: 1, nu: 0, thickness: 1}}\n";
  r = run("check " + (d / "cad.yaml").string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("cad.yaml:3: surfaces[0].cad.patch:"), std::string::npos) << r.out;
  // A dynamic analysis needs the shell's mass: without a density the static plate run as dynamic
  // is refused (it would give a wrong answer silently).
  std::string dynamic = plate();
  dynamic.replace(dynamic.find("analysis: static"), 16, "analysis: dynamic");
  std::ofstream(d / "m.yaml") << dynamic;
  r = run("run " + (d / "m.yaml").string() + " -o " + (d / "o").string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("m.yaml:8: kl_shells[0].material.density: a dynamic run needs the shell's "
                       "mass"),
            std::string::npos)
      << r.out;
  // A prescribed displacement in a dynamic run starts at 0.
  dynamic.replace(dynamic.find("thickness: 0.01}"), 16, "thickness: 0.01, density: 1}");
  dynamic.replace(dynamic.find("fixed: all"), 10, "displacement: [0, 0, \"1+t\"]");
  std::ofstream(d / "m.yaml") << dynamic;
  r = run("run " + (d / "m.yaml").string() + " -o " + (d / "o").string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("m.yaml:12: kl_supports[0].displacement[2]: '1+t' is 1 at t = 0"),
            std::string::npos)
      << r.out;
  EXPECT_FALSE(fs::exists(d / "o" / "summary.json"));
}

TEST(KLCli, NewtonFailureKeepsResultsAndSaysWhere) {
  const fs::path d = temp_dir("fail");
  std::string m = plate();
  // Nonlinear, a huge pressure jump at the second step, one iteration allowed.
  m.replace(m.find("linear: true"), 12, "max_iterations: 1");
  m.replace(m.find("\"-t\""), 4, "\"-1e3*t*(t>0.6)\"");
  std::ofstream(d / "m.yaml") << m;
  const Result r = run("run --static --max-subdivisions 0 " + (d / "m.yaml").string() + " -o " +
                       (d / "out").string());
  EXPECT_EQ(r.code, 3) << r.out;
  EXPECT_NE(r.out.find("load step 2"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("; to get further: more load steps (a smaller solver.dt), more halvings of "
                       "a failing load step (solver.max_subdivisions or --max-subdivisions, now "
                       "0, at most 20), more Newton iterations (solver.max_iterations, now 1), or "
                       "path following past a limit point (solver.path_following)"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("results up to load step 1, t = 0.5"), std::string::npos) << r.out;
  EXPECT_NE(read(d / "out" / "summary.json").find("\"status\": \"failed\""), std::string::npos);
  EXPECT_TRUE(fs::exists(d / "out" / "vtk" / "plate_000001.vtu"));
}

TEST(KLCli, CheckCountsNodeAndConstraintKindsOfAPatchOnABody) {
  const Result r =
      run("check " + std::string(ISOFLEX_SOURCE_DIR) + "/examples/kl_plate_on_hub/model.yaml");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("nodes            56 (1 frame nodes, 12 coordinates each; 55 point nodes, "
                       "3 coordinates each)"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("constraint rows  internal 6; kl_support 30 (10 joints)"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("unknowns         constrained 213, nullspace 177, reparametrized 141"),
            std::string::npos)
      << r.out;
}

// summary.json counts the augmented Lagrangian's work (docs/theory/solvers.md) where it was
// tried, and has no such keys where the saddle point went to the LU.
TEST(KLCli, SummaryCountsTheSaddlePointSolvesOfTheAugmentedLagrangian) {
  const fs::path d = temp_dir("saddle_point");
  fs::create_directories(d);
  for (const std::string solver : {"augmented_lagrangian", "lu"}) {
    isoflex::test::PlateGrid g;
    g.pu = g.pv = 3;
    g.coupling = "strip_constraints";
    g.solver = "{analysis: static, dt: 1, t_end: 1, saddle_point_solver: " + solver + "}";
    const fs::path m = d / (solver + ".yaml");
    std::ofstream(m) << isoflex::test::plate_grid_yaml(g);
    const Result r = run("run " + m.string() + " -o " + (d / solver).string());
    ASSERT_EQ(r.code, 0) << r.out;
    const std::string s = read(d / solver / "summary.json");
    if (solver == "lu") {
      EXPECT_EQ(s.find("krylov_iterations_total"), std::string::npos) << s;
      continue;
    }
    EXPECT_NE(s.find("\"saddle_point_fallbacks\": 0,"), std::string::npos) << s;
    const auto k = s.find("\"krylov_iterations_total\": ");
    ASSERT_NE(k, std::string::npos) << s;
    EXPECT_GT(std::stoi(s.substr(k + 27)), 0) << s;  // measured 34
  }
  fs::remove_all(d);
}

// Gravity acts on bodies, beams and director shells from their mass data, on a Kirchhoff–Love
// shell only through a self_weight load: a shell under gravity without one gets a warning from
// check and run (model::gravity_warnings), and none once it has it.
TEST(KLCli, GravityWithoutSelfWeightIsAWarning) {
  const fs::path d = temp_dir("gravity");
  fs::create_directories(d);
  const std::string warning =
      "kl_shells[0] (plate): the model's gravity does not act on a Kirchhoff-Love shell without a "
      "self_weight load (kl_loads: - {shell: plate, self_weight: 1}, which needs the material's "
      "density)";
  std::ofstream(d / "bare.yaml") << plate("gravity: [0, 0, -9.81]\n");
  EXPECT_NE(run("check " + (d / "bare.yaml").string()).out.find("warning          " + warning),
            std::string::npos);
  const Result r = run("run " + (d / "bare.yaml").string() + " -o " + (d / "bare").string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("warning: " + warning), std::string::npos) << r.out;
  std::string weighed = plate("gravity: [0, 0, -9.81]\n");
  weighed.replace(weighed.find("thickness: 0.01}"), 16, "thickness: 0.01, density: 100}");
  weighed.replace(weighed.find("kl_loads:\n"), 10,
                  "kl_loads:\n  - {shell: plate, self_weight: 1}\n");
  std::ofstream(d / "weighed.yaml") << weighed;
  const Result w = run("run " + (d / "weighed.yaml").string() + " -o " + (d / "w").string());
  ASSERT_EQ(w.code, 0) << w.out;
  EXPECT_EQ(w.out.find("warning"), std::string::npos) << w.out;
  fs::remove_all(d);
}
