// --set KEY=VALUE (io/model_overrides.hpp): values set over the model file's, by a path of map
// keys and list entries (by index or by name), checked like the file's own; a path that leads
// nowhere and a bad value are located errors that name the --set.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "isoflex/io/model_reader.hpp"

using namespace isoflex;

namespace {

const std::string kModel =
    "name: two\n"
    "solver: {dt: 0.01, t_end: 1}\n"
    "bodies:\n"
    "  - {name: a, mass: 1, inertia: [1, 1, 1], position: [0, 0, 0]}\n"
    "  - {name: b, mass: 2, inertia: [1, 1, 1], position: [1, 0, 0]}\n";

model::Model read(const std::vector<std::string>& sets) {
  io::ReadOptions o;
  for (const auto& s : sets) o.overrides.push_back(io::parse_model_override(s));
  return io::read_model_string(kModel, "m.yaml", o);
}

std::string error_of(const std::vector<std::string>& sets) {
  try {
    read(sets);
  } catch (const io::ModelError& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace

TEST(ModelOverrides, SetValuesByKeyIndexAndName) {
  const model::Model m = read({"solver.dt=1e-3", "bodies[0].mass=3", "bodies[b].mass=4.5",
                               "bodies[b].position=[2, 0, 0]", "output.vtk_every=0",
                               "gravity=[0, 0, -9.81]", "solver.t_end=0.5"});
  EXPECT_EQ(m.solver.dt, 1e-3);
  EXPECT_EQ(m.solver.t_end, 0.5);
  EXPECT_EQ(m.bodies[0].mass, 3.0);
  EXPECT_EQ(m.bodies[1].mass, 4.5);
  EXPECT_EQ(m.bodies[1].position.x(), 2.0);
  EXPECT_EQ(m.output.vtk_every, 0);
  EXPECT_EQ(m.gravity.z(), -9.81);
  // The later of two settings of one key wins.
  EXPECT_EQ(read({"bodies[a].mass=5", "bodies[0].mass=6"}).bodies[0].mass, 6.0);
}

TEST(ModelOverrides, PathsThatLeadNowhereAreLocated) {
  EXPECT_EQ(error_of({"bodies[2].mass=1"}),
            "m.yaml: bodies[2].mass: --set: bodies has 2 entries, no [2]");
  EXPECT_EQ(error_of({"bodies[c].mass=1"}),
            "m.yaml: bodies[c].mass: --set: bodies has no entry named \"c\"");
  EXPECT_EQ(error_of({"solver.dt.x=1"}), "m.yaml: solver.dt.x: --set: solver.dt is not a map");
  EXPECT_EQ(error_of({"solver[0]=1"}), "m.yaml: solver[0]: --set: solver is not a list");
  EXPECT_EQ(error_of({"solver..dt=1"}), "m.yaml: solver..dt: --set: an empty key in the path");
  EXPECT_NE(error_of({"solver.dt=[1, 2"})
                .find("m.yaml: solver.dt: --set: the value \"[1, 2\" is "
                      "not YAML"),
            std::string::npos);
  EXPECT_THROW(io::parse_model_override("solver.dt"), std::invalid_argument);
  EXPECT_THROW(io::parse_model_override("=1"), std::invalid_argument);
  EXPECT_EQ(io::parse_model_override("loads[0].force=[0, 0, \"t=1\"]").value,
            "[0, 0, \"t=1\"]");  // split at the first '='
}

// A value set over the file's is checked as the file's own; its message names the --set, not a
// line of the file.
TEST(ModelOverrides, BadValuesNameTheSet) {
  EXPECT_EQ(error_of({"bodies[b].mass=-1"}),
            "m.yaml: bodies[1].mass: must be > 0, got -1 (the value of --set "
            "bodies[b].mass=-1)");
  EXPECT_EQ(error_of({"solver.dtt=1"}).rfind("m.yaml: solver.dtt: unknown key", 0), 0u);
  EXPECT_NE(error_of({"solver.dtt=1"}).find("(the value of --set solver.dtt=1)"),
            std::string::npos);
  // Of two settings of one key, the message names the one in effect, the last.
  EXPECT_EQ(error_of({"bodies[b].mass=2", "bodies[b].mass=-1"}),
            "m.yaml: bodies[1].mass: must be > 0, got -1 (the value of --set "
            "bodies[b].mass=-1)");
  // An error elsewhere in the file keeps its line.
  io::ReadOptions o;
  o.overrides.push_back(io::parse_model_override("solver.dt=0.5"));
  try {
    io::read_model_string(kModel + "  - {name: c, mass: 0, inertia: [1, 1, 1]}\n", "m.yaml", o);
    FAIL() << "no error";
  } catch (const io::ModelError& e) {
    EXPECT_EQ(e.line(), 6) << e.what();
  }
}
