// Output writers (VTK series, CSV histories, summary JSON) and the progress display, fed with a
// hand-made model and fake snapshots.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "isoflex/app/progress.hpp"
#include "isoflex/io/history_writer.hpp"
#include "isoflex/io/shell_mesh.hpp"
#include "isoflex/io/summary_writer.hpp"
#include "isoflex/io/vtk_writer.hpp"
#include "isoflex/math/rotation.hpp"
#include "support/files.hpp"
#include "support/vtu.hpp"

namespace fs = std::filesystem;
using namespace isoflex;
using test::data_array;
using test::data_array_names;
using test::read_text;
using test::xml_error;

namespace {

// test::TempDir isoflex_<suite>_<test> below the system temp directory.
class TempDir : public test::TempDir {
 public:
  TempDir() : test::TempDir(fs::temp_directory_path() / ("isoflex_" + current_test())) {}

 private:
  static std::string current_test() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    return std::string(info->test_suite_name()) + "_" + info->name();
  }
};

std::vector<std::string> read_lines(const fs::path& p) {
  std::ifstream in(p);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

Mat3 rotation(const Vec3& axis, double angle) {
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

model::Model two_body_model() {
  model::Model m;
  m.name = "two";
  model::Body box;
  box.name = "box";
  box.mass = 1.0;
  box.shape.kind = model::ShapeKind::box;
  box.shape.size = Vec3(0.4, 0.2, 0.1);
  model::Body pyr;
  pyr.name = "top";
  pyr.mass = 2.0;
  pyr.shape.kind = model::ShapeKind::pyramid;
  pyr.shape.base = 0.3;
  pyr.shape.height = 0.6;
  pyr.shape.offset = Vec3(0.01, -0.02, -0.15);
  m.bodies = {box, pyr};
  model::Probe probe;
  probe.name = "tip";
  probe.body = "top";
  m.probes = {probe};
  return m;
}

integrate::Snapshot snapshot(int step, double t) {
  integrate::Snapshot s;
  s.step = step;
  s.t = t;
  s.kinetic_energy = 1.0 + t;
  s.potential_energy = -0.5 * t;
  s.total_energy = s.kinetic_energy + s.potential_energy;
  s.linear_momentum = Vec3(1.0, 2.0, 3.0 * t);
  s.angular_momentum = Vec3(-1.0, 0.1, t);
  s.constraint_violation = 1e-12 * (step + 1);
  s.newton_iterations = step == 0 ? 0 : 3;
  s.residual = 1e-11;
  integrate::BodyPose a;
  a.name = "box";
  a.position = Vec3(0.1 * t, 0.0, 0.0);
  a.directors = rotation(Vec3(0, 0, 1), 0.3 * t);
  a.velocity = Vec3(0.1, 0.0, 0.0);
  a.angular_velocity = Vec3(0.0, 0.0, 0.3);
  integrate::BodyPose b;
  b.name = "top";
  b.position = Vec3(1.0, 0.5, 0.25 + t);
  b.directors = rotation(Vec3(1, 2, -0.5), 0.7 + t);
  b.velocity = Vec3(0.0, 0.0, 1.0);
  b.angular_velocity = Vec3(2.0, -1.0, 5.0);
  s.bodies = {a, b};
  integrate::ProbeValue p;
  p.name = "tip";
  p.position = Vec3(1.0, 2.0, 3.0 + t);
  p.displacement = Vec3(0.0, 0.0, t);
  p.velocity = Vec3(0.0, 0.0, 1.0);
  s.probes = {p};
  return s;
}

// ---- a small reader of the .vtu files written here (ascii, one Piece) ----

long attribute(const std::string& xml, const std::string& name) {
  const std::regex re(name + "=\"([0-9]+)\"");
  std::smatch m;
  if (!std::regex_search(xml, m, re)) return -1;
  return std::stol(m[1]);
}

struct Vtu {
  long n_points, n_cells;
  std::vector<Vec3> points, velocity;
  std::vector<long> connectivity, offsets, types, body_id, part;
  // Only with shell elements:
  std::vector<Vec3> displacement, director;
  std::vector<long> shell_id;
};

std::vector<long> as_long(const std::vector<double>& v) {
  return {v.begin(), v.end()};
}

std::vector<Vec3> as_vec3(const std::vector<double>& v) {
  std::vector<Vec3> out;
  for (std::size_t i = 0; i + 2 < v.size(); i += 3) out.emplace_back(v[i], v[i + 1], v[i + 2]);
  return out;
}

Vtu read_vtu(const fs::path& p) {
  const std::string xml = read_text(p);
  Vtu v;
  v.n_points = attribute(xml, "NumberOfPoints");
  v.n_cells = attribute(xml, "NumberOfCells");
  v.points = as_vec3(data_array(xml, "Points"));
  v.velocity = as_vec3(data_array(xml, "velocity"));
  v.connectivity = as_long(data_array(xml, "connectivity"));
  v.offsets = as_long(data_array(xml, "offsets"));
  v.types = as_long(data_array(xml, "types"));
  v.body_id = as_long(data_array(xml, "body_id"));
  v.part = as_long(data_array(xml, "part"));
  v.displacement = as_vec3(data_array(xml, "displacement"));
  v.director = as_vec3(data_array(xml, "director"));
  v.shell_id = as_long(data_array(xml, "shell_id"));
  return v;
}

// Checks that the arrays are mutually consistent, as ParaView requires.
void expect_consistent(const Vtu& v) {
  EXPECT_EQ(static_cast<long>(v.points.size()), v.n_points);
  EXPECT_EQ(static_cast<long>(v.velocity.size()), v.n_points);
  EXPECT_EQ(static_cast<long>(v.offsets.size()), v.n_cells);
  EXPECT_EQ(static_cast<long>(v.types.size()), v.n_cells);
  EXPECT_EQ(static_cast<long>(v.body_id.size()), v.n_cells);
  EXPECT_EQ(static_cast<long>(v.part.size()), v.n_cells);
  if (!v.shell_id.empty()) {
    EXPECT_EQ(static_cast<long>(v.shell_id.size()), v.n_cells);
    EXPECT_EQ(static_cast<long>(v.displacement.size()), v.n_points);
    EXPECT_EQ(static_cast<long>(v.director.size()), v.n_points);
  }
  ASSERT_FALSE(v.offsets.empty());
  EXPECT_EQ(v.offsets.back(), static_cast<long>(v.connectivity.size()));
  long begin = 0;
  for (std::size_t c = 0; c < v.offsets.size(); ++c) {
    const long n = v.offsets[c] - begin;
    switch (v.types[c]) {
      case 1:
        EXPECT_EQ(n, 1);
        break;  // vertex
      case 3:
        EXPECT_EQ(n, 2);
        break;  // line
      case 5:
        EXPECT_EQ(n, 3);
        break;  // triangle
      case 9:
        EXPECT_EQ(n, 4);
        break;  // quad
      case 7:
        EXPECT_GE(n, 3);
        break;  // polygon
      case 12:
        EXPECT_EQ(n, 8);
        break;  // hexahedron
      default:
        ADD_FAILURE() << "unexpected cell type " << v.types[c];
    }
    begin = v.offsets[c];
  }
  for (const long id : v.connectivity) {
    EXPECT_GE(id, 0);
    EXPECT_LT(id, v.n_points);
  }
}

// Cells of the two-body model, counted from the shapes: box 6 quads, pyramid 1 quad + 4
// triangles, plus 3 director lines each.
constexpr long kBoxPoints = 8 + 4, kBoxCells = 6 + 3, kBoxConn = 6 * 4 + 3 * 2;
constexpr long kPyrPoints = 5 + 4, kPyrCells = 5 + 3, kPyrConn = 4 + 4 * 3 + 3 * 2;

// ---- shells: the two-body model plus a beam element and three shells ----

// Shells in the order q, p and one named with XML's special characters (no elements), so that
// shell_id follows the model, not the order of the snapshot's elements.
const char* const kOddShellName = "a<&>\"b";

model::Model shell_model() {
  auto m = two_body_model();
  model::Beam rod;
  rod.name = "rod";
  rod.points = {Vec3(0, 0, -1), Vec3(1, 0, -1)};
  rod.draw_width = 0.1;
  rod.draw_height = 0.05;
  m.beams = {rod};
  for (const char* name : {"q", "p", kOddShellName}) {
    model::Shell sh;
    sh.name = name;
    m.shells.push_back(sh);
  }
  return m;
}

// Node indices of shell_snapshot: bodies 0, 1; beam nodes 2, 3; shell p (2 × 1 elements) nodes
// 4 … 9 = 4 + i + 3j on a grid i = 0…2, j = 0…1; shell q (one element) nodes 10 … 13.
constexpr int kFirstShellNode = 4, kShellNodes = 10;

// Stress resultants of the shell elements: distinct per element and step, and exact in 15
// significant digits, so that the written values compare exactly.
integrate::ShellElementValue shell_element(const char* shell, int element, std::array<int, 4> nodes,
                                           int step) {
  integrate::ShellElementValue e;
  e.shell = shell;
  e.element = element;
  e.nodes = nodes;
  const double f = (1 + step) * (element + 1) * (shell[0] == 'q' ? -1.0 : 1.0);
  e.n << 1.5 * f, 0.25 * f, 0.25 * f, -2.0 * f;
  e.m << 0.5 * f, -0.125 * f, -0.125 * f, 0.75 * f;
  e.q << 3.0 * f, -4.0 * f;
  return e;
}

integrate::Snapshot shell_snapshot(int step, double t) {
  integrate::Snapshot s = snapshot(step, t);
  Mat3 along_x;  // beam triad along +x: d₁ = y, d₂ = z, d₃ = x
  along_x << 0, 0, 1, 1, 0, 0, 0, 1, 0;
  for (const double x : {0.0, 1.0}) {
    integrate::BodyPose b;
    b.position = Vec3(x, 0, -1);
    b.directors = along_x;
    s.bodies.push_back(b);
  }
  s.beam_elements = {{"rod", 0, 2, 3, Vec3(1, 2, 3), Vec3(-0.5, 0.25, 4)}};
  for (int j = 0; j <= 1; ++j) {  // p: bent up along x, its directors turning about −y
    for (int i = 0; i <= 2; ++i) {
      integrate::BodyPose b;
      b.position = Vec3(0.5 * i, 0.4 * j, t * (0.1 * i + 0.2 * j));
      b.directors = rotation(Vec3(0, 1, 0), -0.2 * t * i);
      b.velocity = Vec3(0, 0, 0.1 * i + 0.2 * j);
      s.bodies.push_back(b);
    }
  }
  for (const auto& X : {Vec3(2, 0, 0), Vec3(2, 0.5, 0), Vec3(2, 0.5, 0.5), Vec3(2, 0, 0.5)}) {
    integrate::BodyPose b;  // q: in the plane x = 2 + 0.3 t, director +x
    b.position = X + Vec3(0.3 * t, 0, 0);
    b.directors = rotation(Vec3(0, 1, 0), std::numbers::pi / 2);
    b.velocity = Vec3(0.3, 0, 0);
    s.bodies.push_back(b);
  }
  s.shell_elements = {shell_element("p", 0, {4, 5, 8, 7}, step),
                      shell_element("p", 1, {5, 6, 9, 8}, step),
                      shell_element("q", 0, {10, 11, 12, 13}, step)};
  return s;
}

// What the scalar shell arrays hold for an element (names as written).
double shell_value(const integrate::ShellElementValue& e, const std::string& name) {
  if (name == "n11") return e.n(0, 0);
  if (name == "n22") return e.n(1, 1);
  if (name == "n12") return e.n(0, 1);
  if (name == "m11") return e.m(0, 0);
  if (name == "m22") return e.m(1, 1);
  if (name == "m12") return e.m(0, 1);
  if (name == "q1") return e.q(0);
  if (name == "q2") return e.q(1);
  const Eigen::Matrix2d& a = name == "n_vm" ? e.n : e.m;  // the formula of shell_mesh.hpp
  return std::sqrt(a(0, 0) * a(0, 0) + a(1, 1) * a(1, 1) - a(0, 0) * a(1, 1) +
                   3 * a(0, 1) * a(0, 1));
}

const char* const kShellScalars[] = {"n11", "n22", "n12", "m11",  "m22",
                                     "m12", "q1",  "q2",  "n_vm", "m_vm"};

double min_distance(const std::vector<Vec3>& points, const Vec3& x, std::size_t* index = nullptr) {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double d = (points[i] - x).norm();
    if (d < best) {
      best = d;
      if (index != nullptr) *index = i;
    }
  }
  return best;
}

}  // namespace

// ---------------------------------------------------------------- VtkWriter

TEST(VtkWriter, WritesEveryKthAndLastSnapshotWithConsistentArrays) {
  TempDir dir;
  const auto model = two_body_model();
  {
    io::VtkSeriesWriter w(dir.path(), model, 2, model::VtkFormat::binary);
    w.on_snapshot(snapshot(0, 0.0));
    w.on_snapshot(snapshot(1, 0.1));
    w.on_snapshot(snapshot(2, 0.2));
    w.on_snapshot(snapshot(3, 0.3));
    w.on_finish();
    EXPECT_EQ(w.files(), (std::vector<std::string>{"vtk/step_000000.vtu", "vtk/step_000002.vtu",
                                                   "vtk/step_000003.vtu"}));
  }
  EXPECT_TRUE(fs::exists(dir.path() / "vtk/step_000000.vtu"));
  EXPECT_FALSE(fs::exists(dir.path() / "vtk/step_000001.vtu"));
  EXPECT_TRUE(fs::exists(dir.path() / "vtk/step_000002.vtu"));
  EXPECT_TRUE(fs::exists(dir.path() / "vtk/step_000003.vtu"));
  for (const char* f : {"vtk/step_000000.vtu", "vtk/step_000002.vtu", "vtk/step_000003.vtu"}) {
    SCOPED_TRACE(f);
    const Vtu v = read_vtu(dir.path() / f);
    EXPECT_EQ(v.n_points, kBoxPoints + kPyrPoints);
    EXPECT_EQ(v.n_cells, kBoxCells + kPyrCells);
    EXPECT_EQ(static_cast<long>(v.connectivity.size()), kBoxConn + kPyrConn);
    expect_consistent(v);
    // body ids and parts in order: box shape, box directors, pyramid shape, pyramid directors
    std::vector<long> ids, parts;
    for (int c = 0; c < 6; ++c) ids.push_back(0), parts.push_back(0);
    for (int a = 1; a <= 3; ++a) ids.push_back(0), parts.push_back(a);
    for (int c = 0; c < 5; ++c) ids.push_back(1), parts.push_back(0);
    for (int a = 1; a <= 3; ++a) ids.push_back(1), parts.push_back(a);
    EXPECT_EQ(v.body_id, ids);
    EXPECT_EQ(v.part, parts);
  }
  // no temporary files left behind
  for (const auto& e : fs::recursive_directory_iterator(dir.path())) {
    EXPECT_NE(e.path().extension(), ".tmp") << e.path();
  }
}

TEST(VtkWriter, NoExtraFileWhenLastSnapshotWasWritten) {
  TempDir dir;
  const auto model = two_body_model();
  io::VtkSeriesWriter w(dir.path(), model, 2, model::VtkFormat::binary);
  for (int k = 0; k < 3; ++k) w.on_snapshot(snapshot(k, 0.1 * k));
  w.on_finish();
  EXPECT_EQ(w.files(), (std::vector<std::string>{"vtk/step_000000.vtu", "vtk/step_000002.vtu"}));
}

TEST(VtkWriter, CollectionListsFilesAndTimes) {
  TempDir dir;
  const auto model = two_body_model();
  io::VtkSeriesWriter w(dir.path(), model, 1, model::VtkFormat::binary);
  const double times[] = {0.0, 0.125, 0.3};
  for (int k = 0; k < 3; ++k) {
    w.on_snapshot(snapshot(k, times[k]));
    // valid after every added file, before on_finish
    const std::string pvd = read_text(dir.path() / "results.pvd");
    EXPECT_NE(pvd.find("</VTKFile>"), std::string::npos);
    const std::regex ds("<DataSet timestep=\"([^\"]*)\" group=\"\" part=\"0\" file=\"([^\"]*)\"/>");
    std::vector<std::pair<double, std::string>> entries;
    for (std::sregex_iterator it(pvd.begin(), pvd.end(), ds), end; it != end; ++it) {
      entries.emplace_back(std::stod((*it)[1]), (*it)[2]);
    }
    ASSERT_EQ(entries.size(), static_cast<std::size_t>(k + 1));
    for (int j = 0; j <= k; ++j) {
      EXPECT_EQ(entries[j].first, times[j]);
      EXPECT_EQ(entries[j].second, "vtk/step_00000" + std::to_string(j) + ".vtu");
      EXPECT_TRUE(fs::exists(dir.path() / entries[j].second));
    }
  }
  w.on_finish();
  const std::string pvd = read_text(dir.path() / "results.pvd");
  EXPECT_NE(pvd.find("type=\"Collection\""), std::string::npos);
  EXPECT_FALSE(fs::exists(dir.path() / "results.pvd.tmp"));
}

TEST(VtkWriter, PyramidApexAndVelocityInRotatedPose) {
  TempDir dir;
  const auto model = two_body_model();
  const auto s = snapshot(0, 0.4);
  io::VtkSeriesWriter w(dir.path(), model, 1, model::VtkFormat::binary);
  w.on_snapshot(s);
  w.on_finish();
  const Vtu v = read_vtu(dir.path() / "vtk/step_000000.vtu");
  const auto& pose = s.bodies[1];
  const auto& shape = model.bodies[1].shape;
  const Mat3& R = pose.directors;
  ASSERT_GT((R - Mat3::Identity()).norm(), 0.1);  // really rotated
  const Vec3 apex = pose.position + R * (shape.offset + shape.height * Vec3::UnitZ());
  std::size_t i = 0;
  EXPECT_LT(min_distance(v.points, apex, &i), 1e-12);
  const Vec3 expected_velocity = pose.velocity + pose.angular_velocity.cross(apex - pose.position);
  EXPECT_LT((v.velocity[i] - expected_velocity).norm(), 1e-12);
  // the base corners lie in the plane through φ + R·offset normal to d₃
  const Vec3 base_centre = pose.position + R * shape.offset;
  const double a = 0.5 * shape.base;
  for (const double sx : {-1.0, 1.0}) {
    for (const double sy : {-1.0, 1.0}) {
      const Vec3 corner = base_centre + R * Vec3(sx * a, sy * a, 0.0);
      EXPECT_LT(min_distance(v.points, corner), 1e-12);
    }
  }
  // director tips of the pyramid: length 0.5 · max(base, height)
  const double len = 0.5 * shape.height;
  for (int k = 0; k < 3; ++k) {
    EXPECT_LT(min_distance(v.points, pose.position + len * R.col(k)), 1e-12);
  }
}

// A beam element is drawn as a hexahedron with positive volume in VTK's vertex order (bottom face
// at node a counter-clockwise about d₃, top face at node b), corners φ ± w/2 d₁ ± h/2 d₂.
TEST(VtkWriter, BeamElementHexahedron) {
  integrate::BodyPose a, b;
  const Mat3 R = rodrigues(Vec3(0.3, -0.4, 0.2));
  a.directors = R;
  b.directors = rodrigues(Vec3(0.0, 0.1, 0.0)) * R;  // bent and twisted
  a.position = Vec3(1, 2, 3);
  b.position = a.position + 0.7 * R.col(2);
  a.velocity = Vec3(1, 0, 0);
  a.angular_velocity = Vec3(0, 0, 2);
  const io::BodyMesh m = io::beam_element_mesh(a, b, {0.2, 0.1});
  ASSERT_EQ(m.points.size(), 8u);
  ASSERT_EQ(m.types, std::vector<unsigned char>{io::kVtkHexahedron});
  EXPECT_EQ(m.offsets, std::vector<int>{8});
  EXPECT_EQ(m.parts, std::vector<int>{io::kBeamPart});
  const Vec3 p1 = m.points[1] - m.points[0], p3 = m.points[3] - m.points[0],
             p4 = m.points[4] - m.points[0];
  EXPECT_GT(p1.cross(p3).dot(p4), 0.0);
  EXPECT_LT((m.points[2] - (a.position + 0.1 * R.col(0) + 0.05 * R.col(1))).norm(), 1e-15);
  EXPECT_LT(
      (m.points[4] - (b.position - 0.1 * b.directors.col(0) - 0.05 * b.directors.col(1))).norm(),
      1e-15);
  EXPECT_LT(
      (m.velocities[2] - (a.velocity + a.angular_velocity.cross(m.points[2] - a.position))).norm(),
      1e-15);
}

TEST(VtkWriter, ShapeMeshesOfAllKindsAreClosedAndOriented) {
  integrate::BodyPose pose;
  pose.position = Vec3(0.3, -0.2, 1.0);
  pose.directors = rotation(Vec3(0.2, 1.0, 0.4), 1.1);
  auto make = [](model::ShapeKind kind) {
    model::Shape s;
    s.kind = kind;
    s.size = Vec3(1.0, 0.5, 0.25);
    s.radius = 0.3;
    s.height = 0.8;
    s.base = 0.4;
    s.offset = Vec3(0.05, 0.1, -0.2);
    return s;
  };
  struct Expect {
    model::ShapeKind kind;
    std::size_t points, cells;
  };
  const int n = io::kRoundSegments, rings = io::kSphereRings;
  const Expect expect[] = {
      {model::ShapeKind::none, 1 + 4, 1 + 3},
      {model::ShapeKind::box, 8 + 4, 6 + 3},
      {model::ShapeKind::pyramid, 5 + 4, 5 + 3},
      {model::ShapeKind::cylinder, static_cast<std::size_t>(2 * n + 4),
       static_cast<std::size_t>(n + 2 + 3)},
      {model::ShapeKind::sphere, static_cast<std::size_t>(2 + (rings - 1) * n + 4),
       static_cast<std::size_t>(rings * n + 3)},
  };
  for (const auto& e : expect) {
    SCOPED_TRACE(static_cast<int>(e.kind));
    const auto shape = make(e.kind);
    const auto m = io::body_mesh(shape, pose);
    EXPECT_EQ(m.points.size(), e.points);
    EXPECT_EQ(m.types.size(), e.cells);
    EXPECT_EQ(m.offsets.size(), e.cells);
    EXPECT_EQ(m.parts.size(), e.cells);
    EXPECT_EQ(static_cast<std::size_t>(m.offsets.back()), m.connectivity.size());
    if (e.kind == model::ShapeKind::none) {
      EXPECT_EQ(m.types.front(), io::kVtkVertex);
      EXPECT_LT((m.points[m.connectivity.front()] - pose.position).norm(), 1e-15);
      continue;
    }
    // Closed, outward-oriented surface: Σ ½ (xᵢ × xᵢ₊₁) over each face sums to zero, and the
    // enclosed volume (divergence theorem) is positive.
    Vec3 area_sum = Vec3::Zero();
    double volume = 0.0;
    int begin = 0;
    const Vec3 c = pose.position + pose.directors * shape.offset;
    for (std::size_t k = 0; k < m.types.size(); ++k) {
      const int end = m.offsets[k];
      if (m.parts[k] == 0) {
        Vec3 area = Vec3::Zero();
        for (int j = begin; j < end; ++j) {
          const int j1 = j + 1 < end ? j + 1 : begin;
          area += 0.5 * (m.points[m.connectivity[j]] - c).cross(m.points[m.connectivity[j1]] - c);
        }
        area_sum += area;
        volume += area.dot(m.points[m.connectivity[begin]] - c) / 3.0;
      }
      begin = end;
    }
    EXPECT_LT(area_sum.norm(), 1e-12);
    double exact = 0.0;
    switch (e.kind) {
      case model::ShapeKind::box:
        exact = shape.size.prod();
        break;
      case model::ShapeKind::pyramid:
        exact = shape.base * shape.base * shape.height / 3.0;
        break;
      case model::ShapeKind::cylinder:
        exact = std::numbers::pi * shape.radius * shape.radius * shape.height;
        break;
      case model::ShapeKind::sphere:
        exact = 4.0 / 3.0 * std::numbers::pi * std::pow(shape.radius, 3);
        break;
      default:
        break;
    }
    EXPECT_GT(volume, 0.0);
    EXPECT_NEAR(volume, exact, 0.08 * exact);  // polygonal approximations of round shapes
  }
}

TEST(VtkWriter, DirectorLength) {
  model::Shape s;
  EXPECT_EQ(io::director_length(s), 0.2);
  s.kind = model::ShapeKind::box;
  s.size = Vec3(0.4, 1.2, 0.3);
  EXPECT_DOUBLE_EQ(io::director_length(s), 0.6);
  s.kind = model::ShapeKind::cylinder;
  s.radius = 0.5;
  s.height = 0.2;
  EXPECT_DOUBLE_EQ(io::director_length(s), 0.5);
  s.kind = model::ShapeKind::sphere;
  s.radius = 0.25;
  EXPECT_DOUBLE_EQ(io::director_length(s), 0.25);
}

TEST(VtkWriter, ZeroEveryWritesNothing) {
  TempDir dir;
  const auto model = two_body_model();
  io::VtkSeriesWriter w(dir.path(), model, 0, model::VtkFormat::binary);
  w.on_snapshot(snapshot(0, 0.0));
  w.on_finish();
  EXPECT_TRUE(w.files().empty());
  EXPECT_FALSE(fs::exists(dir.path() / "results.pvd"));
}

// ---------------------------------------------------------------- shells in the VTK series

// Shell elements become VTK_QUADs after the cells of the bodies and beams, over points shared by
// neighbouring elements in node order, with resultants, von Mises magnitudes and shell ids as
// cell data and the director and displacement as point data; a shell name that needs escaping
// keeps the file well-formed.
TEST(VtkWriter, ShellQuadsPointsAndCellData) {
  TempDir dir;
  const auto model = shell_model();
  const auto s0 = shell_snapshot(0, 0.0), s1 = shell_snapshot(1, 0.5);
  {
    io::VtkSeriesWriter w(dir.path(), model, 1, model::VtkFormat::binary);
    w.on_snapshot(s0);
    w.on_snapshot(s1);
    w.on_finish();
  }
  // Bodies, then the beam's hexahedron (8 points, one cell), then the shells.
  constexpr long kOtherPoints = kBoxPoints + kPyrPoints + 8;
  constexpr long kOtherCells = kBoxCells + kPyrCells + 1;
  static_assert(kOtherPoints == 29 && kOtherCells == 18);
  for (const auto* s : {&s0, &s1}) {
    SCOPED_TRACE(s->step);
    const fs::path file = dir.path() / ("vtk/step_00000" + std::to_string(s->step) + ".vtu");
    const std::string xml = read_text(file);
    EXPECT_EQ(xml_error(xml), "");
    const Vtu v = read_vtu(file);
    EXPECT_EQ(v.n_points, kOtherPoints + kShellNodes);
    EXPECT_EQ(v.n_cells, kOtherCells + 3);
    expect_consistent(v);
    ASSERT_EQ(static_cast<long>(v.types.size()), v.n_cells);
    ASSERT_EQ(static_cast<long>(v.points.size()), v.n_points);
    auto tail = [](const std::vector<long>& a, std::size_t n) {
      return std::vector<long>(a.end() - static_cast<long>(n), a.end());
    };
    EXPECT_EQ(tail(v.types, 4), (std::vector<long>{12, 9, 9, 9}));
    EXPECT_EQ(tail(v.part, 4), (std::vector<long>{4, 5, 5, 5}));
    EXPECT_EQ(tail(v.body_id, 4), (std::vector<long>{-1, -1, -1, -1}));
    EXPECT_EQ(tail(v.offsets, 4).back(), static_cast<long>(v.connectivity.size()));
    // Shell node k is point 29 + k − 4; the quads keep the elements' (counter-clockwise) order.
    EXPECT_EQ(tail(v.connectivity, 12),
              (std::vector<long>{29, 30, 33, 32, 30, 31, 34, 33, 35, 36, 37, 38}));
    std::vector<long> ids(kOtherCells, -1);
    ids.insert(ids.end(), {1, 1, 0});  // p is model.shells[1], q is model.shells[0]
    EXPECT_EQ(v.shell_id, ids);
    // Points, velocities and directors of the shell nodes; 0 director on the other points.
    for (int k = 0; k < kShellNodes; ++k) {
      const auto& pose = s->bodies[kFirstShellNode + k];
      EXPECT_LT((v.points[kOtherPoints + k] - pose.position).norm(), 1e-14) << k;
      EXPECT_LT((v.velocity[kOtherPoints + k] - pose.velocity).norm(), 1e-14) << k;
      EXPECT_LT((v.director[kOtherPoints + k] - pose.directors.col(2)).norm(), 1e-14) << k;
    }
    for (long i = 0; i < kOtherPoints; ++i) {
      EXPECT_EQ(v.director[i], Vec3::Zero()) << i;
      EXPECT_EQ(v.displacement[i], Vec3::Zero()) << i;
    }
    // Displacement from the first snapshot: 0 there, φ(t) − φ(0) later (and really moved).
    double moved = 0.0;
    for (int k = 0; k < kShellNodes; ++k) {
      const Vec3 u =
          s->bodies[kFirstShellNode + k].position - s0.bodies[kFirstShellNode + k].position;
      EXPECT_LT((v.displacement[kOtherPoints + k] - u).norm(), 1e-14) << k;
      moved = std::max(moved, u.norm());
    }
    EXPECT_EQ(moved > 0.1, s->step == 1);
    // Resultants in the element frame and the von Mises magnitudes; 0 on bodies and the beam.
    for (const char* name : kShellScalars) {
      SCOPED_TRACE(name);
      const auto values = data_array(xml, name);
      ASSERT_EQ(static_cast<long>(values.size()), v.n_cells);
      for (long c = 0; c < kOtherCells; ++c) EXPECT_EQ(values[c], 0.0) << c;
      for (int e = 0; e < 3; ++e) {
        const double expected = shell_value(s->shell_elements[e], name);
        EXPECT_NEAR(values[kOtherCells + e], expected, 1e-14 * std::abs(expected)) << e;
        EXPECT_NE(expected, 0.0);
      }
    }
    // The beam arrays n, m: the beam element's values, 0 on the shells.
    const auto n = as_vec3(data_array(xml, "n")), m = as_vec3(data_array(xml, "m"));
    ASSERT_EQ(static_cast<long>(n.size()), v.n_cells);
    EXPECT_EQ(n[kOtherCells - 1], Vec3(1, 2, 3));
    EXPECT_EQ(m[kOtherCells - 1], Vec3(-0.5, 0.25, 4));
    for (long c = kOtherCells; c < v.n_cells; ++c) {
      EXPECT_EQ(n[c], Vec3::Zero());
      EXPECT_EQ(m[c], Vec3::Zero());
    }
    // Array names and order; the legend of shell_id as field data, the odd name escaped.
    EXPECT_EQ(data_array_names(xml, "PointData"),
              (std::vector<std::string>{"velocity", "displacement", "director"}));
    EXPECT_EQ(data_array_names(xml, "CellData"),
              (std::vector<std::string>{"body_id", "part", "n", "m", "shell_id", "n11", "n22",
                                        "n12", "m11", "m22", "m12", "q1", "q2", "n_vm", "m_vm"}));
    const std::string odd = "shell_id[a&lt;&amp;&gt;&quot;b]";
    EXPECT_EQ(data_array_names(xml, "FieldData"),
              (std::vector<std::string>{"TimeValue", "shell_id[q]", "shell_id[p]", odd}));
    EXPECT_EQ(data_array(xml, "shell_id[q]"), std::vector<double>{0});
    EXPECT_EQ(data_array(xml, "shell_id[p]"), std::vector<double>{1});
    EXPECT_EQ(data_array(xml, odd), std::vector<double>{2});
  }
}

// The displacement is from the first snapshot the writer sees, even when that one is not written
// (every = 2 and a series starting at step 1).
TEST(VtkWriter, ShellDisplacementIsFromTheFirstSnapshot) {
  TempDir dir;
  const auto model = shell_model();
  const auto first = shell_snapshot(1, 0.25);
  {
    io::VtkSeriesWriter w(dir.path(), model, 2, model::VtkFormat::binary);
    w.on_snapshot(first);
    w.on_snapshot(shell_snapshot(2, 0.5));
    w.on_snapshot(shell_snapshot(3, 0.75));
    w.on_finish();
    EXPECT_EQ(w.files(), (std::vector<std::string>{"vtk/step_000002.vtu", "vtk/step_000003.vtu"}));
  }
  for (const int step : {2, 3}) {
    SCOPED_TRACE(step);
    const auto s = shell_snapshot(step, 0.25 * step);
    const Vtu v = read_vtu(dir.path() / ("vtk/step_00000" + std::to_string(step) + ".vtu"));
    expect_consistent(v);
    ASSERT_EQ(static_cast<long>(v.displacement.size()), v.n_points);
    for (int k = 0; k < kShellNodes; ++k) {
      const int node = kFirstShellNode + k;
      const Vec3 u = s.bodies[node].position - first.bodies[node].position;
      EXPECT_LT((v.displacement[v.n_points - kShellNodes + k] - u).norm(), 1e-14) << k;
    }
  }
}

// Without shell elements (no shells in the model, or shells but no elements in the snapshot)
// the ascii file is byte for byte what the writer wrote before shells existed (this text was
// written by that writer): a body without shape, its director lines and a beam element.
TEST(VtkWriter, OutputWithoutShellsIsUnchanged) {
  const std::string expected =
      "<?xml version=\"1.0\"?>\n"
      "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      "  <UnstructuredGrid>\n"
      "    <FieldData>\n"
      "      <DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" "
      "format=\"ascii\">\n"
      "        0.125\n"
      "      </DataArray>\n"
      "    </FieldData>\n"
      "    <Piece NumberOfPoints=\"13\" NumberOfCells=\"5\">\n"
      "      <PointData Vectors=\"velocity\">\n"
      "        <DataArray type=\"Float64\" Name=\"velocity\" NumberOfComponents=\"3\" "
      "format=\"ascii\">\n"
      "          0.5 0 0\n"
      "          0.5 0 0\n"
      "          0.5 0.2 0\n"
      "          0.3 0 0\n"
      "          0.5 0 0\n"
      "          0 0 0\n"
      "          0 0 0\n"
      "          0 0 0\n"
      "          0 0 0\n"
      "          0 0 0\n"
      "          0 0 0\n"
      "          0 0 0\n"
      "          0 0 0\n"
      "        </DataArray>\n"
      "      </PointData>\n"
      "      <CellData Scalars=\"body_id\">\n"
      "        <DataArray type=\"Int32\" Name=\"body_id\" format=\"ascii\">\n"
      "          0 0 0 0 \n"
      "          -1 \n"
      "        </DataArray>\n"
      "        <DataArray type=\"Int32\" Name=\"part\" format=\"ascii\">\n"
      "          0 1 2 3 \n"
      "          4 \n"
      "        </DataArray>\n"
      "        <DataArray type=\"Float64\" Name=\"n\" NumberOfComponents=\"3\" format=\"ascii\">\n"
      "          0 0 0\n"
      "          0 0 0\n"
      "          0 0 0\n"
      "          0 0 0\n"
      "          1 2 3\n"
      "        </DataArray>\n"
      "        <DataArray type=\"Float64\" Name=\"m\" NumberOfComponents=\"3\" format=\"ascii\">\n"
      "          0 0 0\n"
      "          0 0 0\n"
      "          0 0 0\n"
      "          0 0 0\n"
      "          -0.5 0.25 4\n"
      "        </DataArray>\n"
      "      </CellData>\n"
      "      <Points>\n"
      "        <DataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\" "
      "format=\"ascii\">\n"
      "          1 2 3\n"
      "          1 2 3\n"
      "          1.2 2 3\n"
      "          1 2.2 3\n"
      "          1 2 3.2\n"
      "          0 -0.05 -0.025\n"
      "          0 0.05 -0.025\n"
      "          0 0.05 0.025\n"
      "          0 -0.05 0.025\n"
      "          1 -0.05 -0.025\n"
      "          1 0.05 -0.025\n"
      "          1 0.05 0.025\n"
      "          1 -0.05 0.025\n"
      "        </DataArray>\n"
      "      </Points>\n"
      "      <Cells>\n"
      "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n"
      "          0 \n"
      "          1 2 \n"
      "          1 3 \n"
      "          1 4 \n"
      "          5 6 7 8 9 10 11 12 \n"
      "        </DataArray>\n"
      "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n"
      "          1 3 5 7 \n"
      "          15 \n"
      "        </DataArray>\n"
      "        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n"
      "          1 3 3 3 \n"
      "          12 \n"
      "        </DataArray>\n"
      "      </Cells>\n"
      "    </Piece>\n"
      "  </UnstructuredGrid>\n"
      "</VTKFile>\n";
  model::Model m;
  model::Body body;
  body.name = "bob";
  body.mass = 1.0;
  m.bodies = {body};
  model::Beam beam;
  beam.name = "rod";
  beam.points = {Vec3(0, 0, 0), Vec3(1, 0, 0)};
  beam.draw_width = 0.1;
  beam.draw_height = 0.05;
  m.beams = {beam};
  integrate::Snapshot s;
  s.step = 0;
  s.t = 0.125;
  integrate::BodyPose a;
  a.position = Vec3(1, 2, 3);
  a.velocity = Vec3(0.5, 0, 0);
  a.angular_velocity = Vec3(0, 0, 1);
  integrate::BodyPose n0, n1;
  n0.directors << 0, 0, 1, 1, 0, 0, 0, 1, 0;  // d₁ = y, d₂ = z, d₃ = x
  n1.directors = n0.directors;
  n1.position = Vec3(1, 0, 0);
  s.bodies = {a, n0, n1};
  s.beam_elements = {{"rod", 0, 1, 2, Vec3(1, 2, 3), Vec3(-0.5, 0.25, 4)}};
  for (const bool shell_in_model : {false, true}) {
    SCOPED_TRACE(shell_in_model);
    TempDir dir;
    auto model = m;
    if (shell_in_model) model.shells.resize(1), model.shells[0].name = "p";
    {
      io::VtkSeriesWriter w(dir.path(), model, 1, model::VtkFormat::ascii);
      w.on_snapshot(s);
      w.on_finish();
    }
    EXPECT_EQ(read_text(dir.path() / "vtk/step_000000.vtu"), expected);
  }
}

// shell_mesh on its own: each node once, in node order, local connectivity; von_mises by known
// states and its invariance under a rotation of the frame; errors for bad node indices.
TEST(VtkWriter, ShellMeshAndVonMises) {
  const auto s0 = shell_snapshot(0, 0.0), s1 = shell_snapshot(1, 0.5);
  std::vector<Vec3> reference;
  for (const auto& b : s0.bodies) reference.push_back(b.position);
  const io::ShellMesh sm = io::shell_mesh(s1, reference);
  std::vector<int> nodes(kShellNodes);
  for (int k = 0; k < kShellNodes; ++k) nodes[k] = kFirstShellNode + k;
  EXPECT_EQ(sm.nodes, nodes);
  ASSERT_EQ(sm.mesh.points.size(), nodes.size());
  ASSERT_EQ(sm.displacements.size(), nodes.size());
  ASSERT_EQ(sm.directors.size(), nodes.size());
  EXPECT_EQ(sm.mesh.connectivity, (std::vector<int>{0, 1, 4, 3, 1, 2, 5, 4, 6, 7, 8, 9}));
  EXPECT_EQ(sm.mesh.offsets, (std::vector<int>{4, 8, 12}));
  EXPECT_EQ(sm.mesh.types, std::vector<unsigned char>(3, io::kVtkQuad));
  EXPECT_EQ(sm.mesh.parts, std::vector<int>(3, io::kShellPart));
  for (int k = 0; k < kShellNodes; ++k) {
    const auto& pose = s1.bodies[nodes[k]];
    EXPECT_EQ(sm.mesh.points[k], pose.position);
    EXPECT_EQ(sm.mesh.velocities[k], pose.velocity);
    EXPECT_EQ(sm.directors[k], pose.directors.col(2));
    EXPECT_EQ(sm.displacements[k], pose.position - reference[nodes[k]]);
  }

  Eigen::Matrix2d a;
  a << -3, 0, 0, 0;  // uniaxial
  EXPECT_DOUBLE_EQ(io::von_mises(a), 3.0);
  a << 2, 0, 0, 2;  // equibiaxial
  EXPECT_DOUBLE_EQ(io::von_mises(a), 2.0);
  a << 0, 1.5, 1.5, 0;  // pure shear
  EXPECT_DOUBLE_EQ(io::von_mises(a), std::sqrt(3.0) * 1.5);
  a << 1.5, 0.25, 0.25, -2;
  const Eigen::Matrix2d Q = Eigen::Rotation2Dd(0.7).toRotationMatrix();
  EXPECT_NEAR(io::von_mises(Q * a * Q.transpose()), io::von_mises(a), 1e-14);
  EXPECT_DOUBLE_EQ(io::von_mises(a), std::sqrt(1.5 * 1.5 + 4 + 3 + 3 * 0.0625));

  auto bad = s1;
  bad.shell_elements[1].nodes[2] = 99;
  EXPECT_THROW(io::shell_mesh(bad, reference), std::runtime_error);
  EXPECT_THROW(io::shell_mesh(s1, std::vector<Vec3>(reference.begin(), reference.end() - 1)),
               std::runtime_error);
  TempDir dir;
  auto model = shell_model();
  model.shells.pop_back();
  model.shells.pop_back();  // only q
  io::VtkSeriesWriter w(dir.path(), model, 1, model::VtkFormat::binary);
  EXPECT_THROW(w.on_snapshot(s0), std::runtime_error);  // p is not in the model
}

namespace {
// Runs the isoflex executable; its exit code, stdout and stderr.
int run_isoflex(const std::string& args, std::string& output) {
  const std::string cmd = std::string(ISOFLEX_BINARY) + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) return -1;
  std::array<char, 4096> buf;
  while (fgets(buf.data(), buf.size(), p)) output += buf.data();
  const int status = pclose(p);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}
}  // namespace

// `isoflex run` on a plate (2 × 1 elements, clamped along x = 0, under pressure) next to a rigid
// body: every file of results.pvd is well-formed and holds the plate's two quads after the body,
// the plate's nodes at t = 0, and its displacement and resultants at the end.
TEST(VtkWriter, IsoflexRunWritesShellQuads) {
  TempDir dir;
  std::ofstream(dir.path() / "plate.yaml") << R"(name: shell_vtk
solver: {dt: 0.01, t_end: 0.03}
bodies:
  - name: hub
    mass: 2
    inertia: [0.1, 0.2, 0.3]
    position: [-0.3, 0.25, 0]
    shape: {type: box, size: [0.2, 0.5, 0.1]}
shells:
  - name: p
    plate: {corners: [[0, 0, 0], [1, 0, 0], [1, 0.5, 0], [0, 0.5, 0]], elements: [2, 1]}
    material: {E: 1.0e5, nu: 0.3, thickness: 0.05, density: 100}
shell_supports:
  - {shell: p, edge: u0, translation: all, director: fixed}
shell_loads:
  - {shell: p, pressure: "100"}
)";
  std::string output;
  ASSERT_EQ(run_isoflex("run " + (dir.path() / "plate.yaml").string() + " -o " +
                            (dir.path() / "out").string(),
                        output),
            0)
      << output;
  const std::string pvd = read_text(dir.path() / "out/results.pvd");
  EXPECT_EQ(xml_error(pvd), "");
  const std::regex ds("file=\"([^\"]*)\"");
  std::vector<std::string> files;
  for (std::sregex_iterator it(pvd.begin(), pvd.end(), ds), end; it != end; ++it)
    files.push_back((*it)[1]);
  ASSERT_EQ(files.size(), 4u);  // t = 0 and three steps

  constexpr long kHubPoints = 8 + 4, kHubCells = 6 + 3, kPlatePoints = 6;
  std::vector<Vec3> initial;  // the plate's points in the first file
  for (const auto& f : files) {
    SCOPED_TRACE(f);
    const std::string xml = read_text(dir.path() / "out" / f);
    EXPECT_EQ(xml_error(xml), "");
    const Vtu v = read_vtu(dir.path() / "out" / f);
    expect_consistent(v);
    ASSERT_EQ(v.n_points, kHubPoints + kPlatePoints);
    ASSERT_EQ(v.n_cells, kHubCells + 2);
    ASSERT_EQ(static_cast<long>(v.displacement.size()), v.n_points);
    EXPECT_EQ(data_array(xml, "shell_id[p]"), std::vector<double>{0});
    const std::vector<Vec3> plate(v.points.end() - kPlatePoints, v.points.end());
    if (initial.empty()) initial = plate;
    for (long c = kHubCells; c < v.n_cells; ++c) {
      EXPECT_EQ(v.types[c], 9);
      EXPECT_EQ(v.part[c], 5);
      EXPECT_EQ(v.shell_id[c], 0);
      EXPECT_EQ(v.body_id[c], -1);
      // At t = 0 a 0.5 × 0.5 square of the plate, counter-clockwise about +z (the directors).
      const long begin = v.offsets[c - 1];
      Vec3 area = Vec3::Zero(), centre = Vec3::Zero();
      for (long k = 0; k < 4; ++k) {
        const long i = v.connectivity[begin + k], j = v.connectivity[begin + (k + 1) % 4];
        EXPECT_GE(i, kHubPoints);
        const Vec3 xi = initial[i - kHubPoints], xj = initial[j - kHubPoints];
        area += 0.5 * xi.cross(xj);
        centre += 0.25 * xi;
      }
      EXPECT_LT((area - Vec3(0, 0, 0.25)).norm(), 1e-14);
      EXPECT_NEAR(centre.y(), 0.25, 1e-14);
      EXPECT_NEAR(centre.x(), c == kHubCells ? 0.25 : 0.75, 1e-14);
    }
    double max_u = 0.0;
    for (long k = 0; k < kPlatePoints; ++k) {
      const long i = kHubPoints + k;
      EXPECT_LT((v.displacement[i] - (v.points[i] - initial[k])).norm(), 1e-14);
      EXPECT_NEAR(v.director[i].norm(), 1.0, 1e-12);
      if (f == files.front()) {
        EXPECT_EQ(v.director[i], Vec3::UnitZ());
      }
      if (initial[k].x() == 0.0) {  // clamped
        EXPECT_EQ(v.displacement[i], Vec3::Zero());
      }
      max_u = std::max(max_u, v.displacement[i].norm());
    }
    const auto m_vm = data_array(xml, "m_vm");
    ASSERT_EQ(static_cast<long>(m_vm.size()), v.n_cells);
    if (f == files.back()) {
      EXPECT_GT(max_u, 1e-3);  // the pressure has bent the plate
      EXPECT_GT(m_vm[kHubCells], 0.0);
    } else if (f == files.front()) {
      EXPECT_EQ(max_u, 0.0);
      EXPECT_EQ(m_vm[kHubCells], 0.0);
    }
  }
}

// A binary and an ascii file of the same snapshots hold the same arrays bit for bit: the ascii
// numbers are written with the digits that read back to the same double. The snapshots have
// numbers that need 16 or 17 of them.
TEST(VtkWriter, BinaryAndAsciiFilesHoldTheSameArraysBitForBit) {
  TempDir dir;
  std::vector<std::string> files;
  for (const auto format : {model::VtkFormat::binary, model::VtkFormat::ascii}) {
    io::VtkSeriesWriter w(dir.path() / (format == model::VtkFormat::ascii ? "ascii" : "binary"),
                          shell_model(), 1, format);
    for (int step = 0; step < 3; ++step) w.on_snapshot(shell_snapshot(step, 0.1 * step));
    w.on_finish();
    files = w.files();
  }
  ASSERT_EQ(files.size(), 3u);
  int long_numbers = 0;
  for (const auto& f : files) {
    SCOPED_TRACE(f);
    const std::string binary = read_text(dir.path() / "binary" / f);
    const std::string ascii = read_text(dir.path() / "ascii" / f);
    EXPECT_NE(binary.find("AppendedData"), std::string::npos);
    EXPECT_EQ(ascii.find("AppendedData"), std::string::npos);
    EXPECT_EQ(data_array_names(binary, "VTKFile").size(), 26u);
    EXPECT_EQ(test::data_arrays_difference(binary, ascii), "");
    for (const double v : data_array(binary, "Points"))
      long_numbers += std::stod(fmt::format("{:.15g}", v)) != v;
  }
  EXPECT_GT(long_numbers, 10);
}

// A binary file (the default) is version 1.0 with header_type="UInt64"; every array is appended,
// and the raw appended data are exactly their blocks, each its UInt64 byte count and that many
// bytes, in the order of the offsets, ending where </AppendedData> begins.
TEST(VtkWriter, AppendedBlocksAreWhereTheirOffsetsAndByteCountsSay) {
  TempDir dir;
  {
    io::VtkSeriesWriter w(dir.path(), shell_model(), 1, model::VtkFormat::binary);
    w.on_snapshot(shell_snapshot(0, 0.25));
    w.on_finish();
  }
  const std::string file = read_text(dir.path() / "vtk/step_000000.vtu");
  EXPECT_NE(file.find("<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" "
                      "byte_order=\"LittleEndian\" header_type=\"UInt64\">"),
            std::string::npos);
  const auto raw = file.find("<AppendedData encoding=\"raw\">\n   _");
  ASSERT_NE(raw, std::string::npos);
  EXPECT_EQ(file.find("format=\"ascii\""), std::string::npos);
  // Walked here by hand too: block k at offset k's position, its count, the next one after it.
  const std::size_t data = raw + std::string("<AppendedData encoding=\"raw\">\n   _").size();
  std::size_t at = 0, arrays = 0;
  for (auto tag = file.find("<DataArray"); tag < raw; tag = file.find("<DataArray", tag + 1)) {
    const std::regex offset(R"re(^<DataArray [^>]* format="appended" offset="([0-9]+)"/>)re");
    std::smatch m;
    const std::string element = file.substr(tag, file.find('>', tag) + 1 - tag);
    ASSERT_TRUE(std::regex_search(element, m, offset)) << element;
    EXPECT_EQ(std::stoull(m[1]), at) << element;
    std::uint64_t bytes;
    std::memcpy(&bytes, file.data() + data + at, sizeof bytes);
    at += sizeof bytes + bytes;
    ++arrays;
  }
  EXPECT_EQ(arrays, data_array_names(file, "VTKFile").size());
  EXPECT_EQ(arrays, 26u);  // 4 field data, 3 point data, 15 cell data, Points, 3 Cells
  EXPECT_EQ(file.substr(data + at), "\n  </AppendedData>\n</VTKFile>\n");
  EXPECT_EQ(test::appended_data_error(file), "");
  EXPECT_EQ(xml_error(file), "");

  // The check of support/vtu.hpp catches a wrong count and a missing block.
  std::string longer = file;
  ++longer[data];  // the first block's count, little-endian
  EXPECT_NE(test::appended_data_error(longer), "");
  std::string shorter = file;
  shorter.erase(data, 8 + 8);  // the first block (TimeValue: count and one Float64)
  EXPECT_NE(test::appended_data_error(shorter), "");
}

// The well-formedness check of support/vtu.hpp finds what it is there to find.
TEST(VtuSupport, XmlErrorFindsMalformedXml) {
  EXPECT_EQ(xml_error("<?xml version=\"1.0\"?>\n<a x=\"1&amp;2\"><!-- c --><b/>t &lt;</a>\n"), "");
  for (const char* bad : {
           "<a><b></a></b>",           // crossed
           "<a x=1></a>",              // unquoted attribute
           "<a x=\"&\"></a>",          // stray '&' in a value
           "<a x=\"1\" x=\"2\"></a>",  // duplicate attribute
           "<a>1 < 2</a>",             // '<' in text
           "<a></a><b></b>",           // two roots
           "<a><b></b>",               // unclosed
           "<a>x</a>y",                // text after the root
           "<a><!-- x -- y --></a>",   // "--" in a comment
       }) {
    EXPECT_NE(xml_error(bad), "") << bad;
  }
}

// ---------------------------------------------------------------- HistoryWriter

TEST(HistoryWriter, HeaderAndOneRowPerSnapshot) {
  TempDir dir;
  {
    io::HistoryWriter w(dir.path(), false);
    for (int k = 0; k < 3; ++k) {
      w.on_snapshot(snapshot(k, 0.1 * k));
      // flushed after every row
      EXPECT_EQ(read_lines(dir.path() / "history.csv").size(), static_cast<std::size_t>(k + 2));
    }
    w.on_finish();
  }
  const auto lines = read_lines(dir.path() / "history.csv");
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_EQ(lines[0],
            "t,kinetic_energy,potential_energy,total_energy,px,py,pz,Lx,Ly,Lz,"
            "constraint_violation,newton_iterations,residual");
  // 17 significant digits: values read back exactly
  const auto s = snapshot(1, 0.1);
  std::vector<double> row;
  std::istringstream in(lines[2]);
  for (std::string field; std::getline(in, field, ',');) row.push_back(std::stod(field));
  ASSERT_EQ(row.size(), 13u);
  EXPECT_EQ(row[0], s.t);
  EXPECT_EQ(row[1], s.kinetic_energy);
  EXPECT_EQ(row[2], s.potential_energy);
  EXPECT_EQ(row[3], s.total_energy);
  EXPECT_EQ(row[6], s.linear_momentum.z());
  EXPECT_EQ(row[9], s.angular_momentum.z());
  EXPECT_EQ(row[10], s.constraint_violation);
  EXPECT_EQ(row[11], 3.0);
  EXPECT_EQ(row[12], s.residual);
}

// A model with material damping: the work of the viscous forces in a last column.
TEST(HistoryWriter, DissipatedEnergyColumn) {
  TempDir dir;
  {
    io::HistoryWriter w(dir.path(), true);
    auto s = snapshot(1, 0.1);
    s.dissipated_energy = 0.1234567890123456789;
    w.on_snapshot(s);
    w.on_finish();
  }
  const auto lines = read_lines(dir.path() / "history.csv");
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0],
            "t,kinetic_energy,potential_energy,total_energy,px,py,pz,Lx,Ly,Lz,"
            "constraint_violation,newton_iterations,residual,dissipated_energy");
  const std::size_t comma = lines[1].rfind(',');
  EXPECT_EQ(std::stod(lines[1].substr(comma + 1)), 0.1234567890123456789);
  EXPECT_EQ(std::count(lines[1].begin(), lines[1].end(), ','), 13);
}

TEST(HistoryWriter, ProbeRows) {
  TempDir dir;
  const auto model = two_body_model();
  {
    io::ProbeWriter w(dir.path(), model);
    for (int k = 0; k < 3; ++k) w.on_snapshot(snapshot(k, 0.5 * k));
    w.on_finish();
  }
  const auto lines = read_lines(dir.path() / "probes.csv");
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_EQ(lines[0], "t,probe,x,y,z,ux,uy,uz,vx,vy,vz");
  EXPECT_EQ(lines[1], "0,tip,1,2,3,0,0,0,0,0,1");
  EXPECT_EQ(lines[3], "1,tip,1,2,4,0,0,1,0,0,1");
}

TEST(HistoryWriter, NoProbeFileWithoutProbes) {
  TempDir dir;
  auto model = two_body_model();
  model.probes.clear();
  io::ProbeWriter w(dir.path(), model);
  w.on_snapshot(snapshot(0, 0.0));
  w.on_finish();
  EXPECT_FALSE(fs::exists(dir.path() / "probes.csv"));
}

// ---------------------------------------------------------------- SummaryWriter

TEST(SummaryWriter, KeysValuesNullAndEscapes) {
  TempDir dir;
  io::RunSummary s;
  s.model = "pendulum \"A\"\\ 2\n";
  s.formulation = "reparametrized";
  s.n_coordinates = 240;
  s.n_constraints = 26;
  s.n_unknowns = 214;
  s.n_redundant_constraints = 0;
  s.steps = 1000;
  s.newton_iterations_total = 3012;
  s.dt = 0.01;
  s.t_end = 10.0;
  s.wall_time_s = 1.5;
  s.max_constraint_violation = 1e-13;
  s.energy_initial = -3.25;
  s.energy_final = std::numeric_limits<double>::infinity();
  s.max_energy_drift_after_loads = std::numeric_limits<double>::quiet_NaN();
  integrate::ProbeValue p;
  p.name = "tip";
  p.position = Vec3(1.0, 0.1, -2.0);
  p.displacement = Vec3(0.0, 0.0, -0.5);
  p.velocity = Vec3(0.0, std::numeric_limits<double>::quiet_NaN(), 0.25);
  s.probes = {p};
  s.status = "completed";
  s.message = "ok";
  const fs::path file = dir.path() / "sub" / "summary.json";
  io::write_summary_json(file, s);
  EXPECT_FALSE(fs::exists(dir.path() / "sub" / "summary.json.tmp"));
  const std::string json = read_text(file);
  EXPECT_NE(json.find("\"n_unknowns\": 214"), std::string::npos) << json;
  EXPECT_NE(json.find("\"max_energy_drift_after_loads\": null"), std::string::npos);
  EXPECT_NE(json.find("\"energy_final\": null"), std::string::npos);
  EXPECT_NE(json.find("\"dt\": 0.01"), std::string::npos);
  EXPECT_NE(json.find("\"energy_initial\": -3.25"), std::string::npos);
  EXPECT_NE(json.find("\"model\": \"pendulum \\\"A\\\"\\\\ 2\\n\""), std::string::npos) << json;
  EXPECT_NE(json.find("\"probes\": {\n    \"tip\": {\"position\": [1, 0.10000000000000001, -2], "
                      "\"displacement\": [0, 0, -0.5], \"velocity\": [0, null, 0.25]}\n  }"),
            std::string::npos)
      << json;
  EXPECT_NE(json.find("\"status\": \"completed\""), std::string::npos);
  for (const char* key :
       {"model", "formulation", "n_coordinates", "n_constraints", "n_unknowns",
        "n_redundant_constraints", "steps", "newton_iterations_total", "dt", "t_end", "wall_time_s",
        "max_constraint_violation", "energy_initial", "energy_final",
        "max_energy_drift_after_loads", "probes", "status", "message"}) {
    EXPECT_NE(json.find(std::string("\"") + key + "\": "), std::string::npos) << key;
  }
  EXPECT_EQ(json.find("nan"), std::string::npos);
  EXPECT_EQ(json.find("inf"), std::string::npos);
  EXPECT_EQ(json.find("newton_failed_starts"), std::string::npos);  // not an energy–momentum run
  s.newton_failed_starts = 7;
  EXPECT_NE(io::summary_json(s).find("\"newton_failed_starts\": 7,"), std::string::npos);
  EXPECT_EQ(json.find("subdivided_steps"), std::string::npos);  // not a time integration
  s.subdivided_steps = 3;
  EXPECT_NE(io::summary_json(s).find("\"subdivided_steps\": 3,"), std::string::npos);
}

TEST(SummaryWriter, EmptyProbesAndControlCharacters) {
  io::RunSummary s;
  s.status = "failed";
  s.message = std::string("bad\x01step\t");
  const std::string json = io::summary_json(s);
  EXPECT_NE(json.find("\"probes\": {},"), std::string::npos);
  EXPECT_NE(json.find("\"message\": \"bad\\u0001step\\t\"\n}"), std::string::npos) << json;
  EXPECT_NE(json.find("\"status\": \"failed\""), std::string::npos);
}

// ---------------------------------------------------------------- ProgressBar

TEST(ProgressBar, QuietWhenNotATerminal) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  {
    app::ProgressBar bar(1.0, f);
    EXPECT_FALSE(bar.active());
    bar.on_snapshot(snapshot(0, 0.0));
    bar.on_snapshot(snapshot(1, 0.5));
    bar.on_finish();
  }
  EXPECT_EQ(std::ftell(f), 0L);
  std::fclose(f);
}

TEST(ProgressBar, LineFormat) {
  EXPECT_EQ(app::ProgressBar::format_line(0.42, 420, 4.2, 3, 5.0),
            "[############..................]  42%  step 420  t=4.2000  it=3  ETA 00:05");
  EXPECT_EQ(app::ProgressBar::format_line(1.0, 1000, 10.0, 2, 0.0),
            "[##############################] 100%  step 1000  t=10.0000  it=2  ETA 00:00");
  EXPECT_EQ(app::ProgressBar::format_duration(-1.0), "--:--");
  EXPECT_EQ(app::ProgressBar::format_duration(3725.0), "1:02:05");
}

// The ETA follows the recent rate: a run that did half its work in 5 s and then slowed to 0.1
// in 20 s has 0.4 left at 0.005 per second, 80 s (the average since the start said 16.7 s).
TEST(ProgressBar, EtaFollowsTheRecentRate) {
  app::EtaEstimator e(10.0);
  EXPECT_LT(e.eta(), 0.0);
  e.add(0.0, 0.0);
  EXPECT_LT(e.eta(), 0.0);
  for (int i = 1; i <= 50; ++i) e.add(0.1 * i, 0.01 * i);  // 0.1 per second
  EXPECT_NEAR(e.eta(), 5.0, 1e-9);
  for (int i = 1; i <= 200; ++i) e.add(5.0 + 0.1 * i, 0.5 + 0.0005 * i);  // 0.005 per second
  EXPECT_NEAR(e.eta(), 80.0, 1e-6);
  app::EtaEstimator stalled;
  stalled.add(0.0, 0.3);
  stalled.add(20.0, 0.3);
  EXPECT_LT(stalled.eta(), 0.0);  // no progress: unknown, not infinite
}
