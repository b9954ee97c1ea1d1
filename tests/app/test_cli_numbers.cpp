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
