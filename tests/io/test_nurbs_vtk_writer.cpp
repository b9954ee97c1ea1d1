// NURBS surfaces as .vtu: rational Bézier cells (VTK_BEZIER_QUADRILATERAL), tessellation and
// control net. The files are parsed back by simple string search and checked against the
// analytic cylinder; the Bernstein polynomials here are the closed form IGA-thesis (4.2), and
// the VTK point order is spelled out as explicit tables (from VTK's documentation of
// vtkHigherOrderQuadrilateral), not taken from the writer.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "isoflex/geometry/nurbs_surface.hpp"
#include "isoflex/io/nurbs_vtk_writer.hpp"
#include "support/files.hpp"
#include "support/vtu.hpp"

namespace fs = std::filesystem;
using namespace isoflex;
using test::data_array;
using test::read_text;

namespace {

std::string sci(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2e", v);
  return buf;
}

// Quarter cylinder, radius R, angle 0 … π/2, height 0 … H, 2 × 2 elements: the 90° arc with
// the knot 1/2 inserted by hand (homogeneous points Pw₀, (Pw₀+Pw₁)/2, (Pw₁+Pw₂)/2, Pw₂, which
// gives the weights 1, (1+c)/2, (1+c)/2, 1 with c = 1/√2, cf. the disc of IGA-thesis §4.1.3.2),
// and a quadratic B-spline with knot 1/2 along the axis.
geometry::NurbsSurface quarter_cylinder(double R, double H) {
  geometry::NurbsSurface s;
  s.u = geometry::KnotVector(2, {0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0});
  s.v = geometry::KnotVector(2, {0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0});
  const double c = std::sqrt(0.5);
  const Vec3 P0(R, 0, 0), P1(R, R, 0), P2(0, R, 0);
  const double wm = 0.5 * (1.0 + c);
  const Vec3 arc[4] = {P0, (P0 + c * P1) / (1.0 + c), (c * P1 + P2) / (1.0 + c), P2};
  const double w[4] = {1.0, wm, wm, 1.0};
  const double z[4] = {0.0, 0.25 * H, 0.75 * H, H};
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) {
      s.points.push_back(arc[i] + Vec3(0, 0, z[j]));
      s.weights.push_back(w[i]);
    }
  return s;
}

double bernstein_closed(int p, int k, double t) {
  double binom = 1.0;
  for (int i = 1; i <= k; ++i) binom = binom * (p - k + i) / i;
  return binom * std::pow(t, k) * std::pow(1.0 - t, p - k);
}

// test::TempDir isoflex_nurbs_vtk_<test>_<address of the object>.
class TempDir : public test::TempDir {
 public:
  TempDir()
      : test::TempDir(fs::temp_directory_path() /
                      (std::string("isoflex_nurbs_vtk_") +
                       ::testing::UnitTest::GetInstance()->current_test_info()->name() + "_" +
                       std::to_string(reinterpret_cast<std::uintptr_t>(this)))) {}
};

// The value of the first attribute key="…".
std::string attribute(const std::string& xml, const std::string& key) {
  const auto at = xml.find(key + "=\"");
  if (at == std::string::npos) return {};
  const auto begin = at + key.size() + 2;
  return xml.substr(begin, xml.find('"', begin) - begin);
}

int count(const std::string& xml, const std::string& what) {
  int n = 0;
  for (auto at = xml.find(what); at != std::string::npos; at = xml.find(what, at + 1)) ++n;
  return n;
}

// VTK order of the points of Bézier quadrilaterals, written out: corners, edges (each in +i or
// +j), interior.
const std::vector<std::pair<int, int>> kOrder22 = {{0, 0}, {2, 0}, {2, 2}, {0, 2}, {1, 0},
                                                   {2, 1}, {1, 2}, {0, 1}, {1, 1}};
const std::vector<std::pair<int, int>> kOrder32 = {{0, 0}, {3, 0}, {3, 2}, {0, 2}, {1, 0}, {2, 0},
                                                   {3, 1}, {1, 2}, {2, 2}, {0, 1}, {1, 1}, {2, 1}};
const std::vector<std::pair<int, int>> kOrder33 = {{0, 0}, {3, 0}, {3, 3}, {0, 3}, {1, 0}, {2, 0},
                                                   {3, 1}, {3, 2}, {1, 3}, {2, 3}, {0, 1}, {0, 2},
                                                   {1, 1}, {2, 1}, {1, 2}, {2, 2}};

TEST(NurbsVtk, VtkPointOrder) {
  for (int n = 0; n < 9; ++n)
    EXPECT_EQ(io::vtk_bezier_quad_index(kOrder22[n].first, kOrder22[n].second, 2, 2), n);
  for (int n = 0; n < 12; ++n)
    EXPECT_EQ(io::vtk_bezier_quad_index(kOrder32[n].first, kOrder32[n].second, 3, 2), n);
  for (int n = 0; n < 16; ++n)
    EXPECT_EQ(io::vtk_bezier_quad_index(kOrder33[n].first, kOrder33[n].second, 3, 3), n);
  // Bilinear: the corners only, counter-clockwise.
  EXPECT_EQ(io::vtk_bezier_quad_index(0, 0, 1, 1), 0);
  EXPECT_EQ(io::vtk_bezier_quad_index(1, 0, 1, 1), 1);
  EXPECT_EQ(io::vtk_bezier_quad_index(1, 1, 1, 1), 2);
  EXPECT_EQ(io::vtk_bezier_quad_index(0, 1, 1, 1), 3);
}

TEST(NurbsVtk, RationalBezierCellsOfQuarterCylinder) {
  const double R = 1.25, H = 0.8;
  const geometry::NurbsSurface s = quarter_cylinder(R, H);
  // Fields per control point: z as a scalar, the position as a vector.
  io::SurfaceField height{"height", 1, {}, io::SurfaceField::Location::control_points};
  io::SurfaceField pos{"position", 3, {}, io::SurfaceField::Location::control_points};
  for (const Vec3& p : s.points) {
    height.values.push_back(p.z());
    pos.values.insert(pos.values.end(), {p.x(), p.y(), p.z()});
  }
  TempDir dir;
  const fs::path file = dir.path() / "cyl.vtu";
  io::write_nurbs_bezier_vtu(file, s, model::VtkFormat::binary, {height, pos});
  const std::string xml = read_text(file);

  ASSERT_EQ(attribute(xml, "NumberOfCells"), "4");
  ASSERT_EQ(attribute(xml, "NumberOfPoints"), "36");
  EXPECT_NE(xml.find("<PointData RationalWeights=\"RationalWeights\">"), std::string::npos);
  EXPECT_NE(xml.find("<CellData HigherOrderDegrees=\"HigherOrderDegrees\">"), std::string::npos);
  EXPECT_EQ(count(xml, "<DataArray"), 9);  // 3 point data, 2 cell data, Points, 3 Cells

  const auto types = data_array(xml, "types");
  ASSERT_EQ(types.size(), 4u);
  for (const double t : types) EXPECT_EQ(t, 77.0);
  const auto degrees = data_array(xml, "HigherOrderDegrees");
  ASSERT_EQ(degrees.size(), 12u);
  for (int c = 0; c < 4; ++c) {
    EXPECT_EQ(degrees[3 * c], 2.0);
    EXPECT_EQ(degrees[3 * c + 1], 2.0);
  }
  const auto offsets = data_array(xml, "offsets");
  ASSERT_EQ(offsets.size(), 4u);
  for (int c = 0; c < 4; ++c) EXPECT_EQ(offsets[c], 9.0 * (c + 1));
  const auto conn = data_array(xml, "connectivity");
  const auto xyz = data_array(xml, "Points");
  const auto w = data_array(xml, "RationalWeights");
  const auto hf = data_array(xml, "height");
  const auto pf = data_array(xml, "position");
  ASSERT_EQ(conn.size(), 36u);
  ASSERT_EQ(xyz.size(), 108u);
  ASSERT_EQ(w.size(), 36u);
  ASSERT_EQ(hf.size(), 36u);
  ASSERT_EQ(pf.size(), 108u);

  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U01(0.0, 1.0);
  double worst_radius = 0.0, worst_field = 0.0;
  for (int c = 0; c < 4; ++c) {
    // Tensor-grid control points of cell c from the VTK order.
    Vec3 P[3][3];
    double W[3][3], F[3][3];
    Vec3 G[3][3];
    for (int n = 0; n < 9; ++n) {
      const int id = static_cast<int>(conn[9 * c + n]);
      const auto [i, j] = kOrder22[n];
      P[i][j] = Vec3(xyz[3 * id], xyz[3 * id + 1], xyz[3 * id + 2]);
      W[i][j] = w[id];
      F[i][j] = hf[id];
      G[i][j] = Vec3(pf[3 * id], pf[3 * id + 1], pf[3 * id + 2]);
    }
    for (int trial = 0; trial < 200; ++trial) {
      const double tu = U01(rng), tv = U01(rng);
      Vec3 num = Vec3::Zero(), gnum = Vec3::Zero();
      double den = 0.0, fnum = 0.0;
      for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i) {
          const double b = bernstein_closed(2, i, tu) * bernstein_closed(2, j, tv) * W[i][j];
          num += b * P[i][j];
          gnum += b * G[i][j];
          fnum += b * F[i][j];
          den += b;
        }
      const Vec3 x = num / den;
      const double radius_err = std::abs(std::hypot(x.x(), x.y()) - R);
      worst_radius = std::max(worst_radius, radius_err);
      EXPECT_LT(radius_err, 1e-14);
      EXPECT_GE(x.z(), -1e-15);
      EXPECT_LE(x.z(), H + 1e-15);
      EXPECT_GE(x.x(), -1e-15);
      EXPECT_GE(x.y(), -1e-15);
      // The cell covers its element: the same point as the NURBS surface at the mapped
      // parameters (cells in element order, ξ fastest, element bounds 0, ½, 1).
      const double xi = 0.5 * ((c % 2) + tu), eta = 0.5 * ((c / 2) + tv);
      EXPECT_LT((x - geometry::evaluate(s, xi, eta).x).norm(), 1e-14);
      // Fields interpolate like the geometry.
      worst_field = std::max(worst_field, std::abs(fnum / den - x.z()));
      EXPECT_NEAR(fnum / den, x.z(), 1e-14);
      EXPECT_LT((gnum / den - x).norm(), 1e-14);
    }
  }
  RecordProperty("worst_radius_error", sci(worst_radius));

  // Fields given per Bézier point are written as given (reordered into VTK order).
  io::SurfaceField cell_id{"cell", 1, {}, io::SurfaceField::Location::bezier_points};
  for (int c = 0; c < 4; ++c)
    for (int k = 0; k < 9; ++k) cell_id.values.push_back(10 * c + k);
  const std::string xml2 = io::nurbs_bezier_vtu(s, model::VtkFormat::binary, {cell_id});
  const auto cid = data_array(xml2, "cell");
  const auto conn2 = data_array(xml2, "connectivity");
  ASSERT_EQ(cid.size(), 36u);
  for (int c = 0; c < 4; ++c)
    for (int n = 0; n < 9; ++n) {
      const auto [i, j] = kOrder22[n];
      EXPECT_EQ(cid[static_cast<int>(conn2[9 * c + n])], 10 * c + i + 3 * j);
    }

  // Wrong sizes are reported.
  io::SurfaceField bad{"bad", 3, {1.0, 2.0}, io::SurfaceField::Location::control_points};
  EXPECT_THROW(io::nurbs_bezier_vtu(s, model::VtkFormat::binary, {bad}), std::invalid_argument);
}

TEST(NurbsVtk, TessellationOfQuarterCylinder) {
  const double R = 1.25, H = 0.8;
  const geometry::NurbsSurface s = quarter_cylinder(R, H);
  const int n = 5;
  io::SampledField angle;
  angle.name = "angle";
  angle.n_components = 1;
  angle.at = [](double, double, const Vec3& x, double* out) { out[0] = std::atan2(x.y(), x.x()); };
  io::SampledField height;
  height.name = "height";
  height.n_components = 1;
  for (const Vec3& p : s.points) height.control_point_values.push_back(p.z());

  TempDir dir;
  const fs::path file = dir.path() / "cyl_tess.vtu";
  io::write_nurbs_tessellated_vtu(file, s, n, model::VtkFormat::binary, {angle, height});
  const std::string xml = read_text(file);
  const int np = (2 * n + 1) * (2 * n + 1), nc = (2 * n) * (2 * n);
  ASSERT_EQ(attribute(xml, "NumberOfPoints"), std::to_string(np));
  ASSERT_EQ(attribute(xml, "NumberOfCells"), std::to_string(nc));
  const auto types = data_array(xml, "types");
  ASSERT_EQ(static_cast<int>(types.size()), nc);
  for (const double t : types) EXPECT_EQ(t, 9.0);
  const auto element = data_array(xml, "element");
  ASSERT_EQ(static_cast<int>(element.size()), nc);
  EXPECT_EQ(element.front(), 0.0);
  EXPECT_EQ(element.back(), 3.0);
  const auto xyz = data_array(xml, "Points");
  const auto par = data_array(xml, "parameters");
  const auto ang = data_array(xml, "angle");
  const auto hgt = data_array(xml, "height");
  ASSERT_EQ(static_cast<int>(xyz.size()), 3 * np);
  ASSERT_EQ(static_cast<int>(par.size()), 2 * np);
  ASSERT_EQ(static_cast<int>(ang.size()), np);
  ASSERT_EQ(static_cast<int>(hgt.size()), np);
  double worst = 0.0;
  for (int k = 0; k < np; ++k) {
    const Vec3 x(xyz[3 * k], xyz[3 * k + 1], xyz[3 * k + 2]);
    const double err = std::abs(std::hypot(x.x(), x.y()) - R);
    worst = std::max(worst, err);
    EXPECT_LT(err, 1e-14);
    EXPECT_NEAR(ang[k], std::atan2(x.y(), x.x()), 1e-15);
    EXPECT_NEAR(hgt[k], x.z(), 1e-14);  // interpolated with the basis ↔ evaluated position
  }
  // Corners of the parameter domain: (R, 0, 0) and (0, R, H).
  EXPECT_NEAR(xyz[0], R, 1e-15);
  EXPECT_NEAR(xyz[1], 0.0, 1e-15);
  EXPECT_NEAR(xyz[3 * (np - 1) + 0], 0.0, 1e-15);
  EXPECT_NEAR(xyz[3 * (np - 1) + 1], R, 1e-15);
  EXPECT_NEAR(xyz[3 * (np - 1) + 2], H, 1e-15);
  EXPECT_EQ(par[2 * (np - 1)], 1.0);
  EXPECT_EQ(par[2 * (np - 1) + 1], 1.0);
  RecordProperty("worst_radius_error", sci(worst));
  EXPECT_THROW(io::nurbs_tessellated_vtu(s, 0, model::VtkFormat::binary), std::invalid_argument);
}

TEST(NurbsVtk, ControlNet) {
  const geometry::NurbsSurface s = quarter_cylinder(1.0, 1.0);
  const std::string xml = io::nurbs_control_net_vtu(s, model::VtkFormat::binary);
  ASSERT_EQ(attribute(xml, "NumberOfPoints"), "16");
  ASSERT_EQ(attribute(xml, "NumberOfCells"), "24");  // 4 rows × 3 + 4 columns × 3
  const auto types = data_array(xml, "types");
  for (const double t : types) EXPECT_EQ(t, 3.0);
  const auto conn = data_array(xml, "connectivity");
  const auto dir = data_array(xml, "direction");
  ASSERT_EQ(conn.size(), 48u);
  for (int c = 0; c < 24; ++c) {
    const int a = static_cast<int>(conn[2 * c]), b = static_cast<int>(conn[2 * c + 1]);
    EXPECT_EQ(b - a, dir[c] == 0.0 ? 1 : 4);  // neighbours along ξ (index +1) or η (+n_u)
  }
  const auto w = data_array(xml, "weight");
  ASSERT_EQ(w.size(), 16u);
  EXPECT_NEAR(w[1], 0.5 * (1.0 + std::sqrt(0.5)), 1e-16);
}

// The three views in binary and in ascii hold the same arrays bit for bit (the ascii numbers
// with the digits that read back to the same double).
TEST(NurbsVtk, BinaryAndAsciiHoldTheSameArraysBitForBit) {
  const geometry::NurbsSurface s = quarter_cylinder(1.25, 0.8);
  io::SurfaceField height{"height", 1, {}, io::SurfaceField::Location::control_points};
  for (const Vec3& p : s.points) height.values.push_back(p.z() / 3);
  io::SampledField angle;
  angle.name = "angle";
  angle.at = [](double, double, const Vec3& x, double* out) { out[0] = std::atan2(x.y(), x.x()); };
  for (const auto& [binary, ascii] :
       {std::pair{io::nurbs_bezier_vtu(s, model::VtkFormat::binary, {height}),
                  io::nurbs_bezier_vtu(s, model::VtkFormat::ascii, {height})},
        std::pair{io::nurbs_tessellated_vtu(s, 3, model::VtkFormat::binary, {angle}),
                  io::nurbs_tessellated_vtu(s, 3, model::VtkFormat::ascii, {angle})},
        std::pair{io::nurbs_control_net_vtu(s, model::VtkFormat::binary),
                  io::nurbs_control_net_vtu(s, model::VtkFormat::ascii)}}) {
    EXPECT_EQ(test::xml_error(binary), "");
    EXPECT_EQ(test::xml_error(ascii), "");
    EXPECT_EQ(count(binary, "format=\"appended\""), count(ascii, "format=\"ascii\""));
    EXPECT_EQ(count(binary, "format=\"ascii\""), 0);
    EXPECT_EQ(test::data_arrays_difference(binary, ascii), "");
  }
}

}  // namespace
