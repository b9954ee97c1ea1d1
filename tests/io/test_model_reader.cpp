#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <string>
#include <string_view>
#include <vector>

#include "isoflex/io/model_error.hpp"
#include "isoflex/io/model_reader.hpp"
#include "support/files.hpp"
#include "support/model_errors.hpp"

using namespace isoflex;
using isoflex::io::ModelError;
using isoflex::io::read_model;
using isoflex::io::read_model_string;
using isoflex::test::error_of;

namespace {

// Joins lines with '\n' so that the line numbers of a test model are explicit (first = line 1).
std::string lines(std::initializer_list<std::string_view> ls) {
  std::string s;
  for (const auto l : ls) {
    s += l;
    s += '\n';
  }
  return s;
}

// A valid body list occupying lines 1-5.
constexpr std::string_view kBodies[] = {"bodies:", "  - name: top", "    mass: 1",
                                        "    inertia: [1, 1, 1]", "    position: [0, 0, 0]"};

// kBodies followed by `more`.
std::string with_bodies(std::initializer_list<std::string_view> more) {
  std::string s;
  for (const auto l : kBodies) s += std::string(l) + '\n';
  for (const auto l : more) s += std::string(l) + '\n';
  return s;
}

std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("isoflex_test_" + std::to_string(::getpid()) + "_" + name))
      .string();
}

const std::string kValid = lines({
    "name: heavy_top",                                                             // 1
    "gravity: [0, 0, -9.81]",                                                      // 2
    "solver:",                                                                     // 3
    "  formulation: nullspace",                                                    // 4
    "  dt: 0.005",                                                                 // 5
    "  t_end: 2",                                                                  // 6
    "  residual_tolerance: 1e-9",                                                  // 7
    "  increment_tolerance: 1e-11",                                                // 8
    "  max_iterations: 30",                                                        // 9
    "output:",                                                                     // 10
    "  vtk_every: 0",                                                              // 11
    "  history: false",                                                            // 12
    "joints:          # before the bodies they name",                              // 13
    "  - type: spherical",                                                         // 14
    "    body_b: top",                                                             // 15
    "    point: [0, 0, 0]",                                                        // 16
    "  - name: hinge",                                                             // 17
    "    type: universal",                                                         // 18
    "    body_a: top",                                                             // 19
    "    body_b: arm",                                                             // 20
    "    point_b: [0, 0, -0.5]",                                                   // 21
    "    axis: [0, 0, 2]",                                                         // 22
    "    axis2: [1, 0, 0]",                                                        // 23
    "bodies:",                                                                     // 24
    "  - name: top",                                                               // 25
    "    mass: 1.0",                                                               // 26
    "    inertia: [0.625, 0.625, 0.25]",                                           // 27
    "    position: [0, 0, 1]",                                                     // 28
    "    angular_velocity: [0, 0, 50]",                                            // 29
    "    shape: {type: cylinder, radius: 0.5, height: 0.1, offset: [0, 0, 0.2]}",  // 30
    "  - name: arm",                                                               // 31
    "    mass: 2",                                                                 // 32
    "    inertia: [1, 2, 3]",                                                      // 33
    "    position: [1, 2, 3]",                                                     // 34
    "    orientation: [[0, 1, 0], [-1, 0, 0], [0, 0, 1]]",                         // 35
    "    velocity: [1, 0, 0]",                                                     // 36
    "    shape: {type: box, size: [1, 2, 3]}",                                     // 37
    "loads:",                                                                      // 38
    "  - name: push",                                                              // 39
    "    body: arm",                                                               // 40
    "    force: [\"1000*sin(pi*t)*(t<=2)\", 0, \"0\"]",                            // 41
    "    point_local: [0, 0, 1]",                                                  // 42
    "  - body: top",                                                               // 43
    "    moment: [0, 0, \"2*t\"]",                                                 // 44
    "probes:",                                                                     // 45
    "  - name: tip",                                                               // 46
    "    body: top",                                                               // 47
    "    point: [0, 0, 1.5]",                                                      // 48
    "  - name: c",                                                                 // 49
    "    body: arm",                                                               // 50
});

}  // namespace

TEST(ModelReader, ReadsAllValuesOfAValidModel) {
  const model::Model m = read_model_string(kValid, "m.yaml");
  EXPECT_EQ(m.name, "heavy_top");
  EXPECT_EQ(m.file, "m.yaml");
  EXPECT_EQ(m.gravity, Vec3(0, 0, -9.81));
  EXPECT_EQ(m.solver.formulation, model::Formulation::nullspace);
  EXPECT_EQ(m.solver.dt, 0.005);
  EXPECT_EQ(m.solver.t_end, 2.0);
  EXPECT_EQ(m.solver.residual_tolerance, 1e-9);
  EXPECT_EQ(m.solver.increment_tolerance, 1e-11);
  EXPECT_EQ(m.solver.max_iterations, 30);
  EXPECT_EQ(m.output.vtk_every, 0);
  EXPECT_FALSE(m.output.history);

  ASSERT_EQ(m.bodies.size(), 2u);
  const model::Body& top = m.bodies[0];
  EXPECT_EQ(top.name, "top");
  EXPECT_EQ(top.mass, 1.0);
  EXPECT_EQ(top.inertia, Vec3(0.625, 0.625, 0.25));
  EXPECT_EQ(top.position, Vec3(0, 0, 1));
  EXPECT_EQ(top.orientation, Mat3::Identity());
  EXPECT_EQ(top.velocity, Vec3::Zero());
  EXPECT_EQ(top.angular_velocity, Vec3(0, 0, 50));
  EXPECT_EQ(top.shape.kind, model::ShapeKind::cylinder);
  EXPECT_EQ(top.shape.radius, 0.5);
  EXPECT_EQ(top.shape.height, 0.1);
  EXPECT_EQ(top.shape.offset, Vec3(0, 0, 0.2));
  EXPECT_EQ(top.source.file, "m.yaml");
  EXPECT_EQ(top.source.line, 25);
  const model::Body& arm = m.bodies[1];
  EXPECT_EQ(arm.mass, 2.0);
  EXPECT_EQ(arm.inertia, Vec3(1, 2, 3));
  Mat3 R;
  R.col(0) = Vec3(0, 1, 0);  // the rows of the file are the axes d1, d2, d3
  R.col(1) = Vec3(-1, 0, 0);
  R.col(2) = Vec3(0, 0, 1);
  EXPECT_EQ(arm.orientation, R);
  EXPECT_EQ(arm.velocity, Vec3(1, 0, 0));
  EXPECT_EQ(arm.shape.kind, model::ShapeKind::box);
  EXPECT_EQ(arm.shape.size, Vec3(1, 2, 3));
  EXPECT_EQ(arm.shape.offset, Vec3::Zero());
  EXPECT_EQ(arm.source.line, 31);

  ASSERT_EQ(m.joints.size(), 2u);
  const model::Joint& j0 = m.joints[0];
  EXPECT_EQ(j0.name, "joint0");
  EXPECT_EQ(j0.type, model::JointType::spherical);
  EXPECT_EQ(j0.body_a, "ground");
  EXPECT_EQ(j0.body_b, "top");
  ASSERT_TRUE(j0.point);
  EXPECT_EQ(*j0.point, Vec3::Zero());
  EXPECT_FALSE(j0.point_b || j0.axis || j0.axis2);
  EXPECT_EQ(j0.source.line, 14);
  const model::Joint& j1 = m.joints[1];
  EXPECT_EQ(j1.name, "hinge");
  EXPECT_EQ(j1.type, model::JointType::universal);
  EXPECT_EQ(j1.body_a, "top");
  EXPECT_EQ(j1.body_b, "arm");
  EXPECT_FALSE(j1.point);
  ASSERT_TRUE(j1.point_b && j1.axis && j1.axis2);
  EXPECT_EQ(*j1.point_b, Vec3(0, 0, -0.5));
  EXPECT_EQ(*j1.axis, Vec3(0, 0, 1));  // normalized
  EXPECT_EQ(*j1.axis2, Vec3(1, 0, 0));
  EXPECT_EQ(j1.source.line, 17);

  ASSERT_EQ(m.loads.size(), 2u);
  const model::Load& push = m.loads[0];
  EXPECT_EQ(push.name, "push");
  EXPECT_EQ(push.body, "arm");
  ASSERT_TRUE(push.force);
  EXPECT_EQ((*push.force)[0], "1000*sin(pi*t)*(t<=2)");
  EXPECT_EQ((*push.force)[1], "0");
  EXPECT_EQ((*push.force)[2], "0");
  EXPECT_FALSE(push.moment);
  EXPECT_FALSE(push.point);
  ASSERT_TRUE(push.point_local);
  EXPECT_EQ(*push.point_local, Vec3(0, 0, 1));
  EXPECT_EQ(push.source.line, 39);
  const model::Load& twist = m.loads[1];
  EXPECT_EQ(twist.name, "load1");
  EXPECT_EQ(twist.body, "top");
  EXPECT_FALSE(twist.force);
  ASSERT_TRUE(twist.moment);
  EXPECT_EQ((*twist.moment)[2], "2*t");
  EXPECT_EQ(twist.source.line, 43);

  ASSERT_EQ(m.probes.size(), 2u);
  EXPECT_EQ(m.probes[0].name, "tip");
  EXPECT_EQ(m.probes[0].body, "top");
  ASSERT_TRUE(m.probes[0].point);
  EXPECT_EQ(*m.probes[0].point, Vec3(0, 0, 1.5));
  EXPECT_EQ(m.probes[0].source.line, 46);
  EXPECT_EQ(m.probes[1].body, "arm");
  EXPECT_FALSE(m.probes[1].point || m.probes[1].point_local);
  EXPECT_EQ(m.probes[1].source.line, 49);
}

TEST(ModelReader, DefaultsOfAMinimalModel) {
  const model::Model m = read_model_string(with_bodies({"joints:"}), "m.yaml");
  const model::Model defaults;
  EXPECT_EQ(m.name, "");
  EXPECT_EQ(m.gravity, Vec3::Zero());
  EXPECT_EQ(m.solver.formulation, defaults.solver.formulation);
  EXPECT_EQ(m.solver.dt, defaults.solver.dt);
  EXPECT_EQ(m.solver.max_iterations, defaults.solver.max_iterations);
  EXPECT_EQ(m.output.vtk_every, defaults.output.vtk_every);
  EXPECT_EQ(m.output.history, defaults.output.history);
  EXPECT_EQ(m.output.vtk_format, model::VtkFormat::binary);
  EXPECT_FALSE(m.output.hdf5);
  EXPECT_EQ(m.output.hdf5_state_every, 1);
  ASSERT_EQ(m.bodies.size(), 1u);
  EXPECT_EQ(m.bodies[0].shape.kind, model::ShapeKind::none);
  EXPECT_TRUE(m.joints.empty() && m.loads.empty() && m.probes.empty());
}

TEST(ModelReader, ReadsAFileAndRecordsItsName) {
  const std::string path = temp_path("valid.yaml");
  test::write_text(path, kValid);
  const model::Model m = read_model(path);
  std::filesystem::remove(path);
  EXPECT_EQ(m.file, path);
  ASSERT_EQ(m.bodies.size(), 2u);
  EXPECT_EQ(m.bodies[1].source.file, path);
  EXPECT_EQ(m.joints[1].source.file, path);
  EXPECT_EQ(m.loads[0].source.file, path);
  EXPECT_EQ(m.probes[0].source.file, path);
}

TEST(ModelReader, MissingFile) {
  const std::string path = temp_path("does_not_exist.yaml");
  try {
    read_model(path);
    FAIL() << "no error";
  } catch (const ModelError& e) {
    EXPECT_EQ(std::string(e.what()), path + ": cannot open model file");
    EXPECT_EQ(e.file(), path);
    EXPECT_EQ(e.line(), 0);
  }
}

TEST(ModelReader, ErrorInAFileNamesTheFile) {
  const std::string path = temp_path("bad.yaml");
  test::write_text(path, with_bodies({"probes:", "  - name: p", "    body: nobody"}));
  std::string what = "(no error)";
  try {
    read_model(path);
  } catch (const ModelError& e) {
    what = e.what();
  }
  std::filesystem::remove(path);
  EXPECT_EQ(what, path + ":8: probes[0].body: no body named \"nobody\"");
}

TEST(ModelReader, YamlSyntaxError) {
  const std::string what = error_of(lines({"gravity: [0, 0, -9.81", "bodies: []"}));
  EXPECT_EQ(what.rfind("m.yaml:2: ", 0), 0u) << what;
  EXPECT_GT(what.size(), std::string("m.yaml:2: ").size()) << what;
  EXPECT_EQ(what.find("yaml-cpp"), std::string::npos) << what;  // yaml-cpp's bare message
}

TEST(ModelReader, MissingRequiredKey) {
  EXPECT_EQ(error_of(lines(
                {"bodies:", "  - name: top", "    inertia: [1, 1, 1]", "    position: [0, 0, 0]"})),
            "m.yaml:2: bodies[0].mass: missing required key");
  EXPECT_EQ(error_of(lines({"name: x", "gravity: [0, 0, 1]"})),
            "m.yaml:1: bodies: at least one body, beam or shell is required");
  EXPECT_EQ(error_of(with_bodies({"joints:", "  - type: spherical", "    point: [0, 0, 0]"})),
            "m.yaml:7: joints[0].body_b: missing required key");
  EXPECT_EQ(error_of(with_bodies(
                {"joints:", "  - type: revolute", "    body_b: top", "    point: [0, 0, 0]"})),
            "m.yaml:7: joints[0].axis: missing required key for a revolute joint (or give axis_a)");
  EXPECT_EQ(error_of(with_bodies({"joints:", "  - type: spherical", "    body_b: top"})),
            "m.yaml:7: joints[0].point: missing required key for a spherical joint (or give "
            "point_a or point_b)");
  EXPECT_EQ(error_of(with_bodies({"loads:", "  - body: top", "    point: [0, 0, 0]"})),
            "m.yaml:7: loads[0]: at least one of force and moment is required");
}

// A load's `frame`: global components by default, `body` for a follower load (components along the
// body's or node's directors); anything else is a located error.
TEST(ModelReader, LoadFrame) {
  const model::Model m =
      read_model_string(with_bodies({"loads:", "  - {body: top, force: [1, 0, 0]}",
                                     "  - {body: top, force: [1, 0, 0], frame: global}",
                                     "  - {body: top, moment: [0, 0, 1], frame: body}"}),
                        "m.yaml");
  ASSERT_EQ(m.loads.size(), 3u);
  EXPECT_EQ(m.loads[0].frame, model::LoadFrame::global);
  EXPECT_EQ(m.loads[1].frame, model::LoadFrame::global);
  EXPECT_EQ(m.loads[2].frame, model::LoadFrame::body);
  EXPECT_EQ(
      error_of(with_bodies({"loads:", "  - body: top", "    moment: [0, 0, 1]", "    frame: foo"})),
      "m.yaml:9: loads[0].frame: unknown frame \"foo\" (valid: global, body)");
  EXPECT_EQ(error_of(with_bodies({"loads:", "  - {body: top, force: [1, 0, 0], frame: Body}"})),
            "m.yaml:7: loads[0].frame: unknown frame \"Body\" (valid: global, body)");
  EXPECT_EQ(error_of(with_bodies(
                {"loads:", "  - body: top", "    force: [1, 0, 0]", "    frame: [1, 0, 0]"})),
            "m.yaml:9: loads[0].frame: expected a string");
}

// The step count t_end / dt (issue #15, found by tests/fuzz): more than 10⁸ steps, or a dynamic
// run without a step, is a located error. Before, dt: 1e-30 ran 0 steps (lround overflowed) and
// reported "completed", and t_end: 1e12 wrapped around int into a run of hundreds of millions of
// steps.
TEST(ModelReader, StepCountOfDtAndTEnd) {
  EXPECT_EQ(error_of(with_bodies({"solver:", "  dt: 1e-30", "  t_end: 1"})),
            "m.yaml:8: solver.t_end: t_end / dt = 1 / 1e-30 = 1e+30 time steps, at most 1e+08 "
            "(history.csv has a row per step)");
  EXPECT_EQ(error_of(with_bodies({"solver:", "  t_end: 1e12"})),
            "m.yaml:7: solver.t_end: t_end / dt = 1e+12 / 0.01 = 1e+14 time steps, at most 1e+08 "
            "(history.csv has a row per step)");
  EXPECT_EQ(error_of(with_bodies({"solver:", "  dt: 1e-300"})),
            "m.yaml:7: solver.dt: t_end / dt = 1 / 1e-300 = 1e+300 time steps, at most 1e+08 "
            "(history.csv has a row per step)");
  EXPECT_EQ(error_of(with_bodies({"solver:", "  dt: 0.1", "  t_end: 0.01"})),
            "m.yaml:8: solver.t_end: t_end = 0.01 is shorter than half a time step (dt = 0.1): "
            "the run would take no step");
  // A time integration ends at n dt: a t_end between two step times was cut short silently
  // (dt 0.003, t_end 10 stopped at 9.999 while summary.json said 10). Load steps divide t_end.
  EXPECT_EQ(error_of(with_bodies({"solver:", "  dt: 0.003", "  t_end: 10"})),
            "m.yaml:8: solver.t_end: t_end = 10 is not a whole multiple of dt = 0.003 (t_end / dt "
            "= 3333.333333): the run takes steps of dt; use t_end = 9.999 or 10.002, or a dt "
            "that divides t_end");
  EXPECT_EQ(error_of(with_bodies({"solver: {dt: 0.1, t_end: 0.3}"})), "(no error)");
  EXPECT_EQ(error_of(with_bodies({"solver: {analysis: static, dt: 0.3, t_end: 1}"})), "(no error)");
  // A static analysis takes at least one load step; 10⁸ steps are allowed.
  EXPECT_EQ(error_of(with_bodies({"solver: {analysis: static, dt: 1, t_end: 0.1}"})), "(no error)");
  EXPECT_EQ(error_of(with_bodies({"solver: {dt: 1e-8, t_end: 1}"})), "(no error)");
  EXPECT_EQ(error_of(with_bodies({"solver: {analysis: static, dt: 1, t_end: 2e8}"})),
            "m.yaml:6: solver.t_end: t_end / dt = 2e+08 / 1 = 2e+08 load steps, at most 1e+08 "
            "(history.csv has a row per step)");
}

TEST(ModelReader, UnknownKey) {
  EXPECT_EQ(error_of(with_bodies({"    colour: red"})),
            "m.yaml:6: bodies[0].colour: unknown key (valid keys: name, mass, inertia, position, "
            "orientation, velocity, angular_velocity, shape)");
  EXPECT_EQ(
      error_of(with_bodies({"solver:", "  dt: 0.1", "  tolerance: 1e-3"})),
      "m.yaml:8: solver.tolerance: unknown key (valid keys: analysis, formulation, integrator, "
      "rho_infinity, numerical_dissipation, scaling, dt, t_end, residual_tolerance, "
      "increment_tolerance, max_iterations, max_rotation_correction, mixed_tangent, "
      "max_subdivisions, linear, initial_equilibrium, "
      "path_following, cosimulation, saddle_point_solver, support_rows, linear_solver, "
      "multigrid_coarsening)");
  EXPECT_EQ(error_of(with_bodies({"gravitation: [0, 0, 0]"})),
            "m.yaml:6: gravitation: unknown key (valid keys: name, gravity, solver, output, "
            "bodies, beams, joints, loads, distributed_loads, probes, surfaces, shells, "
            "shell_supports, shell_connections, shell_loads, kl_shells, kl_supports, kl_loads, "
            "kl_interfaces, springs, bushings)");
  EXPECT_EQ(error_of(with_bodies({"    shape: {type: sphere, size: [1, 1, 1]}"})),
            "m.yaml:6: bodies[0].shape.size: unknown key (valid keys: type, radius, offset)");
  EXPECT_EQ(error_of(with_bodies({"gravity: [0, 0, 0]", "gravity: [0, 0, 1]"})),
            "m.yaml:7: gravity: duplicate key (first at line 6)");
}

TEST(ModelReader, UnknownJointType) {
  EXPECT_EQ(error_of(with_bodies({"joints:", "  - type: hinge", "    body_b: top"})),
            "m.yaml:7: joints[0].type: unknown joint type \"hinge\" (valid: spherical, revolute, "
            "prismatic, cylindrical, planar, universal, rigid, point_on_line, fixed)");
}

TEST(ModelReader, BodyNameNotFound) {
  EXPECT_EQ(error_of(with_bodies({"joints:", "  - type: fixed", "    body_b: topp"})),
            "m.yaml:8: joints[0].body_b: no body named \"topp\"");
  EXPECT_EQ(error_of(with_bodies(
                {"joints:", "  - type: fixed", "    body_a: nobody", "    body_b: top"})),
            "m.yaml:8: joints[0].body_a: no body named \"nobody\"");
  EXPECT_EQ(error_of(with_bodies({"joints:", "  - type: fixed", "    body_b: ground"})),
            "m.yaml:8: joints[0].body_b: must name a body, not the fixed space \"ground\"");
  EXPECT_EQ(
      error_of(with_bodies({"joints:", "  - type: fixed", "    body_a: top", "    body_b: top"})),
      "m.yaml:9: joints[0].body_b: body_a and body_b are the same body \"top\"");
  EXPECT_EQ(error_of(with_bodies({"loads:", "  - body: tp", "    force: [1, 0, 0]"})),
            "m.yaml:7: loads[0].body: no body named \"tp\"");
}

TEST(ModelReader, NonOrthonormalTriad) {
  EXPECT_EQ(error_of(with_bodies({"    orientation: [[1, 0, 0], [0, 1, 0], [0, 0.1, 1]]"})),
            "m.yaml:6: bodies[0].orientation: orientation is not an orthonormal right-handed "
            "triad");
  // Orthonormal but left-handed.
  EXPECT_EQ(error_of(with_bodies({"    orientation: [[1, 0, 0], [0, 1, 0], [0, 0, -1]]"})),
            "m.yaml:6: bodies[0].orientation: orientation is not an orthonormal right-handed "
            "triad");
  EXPECT_EQ(error_of(with_bodies({"    orientation: [[1, 0, 0], [0, 1, 0]]"})),
            "m.yaml:6: bodies[0].orientation: expected a list of the three principal axes [d1, "
            "d2, d3]");
}

TEST(ModelReader, NegativeOrNonFiniteMass) {
  EXPECT_EQ(error_of(lines({"bodies:", "  - name: top", "    mass: -1", "    inertia: [1, 1, 1]",
                            "    position: [0, 0, 0]"})),
            "m.yaml:3: bodies[0].mass: must be > 0, got -1");
  EXPECT_EQ(error_of(lines({"bodies:", "  - name: top", "    mass: .nan", "    inertia: [1, 1, 1]",
                            "    position: [0, 0, 0]"})),
            "m.yaml:3: bodies[0].mass: must be a finite number");
  EXPECT_EQ(error_of(lines({"bodies:", "  - name: top", "    mass: heavy", "    inertia: [1, 1, 1]",
                            "    position: [0, 0, 0]"})),
            "m.yaml:3: bodies[0].mass: expected a number");
  // An empty value is reported on the line of its key.
  EXPECT_EQ(error_of(lines({"bodies:", "  - name: top", "    mass:", "    inertia: [1, 1, 1]",
                            "    position: [0, 0, 0]"})),
            "m.yaml:3: bodies[0].mass: expected a number");
}

TEST(ModelReader, MalformedExpression) {
  const std::string what =
      error_of(with_bodies({"loads:", "  - body: top", "    force: [0, \"2*x\", 0]"}));
  EXPECT_EQ(what.rfind("m.yaml:8: loads[0].force[1]: invalid expression \"2*x\": ", 0), 0u) << what;
  EXPECT_NE(what.find("\"x\""), std::string::npos) << what;  // muParser names the token
  EXPECT_EQ(error_of(with_bodies({"loads:", "  - body: top", "    moment: [0, 0, \"sin(t\"]"})),
            "m.yaml:8: loads[0].moment[2]: invalid expression \"sin(t\": Missing parenthesis");
}

TEST(ModelReader, InertiaTriangleInequality) {
  EXPECT_EQ(error_of(lines({"bodies:", "  - name: top", "    mass: 1", "    inertia: [1, 1, 3]",
                            "    position: [0, 0, 0]"})),
            "m.yaml:4: bodies[0].inertia: principal moments violate the triangle inequality J3 "
            "<= J1 + J2 (3 > 2)");
  // Equality (a flat plate) is allowed; so is rounding in the sum.
  EXPECT_NO_THROW(
      read_model_string(lines({"bodies:", "  - name: top", "    mass: 1",
                               "    inertia: [0.1, 0.2, 0.3]", "    position: [0, 0, 0]"}),
                        "m.yaml"));
  EXPECT_EQ(error_of(lines({"bodies:", "  - name: top", "    mass: 1", "    inertia: [1, 0, 1]",
                            "    position: [0, 0, 0]"})),
            "m.yaml:4: bodies[0].inertia[1]: must be > 0, got 0");
}

TEST(ModelReader, VectorsNeedThreeFiniteNumbers) {
  EXPECT_EQ(error_of(with_bodies({"gravity: [0, -9.81]"})),
            "m.yaml:6: gravity: expected a list of 3 numbers [x, y, z]");
  EXPECT_EQ(error_of(with_bodies({"gravity: [0, .inf, 0]"})),
            "m.yaml:6: gravity[1]: must be a finite number");
  EXPECT_EQ(error_of(with_bodies({"    velocity: [0, 0, fast]"})),
            "m.yaml:6: bodies[0].velocity[2]: expected a number");
}

TEST(ModelReader, JointGeometryRules) {
  EXPECT_EQ(error_of(with_bodies({"joints:", "  - type: spherical", "    body_b: top",
                                  "    point: [0, 0, 0]", "    axis: [0, 0, 1]"})),
            "m.yaml:10: joints[0].axis: not allowed for a spherical joint");
  EXPECT_EQ(error_of(with_bodies({"joints:", "  - type: revolute", "    body_b: top",
                                  "    point: [0, 0, 0]", "    axis: [0, 0, 0]"})),
            "m.yaml:10: joints[0].axis: must be a nonzero vector");
  EXPECT_EQ(error_of(with_bodies({"joints:", "  - type: universal", "    body_b: top",
                                  "    point: [0, 0, 0]", "    axis: [0, 0, 1]",
                                  "    axis2: [0, 1, 1]"})),
            "m.yaml:11: joints[0].axis2: must be perpendicular to axis (cosine of the angle "
            "0.7071067811865475)");
  EXPECT_EQ(error_of(with_bodies({"joints:", "  - type: revolute", "    body_b: top",
                                  "    point: [0, 0, 0]", "    axis: [0, 0, 1]",
                                  "    axis2: [1, 0, 0]"})),
            "m.yaml:11: joints[0].axis2: not allowed for a revolute joint (only universal)");
  EXPECT_EQ(error_of(with_bodies({"joints:", "  - type: spherical", "    body_b: top",
                                  "    point: [0, 0, 0]", "    point_b: [0, 0, 0]"})),
            "m.yaml:10: joints[0].point_b: give either point or point_b, not both");
  EXPECT_EQ(error_of(with_bodies({"joints:", "  - type: revolute", "    body_b: top",
                                  "    point_a: [0, 0, 0]", "    point_b: [0, 0, 0]",
                                  "    axis: [0, 0, 1]"})),
            "m.yaml:10: joints[0].point_b: give either point_a or point_b, not both");
  EXPECT_EQ(error_of(with_bodies({"joints:", "  - type: revolute", "    body_b: top",
                                  "    point: [0, 0, 0]", "    axis: [0, 0, 1]",
                                  "    axis_a: [0, 0, 1]"})),
            "m.yaml:11: joints[0].axis_a: give either axis or axis_a, not both");
  EXPECT_EQ(error_of(with_bodies({"joints:", "  - type: spherical", "    body_b: top",
                                  "    point: [0, 0, 0]", "    axis_a: [0, 0, 1]"})),
            "m.yaml:10: joints[0].axis_a: not allowed for a spherical joint");
  EXPECT_EQ(error_of(with_bodies({"joints:", "  - type: universal", "    body_b: top",
                                  "    point: [0, 0, 0]", "    axis: [0, 0, 1]",
                                  "    axis2_b: [0, 0, 0]"})),
            "m.yaml:11: joints[0].axis2_b: must be a nonzero vector");
  const model::Model m =
      read_model_string(with_bodies({"joints:", "  - type: rigid", "    body_b: top"}), "m.yaml");
  EXPECT_FALSE(m.joints[0].point || m.joints[0].point_b);
}

TEST(ModelReader, NamesMustBeUnique) {
  EXPECT_EQ(error_of(with_bodies({"  - name: top", "    mass: 1", "    inertia: [1, 1, 1]",
                                  "    position: [0, 0, 0]"})),
            "m.yaml:6: bodies[1].name: duplicate body name \"top\" (first at line 2)");
  EXPECT_EQ(error_of(lines({"bodies:", "  - name: ground", "    mass: 1", "    inertia: [1, 1, 1]",
                            "    position: [0, 0, 0]"})),
            "m.yaml:2: bodies[0].name: \"ground\" is reserved for the fixed space");
  EXPECT_EQ(error_of(with_bodies({"joints:", "  - name: joint1", "    type: fixed",
                                  "    body_b: top", "  - type: fixed", "    body_b: top"})),
            "m.yaml:10: joints[1].name: duplicate joint name \"joint1\" (first at line 7)");
  EXPECT_EQ(error_of(with_bodies(
                {"probes:", "  - name: p", "    body: top", "  - name: p", "    body: top"})),
            "m.yaml:9: probes[1].name: duplicate probe name \"p\" (first at line 7)");
}

TEST(ModelReader, SolverAnalysis) {
  EXPECT_EQ(read_model_string(with_bodies({"joints:"}), "m.yaml").solver.analysis,
            model::Analysis::dynamic);
  EXPECT_EQ(
      read_model_string(with_bodies({"solver: {analysis: static}"}), "m.yaml").solver.analysis,
      model::Analysis::statics);
  EXPECT_EQ(
      read_model_string(with_bodies({"solver: {analysis: dynamic}"}), "m.yaml").solver.analysis,
      model::Analysis::dynamic);
  EXPECT_EQ(error_of(with_bodies({"solver:", "  analysis: transient"})),
            "m.yaml:7: solver.analysis: unknown analysis \"transient\" (valid: static, dynamic)");
}

// The solver of static saddle-point systems (integrate/static_newton.hpp SaddlePointMethod).
TEST(ModelReader, SolverSaddlePointSolver) {
  const auto read = [](const std::string& line) {
    return read_model_string(with_bodies({line}), "m.yaml").solver.saddle_point_solver;
  };
  EXPECT_EQ(read("joints:"), model::SaddlePointSolver::automatic);
  EXPECT_EQ(read("solver: {saddle_point_solver: auto}"), model::SaddlePointSolver::automatic);
  EXPECT_EQ(read("solver: {saddle_point_solver: lu}"), model::SaddlePointSolver::lu);
  EXPECT_EQ(read("solver: {saddle_point_solver: augmented_lagrangian}"),
            model::SaddlePointSolver::augmented_lagrangian);
  EXPECT_EQ(error_of(with_bodies({"solver:", "  saddle_point_solver: minres"})),
            "m.yaml:7: solver.saddle_point_solver: unknown solver \"minres\" (valid: auto, lu, "
            "augmented_lagrangian)");
}

// The time integrator (integrate/time_integrator.hpp) and its keys.
TEST(ModelReader, SolverIntegrator) {
  const auto m = read_model_string(
      with_bodies({"solver: {integrator: generalized_alpha, rho_infinity: 0.5, scaling: false}"}),
      "m.yaml");
  EXPECT_EQ(m.solver.integrator, model::Integrator::generalized_alpha);
  EXPECT_EQ(m.solver.rho_infinity, 0.5);
  EXPECT_FALSE(m.solver.scaling);
  EXPECT_EQ(read_model_string(with_bodies({"joints:"}), "m.yaml").solver.integrator,
            model::Integrator::energy_momentum);
  for (const char* name : {"bdf1", "bdf2", "energy_momentum"})
    EXPECT_EQ(model::to_string(*model::integrator_from_string(name)), std::string(name));
  EXPECT_EQ(error_of(with_bodies({"solver:", "  integrator: hht"})),
            "m.yaml:7: solver.integrator: unknown integrator \"hht\" (valid: energy_momentum, "
            "generalized_alpha, bdf1, bdf2)");
  // Not clamped: a value outside [0, 1] names the key.
  EXPECT_EQ(error_of(with_bodies({"solver:", "  rho_infinity: 1.2"})),
            "m.yaml:7: solver.rho_infinity: 1.2 is outside [0, 1] (the spectral radius of "
            "generalized-α at infinite frequency)");
  EXPECT_EQ(
      read_model_string(with_bodies({"solver: {rho_infinity: 0}"}), "m.yaml").solver.rho_infinity,
      0.0);
}

// The energy–momentum scheme's numerical dissipation (docs/theory/schemes.md §10).
TEST(ModelReader, SolverNumericalDissipation) {
  const std::vector<std::string_view> shell = {
      "shells:",
      "  - name: plate",
      "    plate:",
      "      corners: [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]",
      "      elements: [1, 1]",
      "    material: {E: 1.0e6, nu: 0.3, thickness: 0.01, density: 1000}"};
  std::string text = with_bodies({"solver: {numerical_dissipation: 0.05}"});
  for (const auto l : shell) text += std::string(l) + '\n';
  const auto m = read_model_string(text, "m.yaml");
  EXPECT_EQ(m.solver.numerical_dissipation, 0.05);
  EXPECT_TRUE(model::has_material_damping(m));  // history.csv gets its dissipated_energy
  EXPECT_EQ(read_model_string(with_bodies({"joints:"}), "m.yaml").solver.numerical_dissipation,
            0.0);
  EXPECT_EQ(error_of(with_bodies({"solver:", "  numerical_dissipation: 0.3"})),
            "m.yaml:7: solver.numerical_dissipation: 0.3 is outside [0, 0.25] (χ of the "
            "algorithmic stress on the strains' second difference; 0.01–0.1 damps the modes with "
            "ωΔt ≈ 1–100)");
  EXPECT_EQ(
      error_of(with_bodies({"solver:", "  integrator: bdf2", "  numerical_dissipation: 0.1"})),
      "m.yaml:8: solver.numerical_dissipation: is for the energy–momentum integrator "
      "(generalized-α has rho_infinity; BDF dissipates by itself)");
  EXPECT_EQ(error_of(with_bodies({"solver:", "  numerical_dissipation: 0.1"})),
            "m.yaml:7: solver.numerical_dissipation: acts on the strains of beams and director "
            "shells, and the model has none");
}

TEST(ModelReader, SolverMixedTangent) {
  EXPECT_TRUE(read_model_string(with_bodies({"joints:"}), "m.yaml").solver.mixed_tangent);
  EXPECT_FALSE(read_model_string(with_bodies({"solver: {mixed_tangent: false}"}), "m.yaml")
                   .solver.mixed_tangent);
  EXPECT_NE(error_of(with_bodies({"solver: {mixed_tangent: 2}"})).find("solver.mixed_tangent"),
            std::string::npos);
}

TEST(ModelReader, SolverMaxRotationCorrection) {
  EXPECT_EQ(read_model_string(with_bodies({"joints:"}), "m.yaml").solver.max_rotation_correction,
            0.1);
  EXPECT_EQ(read_model_string(with_bodies({"solver: {max_rotation_correction: 0}"}), "m.yaml")
                .solver.max_rotation_correction,
            0.0);
  EXPECT_EQ(error_of(with_bodies({"solver:", "  max_rotation_correction: -0.5"})),
            "m.yaml:7: solver.max_rotation_correction: -0.5 is negative (the largest turn, in "
            "rad, of a Newton correction; 0: no limit)");
}

// The solver of static Newton matrices without rows (integrate/static_newton.hpp
// LinearSolverMethod); the PETSc ones load the PETSc module, which the build has.
TEST(ModelReader, SolverLinearSolver) {
  const auto read = [](const std::string& line) {
    return read_model_string(with_bodies({"solver:", line}), "m.yaml").solver.linear_solver;
  };
  EXPECT_EQ(read_model_string(with_bodies({"joints:"}), "m.yaml").solver.linear_solver,
            model::LinearSolver::automatic);
  EXPECT_EQ(read("  linear_solver: direct"), model::LinearSolver::direct);
  EXPECT_EQ(read("  linear_solver: cg_gamg"), model::LinearSolver::cg_gamg);
  EXPECT_EQ(read("  linear_solver: cg_hypre"), model::LinearSolver::cg_hypre);
  EXPECT_EQ(read("  linear_solver: mumps"), model::LinearSolver::mumps);
  EXPECT_EQ(error_of(with_bodies({"solver:", "  linear_solver: pcg"})),
            "m.yaml:7: solver.linear_solver: unknown solver \"pcg\" (valid: auto, direct, "
            "cg_gamg, cg_hypre, mumps, cg_multigrid)");
  EXPECT_EQ(error_of(with_bodies({"solver:", "  linear_solver: cg_multigrid"})),
            "m.yaml:7: solver.linear_solver: cg_multigrid coarsens the knot vectors of "
            "Kirchhoff–Love patches, and the model has none (cg_gamg is the algebraic multigrid)");
}

// The first coarse level of cg_multigrid (system/kl_multigrid.hpp Coarsening).
TEST(ModelReader, SolverMultigridCoarsening) {
  const auto read = [](const std::string& line) {
    return read_model_string(with_bodies({"solver:", line}), "m.yaml").solver.multigrid_coarsening;
  };
  EXPECT_EQ(read_model_string(with_bodies({"joints:"}), "m.yaml").solver.multigrid_coarsening,
            model::MultigridCoarsening::knots);
  EXPECT_EQ(read("  multigrid_coarsening: knots"), model::MultigridCoarsening::knots);
  EXPECT_EQ(read("  multigrid_coarsening: degree"), model::MultigridCoarsening::degree);
  EXPECT_EQ(error_of(with_bodies({"solver:", "  multigrid_coarsening: p"})),
            "m.yaml:7: solver.multigrid_coarsening: unknown coarsening \"p\" (valid: knots, "
            "degree)");
}

TEST(ModelReader, SolverAndOutputValues) {
  EXPECT_EQ(error_of(with_bodies({"solver:", "  formulation: penalty"})),
            "m.yaml:7: solver.formulation: unknown formulation \"penalty\" (valid: constrained, "
            "nullspace, reparametrized)");
  EXPECT_EQ(error_of(with_bodies({"solver:", "  dt: 0"})),
            "m.yaml:7: solver.dt: must be > 0, got 0");
  EXPECT_EQ(error_of(with_bodies({"solver:", "  max_iterations: 2.5"})),
            "m.yaml:7: solver.max_iterations: expected an integer");
  EXPECT_EQ(error_of(with_bodies({"solver:", "  max_iterations: 0"})),
            "m.yaml:7: solver.max_iterations: must be >= 1, got 0");
  EXPECT_EQ(error_of(with_bodies({"output:", "  vtk_every: -1"})),
            "m.yaml:7: output.vtk_every: must be >= 0, got -1");
  EXPECT_EQ(error_of(with_bodies({"output:", "  history: maybe"})),
            "m.yaml:7: output.history: expected true or false");
  EXPECT_EQ(error_of(with_bodies({"output:", "  hdf5: 1.5"})),
            "m.yaml:7: output.hdf5: expected true or false");
  EXPECT_EQ(error_of(with_bodies({"output:", "  hdf5_state_every: 0"})),
            "m.yaml:7: output.hdf5_state_every: must be >= 1, got 0");
  const model::Model m =
      read_model_string(with_bodies({"output: {hdf5: true, hdf5_state_every: 10}"}), "m.yaml");
  EXPECT_TRUE(m.output.hdf5);
  EXPECT_EQ(m.output.hdf5_state_every, 10);
}

// How the .vtu files hold their arrays (io/vtu_data_arrays.hpp).
TEST(ModelReader, OutputVtkFormat) {
  const auto read = [](const std::string& line) {
    return read_model_string(with_bodies({line}), "m.yaml").output.vtk_format;
  };
  EXPECT_EQ(read("output: {vtk_format: binary}"), model::VtkFormat::binary);
  EXPECT_EQ(read("output: {vtk_format: ascii}"), model::VtkFormat::ascii);
  EXPECT_EQ(error_of(with_bodies({"output:", "  vtk_format: base64"})),
            "m.yaml:7: output.vtk_format: unknown format \"base64\" (valid: binary, ascii)");
  EXPECT_EQ(error_of(with_bodies({"output:", "  vtk_format: ASCII"})),
            "m.yaml:7: output.vtk_format: unknown format \"ASCII\" (valid: binary, ascii)");
  EXPECT_EQ(error_of(with_bodies({"output:", "  vtk_format: [ascii]"})),
            "m.yaml:7: output.vtk_format: expected a string");
}

TEST(ModelReader, ShapesAndPoints) {
  EXPECT_EQ(error_of(with_bodies({"    shape: {type: cone, radius: 1}"})),
            "m.yaml:6: bodies[0].shape.type: unknown shape type \"cone\" (valid: box, sphere, "
            "cylinder, pyramid)");
  EXPECT_EQ(error_of(with_bodies({"    shape: {type: pyramid, base: 1}"})),
            "m.yaml:6: bodies[0].shape.height: missing required key");
  EXPECT_EQ(error_of(with_bodies({"    shape: {type: sphere, radius: -2}"})),
            "m.yaml:6: bodies[0].shape.radius: must be > 0, got -2");
  const model::Model m = read_model_string(
      with_bodies({"    shape: {type: pyramid, base: 2, height: 3, offset: [0, 0, -1]}"}),
      "m.yaml");
  EXPECT_EQ(m.bodies[0].shape.kind, model::ShapeKind::pyramid);
  EXPECT_EQ(m.bodies[0].shape.base, 2.0);
  EXPECT_EQ(m.bodies[0].shape.height, 3.0);
  EXPECT_EQ(m.bodies[0].shape.offset, Vec3(0, 0, -1));
  EXPECT_EQ(error_of(with_bodies({"probes:", "  - name: p", "    body: top", "    point: [0, 0, 0]",
                                  "    point_local: [0, 0, 0]"})),
            "m.yaml:10: probes[0].point_local: give either point or point_local, not both");
}

TEST(ModelReader, DocumentMustBeAMappingWithBodies) {
  EXPECT_EQ(error_of(""),
            "m.yaml:1: a model file must be a YAML mapping with the keys name, "
            "gravity, ...");
  EXPECT_EQ(error_of(lines({"name: x", "bodies: []"})),
            "m.yaml:2: bodies: at least one body, beam or shell is required");
  EXPECT_EQ(error_of(lines({"name: x", "bodies:", "joints: []"})),
            "m.yaml:2: bodies: at least one body, beam or shell is required");
  EXPECT_EQ(error_of(lines({"name: x", "beams: []"})),
            "m.yaml:2: beams: at least one body, beam or shell is required");
  EXPECT_EQ(error_of(lines({"name: x", "bodies: 3"})), "m.yaml:2: bodies: expected a list");
}

// The complete example of docs/model-files.md is a valid model.
TEST(ModelReader, DocumentationExampleIsValid) {
  const std::string doc_path = std::string(ISOFLEX_SOURCE_DIR) + "/docs/model-files.md";
  std::ifstream in(doc_path);
  ASSERT_TRUE(in) << doc_path;
  const std::string doc((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto section = doc.find("## Complete example");
  ASSERT_NE(section, std::string::npos);
  const auto begin = doc.find("```yaml\n", section);
  ASSERT_NE(begin, std::string::npos);
  const auto end = doc.find("```", begin + 8);
  ASSERT_NE(end, std::string::npos);
  const model::Model m = read_model_string(doc.substr(begin + 8, end - begin - 8), "example");
  EXPECT_EQ(m.name, "heavy_top");
  EXPECT_EQ(m.bodies.size(), 2u);
  EXPECT_EQ(m.joints.size(), 2u);
  EXPECT_EQ(m.loads.size(), 1u);
  EXPECT_EQ(m.probes.size(), 2u);
}

// ---- beams, beam nodes, distributed loads --------------------------------------------------

namespace {

// A valid beam "crank" with 21 nodes occupying lines 1-6.
constexpr std::string_view kBeam[] = {
    "beams:",
    "  - name: crank",
    "    points: [[0, -3, 1.5], [0, 3, 1.5]]",
    "    elements: 20",
    "    d1: [0, 0, 1]",
    "    section: {EA: 1e5, GA: 1e5, EI: 1e4, GJ: 1e4, A_rho: 20, M_rho: 10}"};

// kBeam followed by `more` (from line 7).
std::string with_beam(std::initializer_list<std::string_view> more) {
  std::string s;
  for (const auto l : kBeam) s += std::string(l) + '\n';
  for (const auto l : more) s += std::string(l) + '\n';
  return s;
}

// A model with beams only; joints, loads and probes name beam nodes before the beams are defined.
const std::string kBeamModel = lines({
    "joints:",                                                                  // 1
    "  - type: revolute",                                                       // 2
    "    body_b: crank[0]            # plain scalar",                           // 3
    "    point: [0, -3, 1.5]",                                                  // 4
    "    axis: [0, 1, 0]",                                                      // 5
    "  - type: spherical",                                                      // 6
    "    body_a: \"crank[20]\"       # quoted",                                 // 7
    "    body_b: rod[0]",                                                       // 8
    "    point: [0, 3, 1.5]",                                                   // 9
    "beams:",                                                                   // 10
    "  - name: crank",                                                          // 11
    "    points: [[0, -3, 1.5], [0, 3, 1.5]]",                                  // 12
    "    elements: 20",                                                         // 13
    "    d1: [0, 0, 2]",                                                        // 14
    "    section: {EA: 1e5, GA: 2e5, EI: 1e4, GJ: 3e4, A_rho: 20, M_rho: 10}",  // 15
    "  - name: rod",                                                            // 16
    "    points: [[0, 3, 1.5], [1, 3, 1.5], [1, 3, 0]]",                        // 17
    "    elements: [2, 3]",                                                     // 18
    "    d1: [1, 1, 0]",                                                        // 19
    "    section:",                                                             // 20
    "      EA: 1",                                                              // 21
    "      GA1: 2",                                                             // 22
    "      GA2: 3",                                                             // 23
    "      EI1: 4",                                                             // 24
    "      EI2: 5",                                                             // 25
    "      GJ: 6",                                                              // 26
    "      A_rho: 7",                                                           // 27
    "      M_rho1: 8",                                                          // 28
    "      M_rho2: 9",                                                          // 29
    "loads:",                                                                   // 30
    "  - body: crank[10]",                                                      // 31
    "    force: [0, 0, \"-10*t\"]",                                             // 32
    "distributed_loads:",                                                       // 33
    "  - beam: crank",                                                          // 34
    "    force_per_length: [0, 0, \"-9.81*20\"]",                               // 35
    "  - name: wind",                                                           // 36
    "    beam: rod",                                                            // 37
    "    force_per_length: [\"sin(t)\", 1, 0]",                                 // 38
    "probes:",                                                                  // 39
    "  - name: tip",                                                            // 40
    "    body: rod[005]",                                                       // 41
    "    point_local: [0, 0, 0.1]",                                             // 42
});

}  // namespace

TEST(ModelReader, ReadsBeamsBeamNodesAndDistributedLoads) {
  const model::Model m = read_model_string(kBeamModel, "m.yaml");
  EXPECT_TRUE(m.bodies.empty());  // beams alone make a model
  ASSERT_EQ(m.beams.size(), 2u);

  const model::Beam& crank = m.beams[0];
  EXPECT_EQ(crank.name, "crank");
  ASSERT_EQ(crank.points.size(), 2u);
  EXPECT_EQ(crank.points[0], Vec3(0, -3, 1.5));
  EXPECT_EQ(crank.points[1], Vec3(0, 3, 1.5));
  EXPECT_EQ(crank.elements, std::vector<int>({20}));
  EXPECT_EQ(crank.node_count(), 21);
  EXPECT_EQ(crank.d1, Vec3(0, 0, 1));  // normalized
  EXPECT_EQ(crank.section.EA, 1e5);
  EXPECT_EQ(crank.section.GA1, 2e5);  // GA sets both
  EXPECT_EQ(crank.section.GA2, 2e5);
  EXPECT_EQ(crank.section.EI1, 1e4);
  EXPECT_EQ(crank.section.EI2, 1e4);
  EXPECT_EQ(crank.section.GJ, 3e4);
  EXPECT_EQ(crank.section.A_rho, 20.0);
  EXPECT_EQ(crank.section.M_rho1, 10.0);
  EXPECT_EQ(crank.section.M_rho2, 10.0);
  EXPECT_EQ(crank.source.file, "m.yaml");
  EXPECT_EQ(crank.source.line, 11);

  const model::Beam& rod = m.beams[1];
  EXPECT_EQ(rod.name, "rod");
  ASSERT_EQ(rod.points.size(), 3u);
  EXPECT_EQ(rod.points[2], Vec3(1, 3, 0));
  EXPECT_EQ(rod.elements, std::vector<int>({2, 3}));
  EXPECT_EQ(rod.node_count(), 6);
  EXPECT_NEAR((rod.d1 - Vec3(1, 1, 0) / std::sqrt(2.0)).norm(), 0.0, 1e-15);
  EXPECT_EQ(rod.section.EA, 1.0);
  EXPECT_EQ(rod.section.GA1, 2.0);
  EXPECT_EQ(rod.section.GA2, 3.0);
  EXPECT_EQ(rod.section.EI1, 4.0);
  EXPECT_EQ(rod.section.EI2, 5.0);
  EXPECT_EQ(rod.section.GJ, 6.0);
  EXPECT_EQ(rod.section.A_rho, 7.0);
  EXPECT_EQ(rod.section.M_rho1, 8.0);
  EXPECT_EQ(rod.section.M_rho2, 9.0);
  EXPECT_EQ(rod.source.line, 16);

  ASSERT_EQ(m.joints.size(), 2u);
  EXPECT_EQ(m.joints[0].body_a, "ground");
  EXPECT_EQ(m.joints[0].body_b, "crank[0]");
  EXPECT_EQ(m.joints[1].body_a, "crank[20]");
  EXPECT_EQ(m.joints[1].body_b, "rod[0]");
  ASSERT_EQ(m.loads.size(), 1u);
  EXPECT_EQ(m.loads[0].body, "crank[10]");
  ASSERT_EQ(m.probes.size(), 1u);
  EXPECT_EQ(m.probes[0].body, "rod[5]");  // canonical form of rod[005]

  ASSERT_EQ(m.distributed_loads.size(), 2u);
  const model::DistributedLoad& g = m.distributed_loads[0];
  EXPECT_EQ(g.name, "distributed_load0");
  EXPECT_EQ(g.beam, "crank");
  EXPECT_EQ(g.force_per_length, (std::array<std::string, 3>{"0", "0", "-9.81*20"}));
  EXPECT_EQ(g.source.file, "m.yaml");
  EXPECT_EQ(g.source.line, 34);
  const model::DistributedLoad& wind = m.distributed_loads[1];
  EXPECT_EQ(wind.name, "wind");
  EXPECT_EQ(wind.beam, "rod");
  EXPECT_EQ(wind.force_per_length, (std::array<std::string, 3>{"sin(t)", "1", "0"}));
  EXPECT_EQ(wind.source.line, 36);
}

TEST(ModelReader, BodiesAndBeamsTogether) {
  const model::Model m =
      read_model_string(with_bodies({"joints:", "  - type: spherical", "    body_a: top",
                                     "    body_b: crank[3]", "    point: [0, 0, 0]", kBeam[0],
                                     kBeam[1], kBeam[2], kBeam[3], kBeam[4], kBeam[5]}),
                        "m.yaml");
  ASSERT_EQ(m.bodies.size(), 1u);
  ASSERT_EQ(m.beams.size(), 1u);
  EXPECT_EQ(m.beams[0].source.line, 12);
  EXPECT_EQ(m.joints[0].body_a, "top");
  EXPECT_EQ(m.joints[0].body_b, "crank[3]");
  // `bodies` may be empty or blank when there are beams.
  EXPECT_NO_THROW(read_model_string(with_beam({"bodies: []"}), "m.yaml"));
  EXPECT_NO_THROW(read_model_string(with_beam({"bodies:"}), "m.yaml"));
}

// yaml-cpp reads an unquoted crank[10] as a plain scalar in block context; inside a flow mapping
// or list the brackets are flow indicators, so the reference must be quoted there.
TEST(ModelReader, BeamNodeReferencesInFlowContextNeedQuotes) {
  const model::Model m =
      read_model_string(with_beam({"loads: [{body: \"crank[1]\", force: [1, 0, 0]}]"}), "m.yaml");
  EXPECT_EQ(m.loads[0].body, "crank[1]");
  const std::string what = error_of(with_beam({"loads: [{body: crank[1], force: [1, 0, 0]}]"}));
  EXPECT_EQ(what.rfind("m.yaml:7: ", 0), 0u) << what;  // a YAML syntax error
}

TEST(ModelReader, BeamErrors) {
  auto beam = [](std::initializer_list<std::string_view> entry) {
    std::string s = "beams:\n";  // line 1, the entry from line 2
    for (const auto l : entry) s += std::string(l) + '\n';
    return s;
  };
  const std::string_view section = "    section: {EA: 1, GA: 1, EI: 1, GJ: 1, A_rho: 1, M_rho: 1}";
  // name
  EXPECT_EQ(error_of(beam({"  - points: [[0, 0, 0], [1, 0, 0]]", "    elements: 1",
                           "    d1: [0, 0, 1]", section})),
            "m.yaml:2: beams[0].name: missing required key");
  EXPECT_EQ(error_of(beam({"  - name: \"\""})), "m.yaml:2: beams[0].name: must not be empty");
  EXPECT_EQ(error_of(beam({"  - name: ground"})),
            "m.yaml:2: beams[0].name: \"ground\" is reserved for the fixed space");
  EXPECT_EQ(error_of(beam({"  - name: a[1]"})),
            "m.yaml:2: beams[0].name: must not contain '[' or ']' (they mark beam nodes, as in "
            "crank[3])");
  EXPECT_EQ(error_of(with_beam({"  - name: crank"})),
            "m.yaml:7: beams[1].name: duplicate beam name \"crank\" (first at line 2)");
  // The later of a body and a beam of the same name is reported.
  EXPECT_EQ(error_of(with_beam({"bodies:", "  - name: crank", "    mass: 1",
                                "    inertia: [1, 1, 1]", "    position: [0, 0, 0]"})),
            "m.yaml:8: bodies[0].name: duplicate name \"crank\": already the name of the beam at "
            "line 2");
  EXPECT_EQ(error_of(with_bodies({kBeam[0], "  - name: top"})),
            "m.yaml:7: beams[0].name: duplicate name \"top\": already the name of the body at "
            "line 2");
  EXPECT_EQ(error_of(lines({"bodies:", "  - name: a]", "    mass: 1", "    inertia: [1, 1, 1]",
                            "    position: [0, 0, 0]"})),
            "m.yaml:2: bodies[0].name: must not contain '[' or ']' (they mark beam nodes, as in "
            "crank[3])");
  // unknown keys
  EXPECT_EQ(error_of(with_beam({"    radius: 1"})),
            "m.yaml:7: beams[0].radius: unknown key (valid keys: name, points, arc, elements, d1, "
            "section, draw, velocity, angular_velocity, velocity_point, node_velocities)");
  // initial velocities of the nodes: a node index out of range names the beam's nodes
  EXPECT_EQ(error_of(with_beam({"    node_velocities: [{node: 100000, velocity: [1, 0, 0]}]"})),
            "m.yaml:7: beams[0].node_velocities[0].node: beam \"crank\" has nodes 0 … 20");
  // drawing size
  EXPECT_EQ(error_of(with_beam({"    draw: {width: 0.1}"})),
            "m.yaml:7: beams[0].draw.height: missing required key");
  EXPECT_EQ(error_of(with_beam({"    draw: {width: 0.1, height: -1}"})),
            "m.yaml:7: beams[0].draw.height: must be > 0, got -1");
  EXPECT_EQ(error_of(with_beam({"    draw: {width: 0.1, height: 0.1, depth: 1}"})),
            "m.yaml:7: beams[0].draw.depth: unknown key (valid keys: width, height)");
  // points
  EXPECT_EQ(error_of(beam({"  - name: b", "    points: [[0, 0, 0]]"})),
            "m.yaml:3: beams[0].points: expected a list of at least 2 points [[x, y, z], [x, y, "
            "z], ...]");
  EXPECT_EQ(error_of(beam({"  - name: b", "    points: [0, 0, 0]"})),
            "m.yaml:3: beams[0].points[0]: expected a list of 3 numbers [x, y, z]");
  EXPECT_EQ(error_of(beam({"  - name: b", "    points:", "      - [0, 0, 0]", "      - [1, 0, 0]",
                           "      - [1, 0, 0]"})),
            "m.yaml:6: beams[0].points[2]: coincides with points[1] (consecutive points must be "
            "distinct)");
  EXPECT_EQ(error_of(beam({"  - name: b", "    points: [[0, 0, 0], [1, 0, 0]]"})),
            "m.yaml:2: beams[0].elements: missing required key");
  // elements
  EXPECT_EQ(
      error_of(beam({"  - name: b", "    points: [[0, 0, 0], [1, 0, 0]]", "    elements: 0"})),
      "m.yaml:4: beams[0].elements: must be >= 1, got 0");
  EXPECT_EQ(
      error_of(beam({"  - name: b", "    points: [[0, 0, 0], [1, 0, 0]]", "    elements: 2.5"})),
      "m.yaml:4: beams[0].elements: expected an integer");
  EXPECT_EQ(error_of(beam({"  - name: b", "    points: [[0, 0, 0], [1, 0, 0], [1, 1, 0]]",
                           "    elements: [1, 2, 3]"})),
            "m.yaml:4: beams[0].elements: expected one number of elements per segment (2 "
            "segments), got 3");
  EXPECT_EQ(error_of(beam({"  - name: b", "    points: [[0, 0, 0], [1, 0, 0], [1, 1, 0]]",
                           "    elements: [1, 0]"})),
            "m.yaml:4: beams[0].elements[1]: must be >= 1, got 0");
  EXPECT_EQ(
      error_of(beam({"  - name: b", "    points: [[0, 0, 0], [1, 0, 0]]", "    elements: {n: 1}"})),
      "m.yaml:4: beams[0].elements: expected an integer (elements in every segment) or a "
      "list of one integer per segment");
  EXPECT_EQ(error_of(beam({"  - name: b", "    points: [[0, 0, 0], [1, 0, 0], [1, 1, 0]]",
                           "    elements: 2000000000"})),
            "m.yaml:4: beams[0].elements: too many elements (4000000000 in all, at most "
            "10000000)");
  // d1
  const std::string_view pts = "    points: [[0, 0, 0], [1, 0, 0], [1, 1, 0]]";
  EXPECT_EQ(error_of(beam({"  - name: b", pts, "    elements: 1", "    d1: [0, 0, 0]", section})),
            "m.yaml:5: beams[0].d1: must be a nonzero vector");
  EXPECT_EQ(error_of(beam({"  - name: b", pts, "    elements: 1", "    d1: [0, -2, 0]", section})),
            "m.yaml:5: beams[0].d1: must not be parallel to segment 1 (points[1] to points[2]): "
            "|cos| = 1");
  EXPECT_EQ(error_of(beam({"  - name: b", pts, "    elements: 1", section})),
            "m.yaml:2: beams[0].d1: missing required key");
  // Nearly parallel (|cos| ≥ 1 − 1e-6) is rejected, |cos| just below is accepted.
  {
    const std::string what =
        error_of(beam({"  - name: b", pts, "    elements: 1", "    d1: [1, 0, 1e-4]", section}));
    EXPECT_EQ(what.rfind("m.yaml:5: beams[0].d1: must not be parallel to segment 0 (points[0] to "
                         "points[1]): |cos| = 0.99999999",
                         0),
              0u)
        << what;
  }
  EXPECT_NO_THROW(read_model_string(
      beam({"  - name: b", pts, "    elements: 1", "    d1: [1, 0, 2e-3]", section}), "m.yaml"));
  // section
  auto with_section = [&](std::string_view s) {
    return beam({"  - name: b", pts, "    elements: 1", "    d1: [0, 0, 1]", s});
  };
  EXPECT_EQ(error_of(beam({"  - name: b", pts, "    elements: 1", "    d1: [0, 0, 1]"})),
            "m.yaml:2: beams[0].section: missing required key");
  EXPECT_EQ(error_of(with_section("    section: 1")),
            "m.yaml:6: beams[0].section: expected a mapping of keys");
  EXPECT_EQ(error_of(with_section("    section: {GA: 1, EI: 1, GJ: 1, A_rho: 1, M_rho: 1}")),
            "m.yaml:6: beams[0].section.EA: missing required key");
  EXPECT_EQ(error_of(with_section("    section: {EA: 1, GA: 1, EI: 1, A_rho: 1, M_rho: 1}")),
            "m.yaml:6: beams[0].section.GJ: missing required key");
  EXPECT_EQ(error_of(with_section("    section: {EA: 1, GA: 1, EI: 1, GJ: 1, M_rho: 1}")),
            "m.yaml:6: beams[0].section.A_rho: missing required key");
  EXPECT_EQ(error_of(with_section("    section: {EA: 1, EI: 1, GJ: 1, A_rho: 1, M_rho: 1}")),
            "m.yaml:6: beams[0].section.GA: missing required key (or give both GA1 and GA2)");
  EXPECT_EQ(
      error_of(with_section("    section: {EA: 1, GA1: 1, EI: 1, GJ: 1, A_rho: 1, M_rho: 1}")),
      "m.yaml:6: beams[0].section.GA2: missing required key (give both GA1 and GA2, or GA "
      "alone)");
  EXPECT_EQ(error_of(with_section(
                "    section: {EA: 1, GA: 1, GA2: 1, EI: 1, GJ: 1, A_rho: 1, M_rho: 1}")),
            "m.yaml:6: beams[0].section.GA2: give either GA or GA2, not both");
  EXPECT_EQ(error_of(with_section(
                "    section: {EA: 1, GA: 1, EI: 1, EI1: 1, GJ: 1, A_rho: 1, M_rho: 1}")),
            "m.yaml:6: beams[0].section.EI1: give either EI or EI1, not both");
  EXPECT_EQ(error_of(with_section("    section: {EA: 1, GA: 1, GJ: 1, A_rho: 1, M_rho: 1}")),
            "m.yaml:6: beams[0].section.EI: missing required key (or give both EI1 and EI2)");
  EXPECT_EQ(
      error_of(with_section("    section: {EA: 1, GA: 1, EI2: 1, GJ: 1, A_rho: 1, M_rho: 1}")),
      "m.yaml:6: beams[0].section.EI1: missing required key (give both EI1 and EI2, or EI "
      "alone)");
  EXPECT_EQ(error_of(with_section(
                "    section: {EA: 1, GA: 1, EI: 1, GJ: 1, A_rho: 1, M_rho: 1, M_rho1: 1}")),
            "m.yaml:6: beams[0].section.M_rho1: give either M_rho or M_rho1, not both");
  EXPECT_EQ(error_of(with_section("    section: {EA: 1, GA: 1, EI: 1, GJ: 1, A_rho: 1}")),
            "m.yaml:6: beams[0].section.M_rho: missing required key (or give both M_rho1 and "
            "M_rho2)");
  EXPECT_EQ(
      error_of(with_section("    section: {EA: 1, GA: 1, EI: 1, GJ: 1, A_rho: 1, M_rho1: 1}")),
      "m.yaml:6: beams[0].section.M_rho2: missing required key (give both M_rho1 and M_rho2, or "
      "M_rho alone)");
  EXPECT_EQ(
      error_of(with_section("    section: {EA: -1, GA: 1, EI: 1, GJ: 1, A_rho: 1, M_rho: 1}")),
      "m.yaml:6: beams[0].section.EA: must be > 0, got -1");
  EXPECT_EQ(error_of(with_section("    section: {EA: 1, GA: 1, EI: 1, GJ: 1, A_rho: 1, M_rho: 0}")),
            "m.yaml:6: beams[0].section.M_rho: must be > 0, got 0");
  EXPECT_EQ(
      error_of(with_section("    section: {EA: 1, GA: .inf, EI: 1, GJ: 1, A_rho: 1, M_rho: 1}")),
      "m.yaml:6: beams[0].section.GA: must be a finite number");
  EXPECT_EQ(error_of(with_section("    section: {EA: 1, GA: 1, EI: 1, GJ: 1, A_rho: 1, M_rho: 1, "
                                  "EIz: 2}")),
            "m.yaml:6: beams[0].section.EIz: unknown key (valid keys: EA, GA, GA1, GA2, EI, EI1, "
            "EI2, GJ, A_rho, M_rho, M_rho1, M_rho2, eta)");
  EXPECT_EQ(error_of(beam({"  - name: b", pts, "    elements: 1", "    d1: [0, 0, 1]",
                           "    section:", "      EA: 1", "      GA: 1", "      EI: 1",
                           "      GJ: 1", "      A_rho: 1", "      M_rho1: 1", "      M_rho2: x"})),
            "m.yaml:13: beams[0].section.M_rho2: expected a number");
}

TEST(ModelReader, BeamNodeReferenceErrors) {
  auto joint_to = [](std::string_view body_b) {
    return with_beam({"joints:", "  - type: fixed", "    body_b: " + std::string(body_b)});
  };
  EXPECT_EQ(error_of(joint_to("crnk[3]")),
            "m.yaml:9: joints[0].body_b: no beam or shell named \"crnk\"");
  EXPECT_EQ(error_of(joint_to("crank[25]")),
            "m.yaml:9: joints[0].body_b: node index 25 out of range: beam \"crank\" has 21 nodes "
            "(0 … 20)");
  EXPECT_EQ(error_of(joint_to("crank[21]")),
            "m.yaml:9: joints[0].body_b: node index 21 out of range: beam \"crank\" has 21 nodes "
            "(0 … 20)");
  EXPECT_EQ(error_of(joint_to("crank[99999999999999999999999]")),
            "m.yaml:9: joints[0].body_b: node index 99999999999999999999999 out of range: beam "
            "\"crank\" has 21 nodes (0 … 20)");
  EXPECT_NO_THROW(read_model_string(joint_to("crank[20]"), "m.yaml"));
  for (const char* bad : {"crank[x]", "crank[-1]", "crank[+1]", "crank[]", "crank[1]x",
                          "crank[1][2]", "\"[1]\"", "crank]1[", "\"crank[1\"", "crank[ 1]"})
    EXPECT_EQ(error_of(joint_to(bad)),
              fmt::format("m.yaml:9: joints[0].body_b: malformed beam node reference \"{}\" "
                          "(expected BEAM[INDEX], e.g. crank[0], with a decimal index counted "
                          "from 0)",
                          std::string_view(bad).starts_with('"')
                              ? std::string_view(bad).substr(1, std::string_view(bad).size() - 2)
                              : std::string_view(bad)));
  EXPECT_EQ(error_of(joint_to("crank")),
            "m.yaml:9: joints[0].body_b: \"crank\" is a beam, not a body: name one of its nodes, "
            "crank[i] with i = 0 … 20");
  EXPECT_EQ(error_of(with_beam({"joints:", "  - type: fixed", "    body_a: crank",
                                "    body_b: "
                                "crank[1]"})),
            "m.yaml:9: joints[0].body_a: \"crank\" is a beam, not a body: name one of its nodes, "
            "crank[i] with i = 0 … 20");
  EXPECT_EQ(error_of(with_beam(
                {"joints:", "  - type: fixed", "    body_a: crank[3]", "    body_b: crank[03]"})),
            "m.yaml:10: joints[0].body_b: body_a and body_b are the same beam node \"crank[3]\"");
  EXPECT_EQ(error_of(with_beam({"loads:", "  - body: crank[21]", "    force: [1, 0, 0]"})),
            "m.yaml:8: loads[0].body: node index 21 out of range: beam \"crank\" has 21 nodes (0 "
            "… 20)");
  EXPECT_EQ(error_of(with_beam({"probes:", "  - name: p", "    body: crank"})),
            "m.yaml:9: probes[0].body: \"crank\" is a beam, not a body: name one of its nodes, "
            "crank[i] with i = 0 … 20");
  EXPECT_EQ(error_of(with_beam({"probes:", "  - name: p", "    body: crank[x]"})),
            "m.yaml:9: probes[0].body: malformed beam node reference \"crank[x]\" (expected "
            "BEAM[INDEX], e.g. crank[0], with a decimal index counted from 0)");
  EXPECT_EQ(error_of(with_beam({"probes:", "  - name: p", "    body: ground"})),
            "m.yaml:9: probes[0].body: must name a body, not the fixed space \"ground\"");
}

TEST(ModelReader, DistributedLoadErrors) {
  EXPECT_EQ(error_of(with_beam({"distributed_loads:", "  - force_per_length: [0, 0, -1]"})),
            "m.yaml:8: distributed_loads[0].beam: missing required key");
  EXPECT_EQ(error_of(with_beam({"distributed_loads:", "  - beam: crank"})),
            "m.yaml:8: distributed_loads[0].force_per_length: missing required key");
  EXPECT_EQ(error_of(with_beam(
                {"distributed_loads:", "  - beam: crnk", "    force_per_length: [0, 0, -1]"})),
            "m.yaml:8: distributed_loads[0].beam: no beam named \"crnk\"");
  EXPECT_EQ(error_of(with_beam(
                {"distributed_loads:", "  - beam: crank[2]", "    force_per_length: [0, 0, -1]"})),
            "m.yaml:8: distributed_loads[0].beam: must name a whole beam (\"crank\"), not one of "
            "its nodes");
  EXPECT_EQ(error_of(with_bodies(
                {"distributed_loads:", "  - beam: top", "    force_per_length: [0, 0, -1]"})),
            "m.yaml:7: distributed_loads[0].beam: \"top\" is a body: distributed loads act on "
            "beams only");
  EXPECT_EQ(error_of(with_beam(
                {"distributed_loads:", "  - beam: crank", "    force_per_length: [0, -1]"})),
            "m.yaml:9: distributed_loads[0].force_per_length: expected a list of 3 numbers or "
            "expressions in t");
  EXPECT_EQ(error_of(with_beam({"distributed_loads:", "  - beam: crank",
                                "    force_per_length: [0, 0, \"sin(t\"]"})),
            "m.yaml:9: distributed_loads[0].force_per_length[2]: invalid expression \"sin(t\": "
            "Missing parenthesis");
  EXPECT_EQ(error_of(with_beam({"distributed_loads:", "  - beam: crank",
                                "    force_per_length: [0, 0, -1]", "    point: [0, 0, 0]"})),
            "m.yaml:10: distributed_loads[0].point: unknown key (valid keys: name, beam, "
            "force_per_length)");
  EXPECT_EQ(error_of(with_beam({"distributed_loads: {beam: crank}"})),
            "m.yaml:7: distributed_loads: expected a list");
  const model::Model m = read_model_string(with_beam({"distributed_loads:"}), "m.yaml");
  EXPECT_TRUE(m.distributed_loads.empty());
}

// The beam example of docs/model-files.md is a valid model.
TEST(ModelReader, DocumentationBeamExampleIsValid) {
  const std::string doc_path = std::string(ISOFLEX_SOURCE_DIR) + "/docs/model-files.md";
  std::ifstream in(doc_path);
  ASSERT_TRUE(in) << doc_path;
  const std::string doc((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto section = doc.find("## `beams`");
  ASSERT_NE(section, std::string::npos);
  const auto begin = doc.find("```yaml\n", section);
  ASSERT_NE(begin, std::string::npos);
  const auto end = doc.find("```", begin + 8);
  ASSERT_NE(end, std::string::npos);
  const model::Model m = read_model_string(doc.substr(begin + 8, end - begin - 8), "example");
  EXPECT_EQ(m.beams.size(), 1u);
  EXPECT_EQ(m.distributed_loads.size(), 1u);
  EXPECT_FALSE(m.joints.empty());
}

// Kelvin–Voigt damping factors (seconds, ≥ 0) of a beam section and a director-shell material;
// has_material_damping sees them (history.csv's dissipated_energy column).
TEST(ModelReader, DampingFactorsOfBeamsAndShells) {
  const std::string beam =
      "beams:\n  - name: b\n    points: [[0, 0, 0], [1, 0, 0]]\n    elements: 2\n    d1: [0, 0, "
      "1]\n"
      "    section: {EA: 1, GA: 1, EI: 1, GJ: 1, A_rho: 1, M_rho: 1, eta: ";
  const std::string shell =
      "shells:\n  - name: p\n    plate: {corners: [[0, 0, 0], [1, 0, 0], [1, 0.5, 0], [0, 0.5, "
      "0]], elements: [2, 1]}\n    material: {E: 1.0e5, nu: 0.3, thickness: 0.05, density: 100, "
      "eta: ";
  const model::Model a = io::read_model_string(beam + "0.02}\n", "m.yaml");
  EXPECT_EQ(a.beams[0].section.eta, 0.02);
  EXPECT_TRUE(model::has_material_damping(a));
  const model::Model b = io::read_model_string(shell + "0.5}\n", "m.yaml");
  EXPECT_EQ(b.shells[0].material.eta, 0.5);
  EXPECT_TRUE(model::has_material_damping(b));
  EXPECT_FALSE(model::has_material_damping(io::read_model_string(beam + "0}\n", "m.yaml")));
  EXPECT_EQ(error_of(beam + "-1}\n"),
            "m.yaml:6: beams[0].section.eta: the damping factor η must be >= 0 (seconds)");
  EXPECT_EQ(error_of(shell + "-0.1}\n"),
            "m.yaml:4: shells[0].material.eta: the damping factor η must be >= 0 (seconds)");
}

TEST(ModelReader, PathFollowing) {
  const model::Model m = read_model_string(
      with_bodies({"probes: [{name: tip, body: top, point: [1, 0, 0]}]",
                   "solver:", "  analysis: static",
                   "  path_following: {method: displacement, probe: tip, direction: [0, 0, -2], "
                   "displacement: 3}"}),
      "m.yaml");
  EXPECT_EQ(m.solver.path.method, model::PathMethod::displacement);
  EXPECT_EQ(m.solver.path.probe, "tip");
  EXPECT_EQ(m.solver.path.direction, Vec3(0, 0, -1));
  EXPECT_EQ(m.solver.path.displacement, 3.0);
  EXPECT_EQ(m.solver.path.line, 9);
  const model::Model a = read_model_string(
      with_bodies({"solver:", "  analysis: static",
                   "  path_following: {method: arc_length, arc_length: 0.5, max_arc_length: 2, "
                   "load_weight: 1, target_iterations: 4, max_steps: 50}"}),
      "m.yaml");
  EXPECT_EQ(a.solver.path.method, model::PathMethod::arc_length);
  EXPECT_EQ(a.solver.path.arc_length, 0.5);
  EXPECT_EQ(a.solver.path.max_arc_length, 2.0);
  EXPECT_EQ(a.solver.path.load_weight, 1.0);
  EXPECT_EQ(a.solver.path.target_iterations, 4);
  EXPECT_EQ(a.solver.path.max_steps, 50);

  EXPECT_EQ(error_of(with_bodies({"solver:", "  path_following: {method: riks}"})),
            "m.yaml:7: solver.path_following.method: unknown method \"riks\" (valid: arc_length, "
            "displacement)");
  EXPECT_EQ(error_of(with_bodies({"solver:", "  path_following: {method: arc_length, probe: p}"})),
            "m.yaml:7: solver.path_following.probe: not used with method arc_length");
  EXPECT_EQ(
      error_of(with_bodies({"solver:",
                            "  path_following: {method: displacement, probe: nope, "
                            "displacement: 1}"})),
      "m.yaml:7: solver.path_following.probe: no probe named \"nope\" (give it under probes)");
  EXPECT_EQ(error_of(with_bodies(
                {"solver:", "  linear: true", "  path_following: {method: arc_length}"})),
            "m.yaml:8: solver.path_following.method: path following needs a nonlinear analysis "
            "(remove solver.linear)");
  EXPECT_EQ(error_of(with_bodies({"solver:",
                                  "  path_following: {method: displacement, probe: p, "
                                  "displacement: 1, direction: [0, 0, 0]}"})),
            "m.yaml:7: solver.path_following.direction: must not be zero");
}
