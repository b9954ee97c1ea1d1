// Output writers (VTK series, CSV histories, summary JSON) and the progress display, fed with a
// hand-made model and fake snapshots.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
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
#include "isoflex/io/summary_writer.hpp"
#include "isoflex/io/vtk_writer.hpp"
#include "isoflex/math/rotation.hpp"
#include "support/files.hpp"
#include "support/vtu.hpp"

namespace fs = std::filesystem;
using namespace isoflex;
using test::data_array;
using test::read_text;

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
    io::VtkSeriesWriter w(dir.path(), model, 2);
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
  io::VtkSeriesWriter w(dir.path(), model, 2);
  for (int k = 0; k < 3; ++k) w.on_snapshot(snapshot(k, 0.1 * k));
  w.on_finish();
  EXPECT_EQ(w.files(), (std::vector<std::string>{"vtk/step_000000.vtu", "vtk/step_000002.vtu"}));
}

TEST(VtkWriter, CollectionListsFilesAndTimes) {
  TempDir dir;
  const auto model = two_body_model();
  io::VtkSeriesWriter w(dir.path(), model, 1);
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
  io::VtkSeriesWriter w(dir.path(), model, 1);
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
  io::VtkSeriesWriter w(dir.path(), model, 0);
  w.on_snapshot(snapshot(0, 0.0));
  w.on_finish();
  EXPECT_TRUE(w.files().empty());
  EXPECT_FALSE(fs::exists(dir.path() / "results.pvd"));
}

// ---------------------------------------------------------------- HistoryWriter

TEST(HistoryWriter, HeaderAndOneRowPerSnapshot) {
  TempDir dir;
  {
    io::HistoryWriter w(dir.path());
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
