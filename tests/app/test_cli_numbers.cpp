// Numerical hardening end to end (#15): joint layouts without freedom, far-off coordinates,
// non-finite results and absurdly thin shells end with counts, a message and an exit code.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

#include "support/cli.hpp"
#include "support/files.hpp"

namespace fs = std::filesystem;

namespace {
using isoflex::test::read_text;
using isoflex::test::run_isoflex;

const std::string kExamples = ISOFLEX_SOURCE_DIR "/examples/";

// `text` with the first `from` replaced by `to`.
std::string with(std::string text, const std::string& from, const std::string& to) {
  const auto p = text.find(from);
  EXPECT_NE(p, std::string::npos) << from;
  return p == std::string::npos ? text : text.replace(p, from.size(), to);
}

// Writes `text` as `name` into the test's directory and returns its path.
fs::path model_file(const isoflex::test::TempDir& d, const std::string& name,
                    const std::string& text) {
  std::ofstream(d.path() / name) << text;
  return d.path() / name;
}

isoflex::test::TempDir temp(const std::string& name) {
  return isoflex::test::TempDir(fs::temp_directory_path() /
                                ("isoflex_numbers_" + name + "_" + std::to_string(::getpid())));
}
}  // namespace

// The four-bar with joint O prismatic along z is locked (no freedom left): the initial velocity
// projection had an empty least-squares problem (an Eigen assertion, SIGABRT, before).
TEST(CliNumbers, LockedFourBarGivesCountsAndRuns) {
  const auto d = temp("locked_four_bar");
  const std::string text = with(read_text(kExamples + "four_bar/model.yaml"),
                                "{name: O, type: revolute", "{name: O, type: prismatic");
  const fs::path m = model_file(d, "m.yaml", text);
  const auto c = run_isoflex("check " + m.string());
  ASSERT_EQ(c.code, 0) << c.out;
  EXPECT_NE(c.out.find("dof              0  (n - m)"), std::string::npos) << c.out;
  EXPECT_NE(c.out.find("initial velocities violate the joints"), std::string::npos) << c.out;
  for (const char* f : {"reparametrized", "nullspace", "constrained"}) {
    const auto r = run_isoflex("run " + m.string() + " -o " + (d.path() / f).string() +
                               " --t-end 0.05 --formulation " + f);
    EXPECT_EQ(r.code, 0) << f << ": " << r.out;
  }
}

// A body fixed to the ground and also on a revolute joint: no tree coordinates, so the
// loop-closing rows have no columns (an empty matrix in the rank test, SIGABRT, before).
TEST(CliNumbers, LoopRowsWithoutFreedomAreAllRedundant) {
  const auto d = temp("no_freedom");
  const fs::path m = model_file(d, "m.yaml", R"(name: locked
gravity: [0, 0, -9.81]
solver: {dt: 0.01, t_end: 0.05}
bodies:
  - {name: a, mass: 1.0, inertia: [0.1, 0.1, 0.1], position: [1, 0, 0], velocity: [0, 1, 0]}
joints:
  - {type: fixed, body_b: a, point: [1, 0, 0]}
  - {type: revolute, body_a: ground, body_b: a, point: [0, 0, 0], axis: [0, 0, 1]}
)");
  const auto c = run_isoflex("check " + m.string());
  ASSERT_EQ(c.code, 0) << c.out;
  EXPECT_NE(c.out.find("redundant        5"), std::string::npos) << c.out;
  EXPECT_NE(c.out.find("tree coordinates 0"), std::string::npos) << c.out;
  const auto r = run_isoflex("run " + m.string() + " -o " + (d.path() / "out").string());
  EXPECT_EQ(r.code, 0) << r.out;
}

// A body 1e9 from the point of its prismatic joint: G Gᵀ of the multiplier estimate is singular
// to working precision (lever arms 1e9 beside unit entries), which failed every step ("constraint
// Jacobian rank deficient") before; the estimate now comes from a pivoted QR of Gᵀ
// (solve/normal_equations.cpp).
TEST(CliNumbers, FarOffPrismaticJointRuns) {
  const auto d = temp("far_off");
  const fs::path m = model_file(d, "m.yaml", R"(name: far
gravity: [0, 0, -9.81]
solver: {dt: 0.01, t_end: 0.1}
bodies:
  - {name: bob, mass: 1.0, inertia: [0.1, 0.1, 0.1], position: [0, 1e9, 0], velocity: [1, 0, 0]}
joints:
  - {type: prismatic, body_a: ground, body_b: bob, point: [0, 0, 0], axis: [1, 0, 0]}
)");
  ASSERT_EQ(run_isoflex("check " + m.string()).code, 0);
  for (const char* f : {"reparametrized", "nullspace"}) {
    const fs::path out = d.path() / f;
    const auto r = run_isoflex("run " + m.string() + " -o " + out.string() + " --formulation " + f);
    EXPECT_EQ(r.code, 0) << f << ": " << r.out;
    EXPECT_NE(read_text(out / "summary.json").find("\"status\": \"completed\""), std::string::npos);
  }
  // The constrained form's Newton matrix holds G itself; whatever it does, it ends with a
  // status and a summary, never an abort.
  const fs::path out = d.path() / "constrained";
  const auto r =
      run_isoflex("run " + m.string() + " -o " + out.string() + " --formulation constrained");
  EXPECT_TRUE(r.code == 0 || r.code == 3) << r.out;
  EXPECT_TRUE(fs::exists(out / "summary.json")) << r.out;
}

// The pinched hemisphere (coarse) under a load of 1e300: the linear solve gives displacements of
// 1e298 and a strain energy that overflows (-nan); the run said "completed", exit 0, before. The
// correction, 10²⁹⁷ times the model's size, now fails the load step itself (static_newton.cpp:
// no static correction is 10⁸ times the model), before non_finite_results would catch the
// energy.
TEST(CliNumbers, NonFiniteResultsFailTheRun) {
  const auto d = temp("non_finite");
  std::string text = read_text(kExamples + "pinched_hemisphere/kl_shell_hole.yaml");
  text = with(text, "knots_per_span: [15, 15]", "knots_per_span: [3, 3]");
  text = with(text, R"(force: ["t", 0, 0])", R"(force: ["1e300*t", 0, 0])");
  const fs::path m = model_file(d, "m.yaml", text);
  const fs::path out = d.path() / "out";
  const auto r = run_isoflex("run " + m.string() + " --max-subdivisions 0 -o " + out.string());
  EXPECT_EQ(r.code, 3) << r.out;
  EXPECT_NE(r.out.find("load step 1 did not converge at load factor 1"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("times the size of the model"), std::string::npos) << r.out;
  const std::string s = read_text(out / "summary.json");
  EXPECT_NE(s.find("\"status\": \"failed\""), std::string::npos) << s;
  EXPECT_NE(s.find("times the size of the model"), std::string::npos) << s;
  // The outputs end with the last finite step (the initial state).
  const std::string h = read_text(out / "history.csv");
  EXPECT_EQ(std::count(h.begin(), h.end(), '\n'), 2) << h;
  EXPECT_EQ(h.find("nan"), std::string::npos) << h;
  EXPECT_TRUE(fs::exists(out / "results.pvd"));
}

// A Kirchhoff–Love shell 4e-302 thick on a hemisphere of radius 10: a located model error for
// check and run (it ran to "completed" with -nan energy and 1e304 displacements before).
TEST(CliNumbers, AbsurdlyThinKLShellIsAModelError) {
  const auto d = temp("thin_kl");
  std::string text = read_text(kExamples + "pinched_hemisphere/kl_shell_hole.yaml");
  text = with(text, "thickness: 0.04}", "thickness: 4.0000000000000004e-302}");
  const fs::path m = model_file(d, "m.yaml", text);
  const std::string run = "run " + m.string() + " -o " + (d.path() / "out").string();
  for (const std::string& args : {"check " + m.string(), run}) {
    const auto r = run_isoflex(args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.out;
    EXPECT_NE(r.out.find("m.yaml:26: kl_shells[0].material.thickness: 4.0000000000000004e-302 "
                         "is below 1e-12 x the model size"),
              std::string::npos)
        << r.out;
  }
  EXPECT_FALSE(fs::exists(d.path() / "out" / "summary.json"));
}

// The same bound for a director shell (its nodes' bounding box).
TEST(CliNumbers, AbsurdlyThinDirectorShellIsAModelError) {
  const auto d = temp("thin_director");
  const std::string text = read_text(kExamples + "pinched_hemisphere/director_shell.yaml");
  const auto at = text.find("thickness: ");
  ASSERT_NE(at, std::string::npos);
  const auto end = text.find_first_of(",}", at);
  const fs::path m =
      model_file(d, "m.yaml", text.substr(0, at) + "thickness: 1e-20" + text.substr(end));
  const auto r = run_isoflex("check " + m.string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("shells[0].material.thickness: 1e-20 is below 1e-12 x the model size"),
            std::string::npos)
      << r.out;
}
