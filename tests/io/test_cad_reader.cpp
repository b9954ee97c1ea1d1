// io::read_cad and io::check_patch: the shared CAD files against their exact geometry
// (tests/data/cad/README.md), OCCT-written round trips, trimmed/converted/reversed faces, errors.
#include <gtest/gtest.h>

#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakePolygon.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Geom_CylindricalSurface.hxx>
#include <IGESControl_Writer.hxx>
#include <STEPControl_Writer.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColStd_Array2OfReal.hxx>
#include <TColgp_Array2OfPnt.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Wire.hxx>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <gp_Ax2.hxx>
#include <gp_Ax3.hxx>
#include <gp_Circ.hxx>
#include <gp_Pln.hxx>
#include <iostream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "isoflex/geometry/nurbs_surface.hpp"
#include "isoflex/io/cad/cad_checks.hpp"
#include "isoflex/io/cad/cad_reader.hpp"
#include "isoflex/io/cad/occt_messages.hpp"
#include "support/files.hpp"

using namespace isoflex;
using io::CadError;
using io::CadPatch;
using io::read_cad;
using io::Severity;
namespace fs = std::filesystem;

namespace {

const std::string kData = ISOFLEX_SOURCE_DIR "/tests/data/cad/";

fs::path temp_dir(const std::string& name) {
  return test::temp_dir("isoflex_cad_", name);
}

// Control points i + n_u·j and weights of a patch, compared entry by entry to `tol` (absolute).
void expect_points(const geometry::NurbsSurface& s, const std::vector<Vec3>& points,
                   const std::vector<double>& weights, double tol) {
  ASSERT_EQ(s.points.size(), points.size());
  ASSERT_EQ(s.weights.size(), weights.size());
  for (std::size_t k = 0; k < points.size(); ++k) {
    EXPECT_LE((s.points[k] - points[k]).norm(), tol) << "control point " << k;
    EXPECT_NEAR(s.weights[k], weights[k], tol) << "weight " << k;
  }
}

// --- Exact geometry of the shared files (their README, geometry.json) ---------------------------

const double kHalfSqrt2 = 0.70710678118654757;

std::vector<Vec3> cylinder_points() {
  std::vector<Vec3> p;
  for (double z : {0.0, 1.0, 2.0})
    for (auto [x, y] : {std::pair{1.0, 0.0}, {1.0, 1.0}, {0.0, 1.0}}) p.emplace_back(x, y, z);
  return p;
}
std::vector<double> cylinder_weights() {
  std::vector<double> w;
  for (int j = 0; j < 3; ++j) w.insert(w.end(), {1.0, kHalfSqrt2, 1.0});
  return w;
}

// Scordelis–Lo roof split at x = 25: rows j of the cross-section, x_i = x0 + 12.5 i.
std::vector<Vec3> roof_points(double x0) {
  const double ys = 16.069690242163482, zs = 19.151111077974452, zc = 32.635182233306963;
  std::vector<Vec3> p;
  for (auto [y, z] : {std::pair{-ys, zs}, {0.0, zc}, {ys, zs}})
    for (int i = 0; i < 3; ++i) p.emplace_back(x0 + 12.5 * i, y, z);
  return p;
}
std::vector<double> roof_weights() {
  std::vector<double> w(3, 1.0);
  w.insert(w.end(), 3, 0.76604444311897801);
  w.insert(w.end(), 3, 1.0);
  return w;
}

void expect_open_single_element(const geometry::NurbsSurface& s, int p, int q) {
  std::vector<double> ku(p + 1, 0.0), kv(q + 1, 0.0);
  ku.insert(ku.end(), p + 1, 1.0);
  kv.insert(kv.end(), q + 1, 1.0);
  EXPECT_EQ(s.u.degree(), p);
  EXPECT_EQ(s.v.degree(), q);
  EXPECT_EQ(s.u.knots(), ku);
  EXPECT_EQ(s.v.knots(), kv);
}

struct CylinderCase {
  const char* file;
  double tol;  // 9 decimals (IGES), 12 digits (STEP), bit-exact (_fullprec)
};

class QuarterCylinder : public ::testing::TestWithParam<CylinderCase> {};

TEST_P(QuarterCylinder, MatchesTheExactNurbsAndLiesOnTheCylinder) {
  const auto [file, tol] = GetParam();
  const io::CadModel m = read_cad(kData + file);
  ASSERT_EQ(m.patches.size(), 1u);
  const CadPatch& p = m.patches[0];
  EXPECT_EQ(p.name, "patch 0");
  EXPECT_EQ(p.index, 0);
  EXPECT_FALSE(p.trimmed);
  EXPECT_FALSE(p.reversed_orientation);
  EXPECT_FALSE(p.converted);
  EXPECT_EQ(p.surface_type, "B-spline");
  EXPECT_EQ(m.length_unit, "millimetre");
  expect_open_single_element(p.surface, 2, 2);
  EXPECT_EQ(p.surface.n_u(), 3);
  EXPECT_EQ(p.surface.n_v(), 3);
  expect_points(p.surface, cylinder_points(), cylinder_weights(), tol);
  EXPECT_TRUE(p.surface.is_rational());

  // S(u,v) = (cos θ, sin θ, 2v): radius 1 everywhere, normal x_u × x_v outward.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  for (int k = 0; k < 50; ++k) {
    const double u = uni(rng), v = uni(rng);
    const geometry::SurfacePoint s = geometry::evaluate(p.surface, u, v);
    EXPECT_NEAR(std::hypot(s.x.x(), s.x.y()), 1.0, 2 * tol + 1e-15) << u << ", " << v;
    EXPECT_NEAR(s.x.z(), 2 * v, 2 * tol + 1e-15);
    const Vec3 n = s.xu.cross(s.xv);
    EXPECT_GT(n.dot(Vec3(s.x.x(), s.x.y(), 0.0)), 0.0);
  }
  const Vec3 c = geometry::evaluate(p.surface, 0.5, 0.5).x;
  EXPECT_LE((c - Vec3(kHalfSqrt2, kHalfSqrt2, 1.0)).norm(), 2 * tol + 1e-15);
  EXPECT_TRUE(io::check_patch(p).empty());
}

INSTANTIATE_TEST_SUITE_P(
    CadFiles, QuarterCylinder,
    ::testing::Values(CylinderCase{"quarter_cylinder_R1_L2_deg2.igs", 1e-9},
                      CylinderCase{"quarter_cylinder_R1_L2_deg2.stp", 1e-12},
                      CylinderCase{"quarter_cylinder_R1_L2_deg2_fullprec.igs", 0.0},
                      CylinderCase{"quarter_cylinder_R1_L2_deg2_fullprec.stp", 0.0}));

TEST(CadReader, TwoPatchAnglePlateFromIgesAndStep) {
  const std::vector<std::vector<Vec3>> expected = {
      {{0, 0, 0}, {1, 0, 0}, {0, 10, 0}, {1, 10, 0}},
      {{1, 0, 0}, {1, 0, -3}, {1, 10, 0}, {1, 10, -3}}};
  for (const char* file :
       {"l_angle_plate_2patch_L10_b1_b3_deg1.igs", "l_angle_plate_2patch_L10_b1_b3_deg1.stp"}) {
    SCOPED_TRACE(file);
    const io::CadModel m = read_cad(kData + file);
    ASSERT_EQ(m.patches.size(), 2u);
    for (int k = 0; k < 2; ++k) {
      const CadPatch& p = m.patches[static_cast<std::size_t>(k)];
      EXPECT_EQ(p.index, k);
      EXPECT_EQ(p.name, "patch " + std::to_string(k));
      EXPECT_FALSE(p.trimmed);
      EXPECT_FALSE(p.reversed_orientation);
      expect_open_single_element(p.surface, 1, 1);
      expect_points(p.surface, expected[static_cast<std::size_t>(k)], {1, 1, 1, 1}, 0.0);
      EXPECT_FALSE(p.surface.is_rational());
      // Bilinear: one degree finding per direction, nothing else.
      const auto f = io::check_patch(p);
      ASSERT_EQ(f.size(), 2u);
      for (const auto& x : f) {
        EXPECT_EQ(x.severity, Severity::warning);
        EXPECT_NE(x.issue.find("degree 1"), std::string::npos) << x.issue;
        EXPECT_NE(x.fix.find("elevate"), std::string::npos) << x.fix;
      }
    }
    EXPECT_NE(m.patches[0].entity, "");
  }
}

TEST(CadReader, TwoPatchRoofSplitAtX25) {
  struct Case {
    const char* file;
    double tol;
  };
  for (const auto& [file, tol] : {Case{"scordelis_lo_roof_2patch_split_x25.igs", 1e-9},
                                  Case{"scordelis_lo_roof_2patch_split_x25_fullprec.stp", 0.0}}) {
    SCOPED_TRACE(file);
    const io::CadModel m = read_cad(kData + file);
    ASSERT_EQ(m.patches.size(), 2u);
    for (int k = 0; k < 2; ++k) {
      const geometry::NurbsSurface& s = m.patches[static_cast<std::size_t>(k)].surface;
      expect_open_single_element(s, 2, 2);
      // The IGES file holds 9 decimals of values up to 33: relative 1e-9 ⇒ absolute ~1e-8.
      expect_points(s, roof_points(25.0 * k), roof_weights(), tol * 33);
      // On the cylinder y² + z² = 25² (measured error of the exact data: 4e-15).
      for (double u : {0.1, 0.5, 0.9})
        for (double v : {0.0, 0.3, 0.5, 1.0}) {
          const Vec3 x = geometry::evaluate(s, u, v).x;
          EXPECT_NEAR(std::hypot(x.y(), x.z()), 25.0, 25 * (2 * tol + 1e-15));
        }
      EXPECT_TRUE(io::check_patch(m.patches[static_cast<std::size_t>(k)]).empty());
    }
  }
}

TEST(CadReader, ExtensionIsCaseInsensitive) {
  const fs::path d = temp_dir("ext");
  fs::copy_file(kData + "quarter_cylinder_R1_L2_deg2.igs", d / "CYL.IGES");
  fs::copy_file(kData + "quarter_cylinder_R1_L2_deg2.stp", d / "Cyl.Step");
  EXPECT_EQ(read_cad(d / "CYL.IGES").format, io::CadFormat::iges);
  EXPECT_EQ(read_cad(d / "Cyl.Step").format, io::CadFormat::step);
  fs::remove_all(d);
}

TEST(CadReader, NothingIsPrintedOnStdout) {
  // OCCT prints transfer statistics and parse errors on stdout unless read_cad captures them.
  const fs::path d = temp_dir("quiet");
  test::write_text(d / "garbage.stp", "not STEP\n");
  testing::internal::CaptureStdout();
  read_cad(kData + "l_angle_plate_2patch_L10_b1_b3_deg1.igs");
  read_cad(kData + "l_angle_plate_2patch_L10_b1_b3_deg1.stp");
  EXPECT_THROW(read_cad(d / "garbage.stp"), CadError);
  EXPECT_EQ(testing::internal::GetCapturedStdout(), "");
  fs::remove_all(d);
}

// --- Names and labels ----------------------------------------------------------------------------

TEST(CadReader, NamesFromStepFacesAndSurfaces) {
  const fs::path d = temp_dir("names_step");
  std::string text = test::read_text(kData + "l_angle_plate_2patch_L10_b1_b3_deg1.stp");
  // Face #17 gets a name; face #97 has none, but its surface #73 has.
  for (auto [from, to] :
       {std::pair<std::string, std::string>{"#17 = ADVANCED_FACE(''",
                                            "#17 = ADVANCED_FACE('top flange'"},
        {"#73 = B_SPLINE_SURFACE_WITH_KNOTS(''", "#73 = B_SPLINE_SURFACE_WITH_KNOTS('web'"}}) {
    const auto at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
  }
  test::write_text(d / "named.stp", text);
  const io::CadModel m = read_cad(d / "named.stp");
  ASSERT_EQ(m.patches.size(), 2u);
  EXPECT_EQ(m.patches[0].name, "top flange");
  EXPECT_EQ(m.patches[1].name, "web");
  EXPECT_EQ(m.patches[0].entity, "STEP #17");
  EXPECT_EQ(m.patches[1].entity, "STEP #97");
  fs::remove_all(d);
}

TEST(CadReader, NamesFromIgesEntityLabels) {
  const fs::path d = temp_dir("names_iges");
  // The entity label is columns 57–64 of a directory entry's second line: label the 144 of the
  // first patch (D3, second line D0000004) and the 128 of the second (D9, line D0000010).
  std::istringstream in(test::read_text(kData + "l_angle_plate_2patch_L10_b1_b3_deg1.igs"));
  std::string out, line;
  int labelled = 0;
  while (std::getline(in, line)) {
    if (line.size() >= 80 && line.compare(72, 8, "D0000004") == 0) {
      line.replace(56, 8, "  FLANGE");
      ++labelled;
    }
    if (line.size() >= 80 && line.compare(72, 8, "D0000010") == 0) {
      line.replace(56, 8, "     WEB");
      ++labelled;
    }
    out += line + "\n";
  }
  ASSERT_EQ(labelled, 2);
  test::write_text(d / "named.igs", out);
  const io::CadModel m = read_cad(d / "named.igs");
  ASSERT_EQ(m.patches.size(), 2u);
  EXPECT_EQ(m.patches[0].name, "FLANGE");
  EXPECT_EQ(m.patches[1].name, "WEB");
  EXPECT_EQ(m.patches[1].entity, "IGES entity 128 (D9)");
  fs::remove_all(d);
}

// --- Round trips through files written by OCCT ---------------------------------------------------

// A rational surface of degrees (2, 3) on [0, 2] × [0, 1] with interior knots (u: 0.5 and the
// double knot 1.25, a C⁰ line; v: 0.5). Every number is a multiple of 1/8, exact in the 9-decimal
// IGES and the 12-digit STEP formatting, so the round trip must be exact.
opencascade::handle<Geom_BSplineSurface> test_surface() {
  TColStd_Array1OfReal ku(1, 4), kv(1, 3);
  TColStd_Array1OfInteger mu(1, 4), mv(1, 3);
  const double u_knots[] = {0.0, 0.5, 1.25, 2.0};
  const int u_mults[] = {3, 1, 2, 3};
  for (int k = 0; k < 4; ++k) {
    ku(k + 1) = u_knots[k];
    mu(k + 1) = u_mults[k];
  }
  const double v_knots[] = {0.0, 0.5, 1.0};
  const int v_mults[] = {4, 1, 4};
  for (int k = 0; k < 3; ++k) {
    kv(k + 1) = v_knots[k];
    mv(k + 1) = v_mults[k];
  }
  const int nu = 6, nv = 5;  // 9 − 3 and 9 − 4
  TColgp_Array2OfPnt poles(1, nu, 1, nv);
  TColStd_Array2OfReal weights(1, nu, 1, nv);
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      poles(i + 1, j + 1) = gp_Pnt(0.5 * i + 0.125 * j, 0.75 * j, 0.25 * ((i + j) % 3) - 0.5);
      weights(i + 1, j + 1) = 1.0 + 0.125 * ((3 * i + j) % 5);
    }
  return new Geom_BSplineSurface(poles, weights, ku, kv, mu, mv, 2, 3);
}

// The expected NurbsSurface of test_surface(): full knot vectors, i + n_u·j.
geometry::NurbsSurface expected_test_surface(double scale = 1.0) {
  geometry::NurbsSurface s;
  s.u = geometry::KnotVector(2, {0, 0, 0, 0.5, 1.25, 1.25, 2, 2, 2});
  s.v = geometry::KnotVector(3, {0, 0, 0, 0, 0.5, 1, 1, 1, 1});
  for (int j = 0; j < 5; ++j)
    for (int i = 0; i < 6; ++i) {
      s.points.push_back(scale * Vec3(0.5 * i + 0.125 * j, 0.75 * j, 0.25 * ((i + j) % 3) - 0.5));
      s.weights.push_back(1.0 + 0.125 * ((3 * i + j) % 5));
    }
  return s;
}

void write_iges(const TopoDS_Shape& shape, const fs::path& file, const char* unit = "MM") {
  const io::detail::OcctMessageCapture quiet;
  IGESControl_Writer w(unit, 0);
  w.AddShape(shape);
  w.ComputeModel();
  ASSERT_TRUE(w.Write(file.string().c_str()));
}

void write_step(const TopoDS_Shape& shape, const fs::path& file) {
  const io::detail::OcctMessageCapture quiet;
  STEPControl_Writer w;
  ASSERT_EQ(w.Transfer(shape, STEPControl_AsIs), IFSelect_RetDone);
  ASSERT_EQ(w.Write(file.string().c_str()), IFSelect_RetDone);
}

TEST(CadReader, RoundTripOfARationalSurfaceThroughIgesAndStep) {
  const fs::path d = temp_dir("roundtrip");
  const TopoDS_Face face = BRepBuilderAPI_MakeFace(test_surface(), 1e-7);
  write_iges(face, d / "surface.igs");
  write_step(face, d / "surface.stp");
  const geometry::NurbsSurface want = expected_test_surface();
  for (const char* file : {"surface.igs", "surface.stp"}) {
    SCOPED_TRACE(file);
    const io::CadModel m = read_cad(d / file);
    ASSERT_EQ(m.patches.size(), 1u);
    const CadPatch& p = m.patches[0];
    EXPECT_FALSE(p.trimmed);
    EXPECT_FALSE(p.reversed_orientation);
    EXPECT_EQ(p.surface.u.degree(), 2);
    EXPECT_EQ(p.surface.v.degree(), 3);
    EXPECT_EQ(p.surface.u.knots(), want.u.knots());
    EXPECT_EQ(p.surface.v.knots(), want.v.knots());
    EXPECT_EQ(p.surface.n_u(), 6);
    EXPECT_EQ(p.surface.n_v(), 5);
    expect_points(p.surface, want.points, want.weights, 0.0);

    // The only finding: the C⁰ line at the double knot u = 1.25.
    const auto f = io::check_patch(p);
    ASSERT_EQ(f.size(), 1u);
    EXPECT_EQ(f[0].severity, Severity::warning);
    EXPECT_NE(f[0].issue.find("C⁰ line inside the patch at u = 1.25"), std::string::npos)
        << f[0].issue;
  }
  fs::remove_all(d);
}

TEST(CadReader, KeepsTheNumbersOfAFileInMetres) {
  // OCCT's writer scales its millimetres to the file's metres; read_cad must not scale back.
  const fs::path d = temp_dir("metres");
  write_iges(BRepBuilderAPI_MakeFace(test_surface(), 1e-7), d / "metres.igs", "M");
  const io::CadModel m = read_cad(d / "metres.igs");
  EXPECT_EQ(m.length_unit, "metre");
  const geometry::NurbsSurface want = expected_test_surface(1e-3);
  ASSERT_EQ(m.patches.size(), 1u);
  expect_points(m.patches[0].surface, want.points, want.weights, 1e-15);

  // The same for STEP: the shared millimetre file relabelled as metres.
  std::string text = test::read_text(kData + "quarter_cylinder_R1_L2_deg2_fullprec.stp");
  const std::string mm = "SI_UNIT(.MILLI.,.METRE.)";
  ASSERT_NE(text.find(mm), std::string::npos);
  text.replace(text.find(mm), mm.size(), "SI_UNIT($,.METRE.)");
  test::write_text(d / "metres.stp", text);
  const io::CadModel c = read_cad(d / "metres.stp");
  EXPECT_EQ(c.length_unit, "metre");
  expect_points(c.patches.at(0).surface, cylinder_points(), cylinder_weights(), 0.0);
  fs::remove_all(d);
}

TEST(CadReader, TrimmedFaceGivesTheUntrimmedSurface) {
  const fs::path d = temp_dir("trimmed");
  // The face covers [0.25, 1.5] × [0.125, 0.75] of the surface's [0, 2] × [0, 1].
  const TopoDS_Face face = BRepBuilderAPI_MakeFace(test_surface(), 0.25, 1.5, 0.125, 0.75, 1e-7);
  write_iges(face, d / "trimmed.igs");
  write_step(face, d / "trimmed.stp");
  const geometry::NurbsSurface want = expected_test_surface();
  for (const char* file : {"trimmed.igs", "trimmed.stp"}) {
    SCOPED_TRACE(file);
    const io::CadModel m = read_cad(d / file);
    ASSERT_EQ(m.patches.size(), 1u);
    const CadPatch& p = m.patches[0];
    EXPECT_TRUE(p.trimmed);
    EXPECT_EQ(p.surface.u.knots(), want.u.knots());
    EXPECT_EQ(p.surface.v.knots(), want.v.knots());
    expect_points(p.surface, want.points, want.weights, 0.0);
    const auto f = io::check_patch(p);
    ASSERT_FALSE(f.empty());
    EXPECT_EQ(f[0].severity, Severity::warning);
    EXPECT_NE(f[0].issue.find("trimmed face"), std::string::npos);
    EXPECT_NE(f[0].issue.find("untrimmed surface is used"), std::string::npos);
  }
  fs::remove_all(d);
}

TEST(CadReader, PlateWithAHoleIsTrimmedAndConverted) {
  const fs::path d = temp_dir("hole");
  // The square [0, 4]² in z = 0 with a hole of radius 1 at (2, 2): a plane, two boundary loops.
  const TopoDS_Wire outer = BRepBuilderAPI_MakePolygon(gp_Pnt(0, 0, 0), gp_Pnt(4, 0, 0),
                                                       gp_Pnt(4, 4, 0), gp_Pnt(0, 4, 0), true);
  const TopoDS_Edge circle = BRepBuilderAPI_MakeEdge(gp_Circ(gp_Ax2(gp_Pnt(2, 2, 0), gp::DZ()), 1));
  BRepBuilderAPI_MakeFace mf(gp_Pln(gp::XOY()), outer);
  mf.Add(TopoDS::Wire(BRepBuilderAPI_MakeWire(circle).Wire().Reversed()));
  write_step(mf.Face(), d / "hole.stp");
  const io::CadModel m = read_cad(d / "hole.stp");
  ASSERT_EQ(m.patches.size(), 1u);
  const CadPatch& p = m.patches[0];
  EXPECT_TRUE(p.trimmed);
  EXPECT_TRUE(p.converted);
  EXPECT_EQ(p.surface_type, "plane");
  // The untrimmed patch is the plane on the face's parameter bounds: the square itself.
  Vec3 lo = p.surface.points.front(), hi = lo;
  for (const Vec3& x : p.surface.points) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  EXPECT_LE((lo - Vec3(0, 0, 0)).norm(), 1e-12);
  EXPECT_LE((hi - Vec3(4, 4, 0)).norm(), 1e-12);
  fs::remove_all(d);
}

TEST(CadReader, ReversedFaceIsReported) {
  const fs::path d = temp_dir("reversed");
  TopoDS_Face face = BRepBuilderAPI_MakeFace(test_surface(), 1e-7);
  face.Reverse();
  write_step(face, d / "reversed.stp");
  write_iges(face, d / "reversed.igs");

  // STEP keeps the surface and marks the face (ADVANCED_FACE same_sense .F.).
  const io::CadModel m = read_cad(d / "reversed.stp");
  ASSERT_EQ(m.patches.size(), 1u);
  EXPECT_TRUE(m.patches[0].reversed_orientation);
  EXPECT_FALSE(m.patches[0].trimmed);
  EXPECT_EQ(m.patches[0].surface.u.knots(), expected_test_surface().u.knots());
  const auto f = io::check_patch(m.patches[0]);
  const auto it = std::find_if(f.begin(), f.end(), [](const io::Finding& x) {
    return x.issue.find("reversed") != std::string::npos;
  });
  ASSERT_NE(it, f.end());
  EXPECT_EQ(it->severity, Severity::warning);
  EXPECT_NE(it->issue.find("left-handed"), std::string::npos);

  // IGES (entity 144 has no sense flag): OCCT's writer reverses the u direction of the surface
  // instead, so the file's patch is forward and right-handed: u knots mirrored in [0, 2].
  const io::CadModel mi = read_cad(d / "reversed.igs");
  ASSERT_EQ(mi.patches.size(), 1u);
  EXPECT_FALSE(mi.patches[0].reversed_orientation);
  EXPECT_EQ(mi.patches[0].surface.u.knots(),
            (std::vector<double>{0, 0, 0, 0.75, 0.75, 1.5, 2, 2, 2}));
  fs::remove_all(d);
}

TEST(CadReader, AnalyticCylinderIsConvertedExactly) {
  const fs::path d = temp_dir("cylinder");
  const double r = 2.0, half_pi = 1.5707963267948966;
  const opencascade::handle<Geom_Surface> cyl = new Geom_CylindricalSurface(gp_Ax3(gp::XOY()), r);
  write_step(BRepBuilderAPI_MakeFace(cyl, 0.0, half_pi, 0.0, 3.0, 1e-7), d / "cylinder.stp");
  const io::CadModel m = read_cad(d / "cylinder.stp");
  ASSERT_EQ(m.patches.size(), 1u);
  const CadPatch& p = m.patches[0];
  EXPECT_TRUE(p.converted);
  EXPECT_EQ(p.surface_type, "cylinder");
  EXPECT_FALSE(p.trimmed);
  EXPECT_TRUE(p.surface.is_rational());
  double lo_z = 1e300, hi_z = -1e300;
  for (int a = 0; a <= 10; ++a)
    for (int b = 0; b <= 10; ++b) {
      const double u = p.surface.u.front() + (p.surface.u.back() - p.surface.u.front()) * a / 10;
      const double v = p.surface.v.front() + (p.surface.v.back() - p.surface.v.front()) * b / 10;
      const Vec3 x = geometry::evaluate(p.surface, u, v).x;
      EXPECT_NEAR(std::hypot(x.x(), x.y()), r, 1e-12);
      EXPECT_GE(std::min(x.x(), x.y()), -1e-12);
      lo_z = std::min(lo_z, x.z());
      hi_z = std::max(hi_z, x.z());
    }
  EXPECT_NEAR(lo_z, 0.0, 1e-12);
  EXPECT_NEAR(hi_z, 3.0, 1e-12);
  const auto f = io::check_patch(p);
  EXPECT_TRUE(std::any_of(f.begin(), f.end(), [](const io::Finding& x) {
    return x.severity == Severity::info && x.issue.find("cylinder") != std::string::npos;
  }));
  fs::remove_all(d);
}

// --- Checks on hand-made patches ----------------------------------------------------------------

CadPatch patch_of(geometry::NurbsSurface s) {
  CadPatch p;
  p.name = "test";
  p.surface = std::move(s);
  p.surface_type = "B-spline";
  return p;
}

// An open, smooth, biquadratic 3 × 3 patch on the unit square.
geometry::NurbsSurface biquadratic() {
  geometry::NurbsSurface s;
  s.u = geometry::KnotVector(2, {0, 0, 0, 1, 1, 1});
  s.v = s.u;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) s.points.emplace_back(0.5 * i, 0.5 * j, 0.1 * i * j);
  s.weights.assign(9, 1.0);
  return s;
}

bool has(const std::vector<io::Finding>& f, Severity sev, const std::string& text) {
  return std::any_of(f.begin(), f.end(), [&](const io::Finding& x) {
    return x.severity == sev && x.issue.find(text) != std::string::npos && !x.fix.empty();
  });
}

TEST(CadChecks, SmoothOpenBiquadraticPatchHasNoFindings) {
  EXPECT_TRUE(io::check_patch(patch_of(biquadratic())).empty());
}

TEST(CadChecks, NonPositiveWeights) {
  auto s = biquadratic();
  s.weights[4] = 0.0;
  s.weights[5] = -1.0;
  const auto f = io::check_patch(patch_of(s));
  ASSERT_EQ(f.size(), 1u);
  EXPECT_TRUE(has(f, Severity::error, "2 of 9 weights are not positive")) << f[0].issue;
}

TEST(CadChecks, NonOpenKnotVector) {
  auto s = biquadratic();
  s.u = geometry::KnotVector(2, {0, 1, 2, 3, 4, 5});  // 3 functions, domain [2, 3]
  const auto f = io::check_patch(patch_of(s));
  // A note only: a model file's surface clamps the patch (tests/io/test_cad_clamping.cpp).
  EXPECT_TRUE(has(f, Severity::info, "knot vector in u is not open"));
  EXPECT_FALSE(has(f, Severity::info, "knot vector in v is not open"));
  EXPECT_FALSE(has(f, Severity::warning, "not open"));
  const auto it = std::find_if(f.begin(), f.end(), [](const io::Finding& x) {
    return x.issue.find("knot vector in u") != std::string::npos;
  });
  ASSERT_NE(it, f.end());
  EXPECT_NE(it->fix.find("ends of the domain [2, 3] in u"), std::string::npos) << it->fix;
}

TEST(CadChecks, C0AndDiscontinuousLinesSayWhere) {
  auto s = biquadratic();
  // v: double knot at 0.25 (C⁰), triple knot at 0.75 (discontinuous); 9 functions.
  s.v = geometry::KnotVector(2, {0, 0, 0, 0.25, 0.25, 0.75, 0.75, 0.75, 1, 1, 1});
  s.points.clear();
  for (int j = 0; j < 8; ++j)
    for (int i = 0; i < 3; ++i) s.points.emplace_back(0.5 * i, 0.125 * j, 0.0);
  s.weights.assign(24, 1.0);
  const auto f = io::check_patch(patch_of(s));
  EXPECT_TRUE(has(f, Severity::warning, "C⁰ line inside the patch at v = 0.25 "));
  EXPECT_TRUE(has(f, Severity::error, "the patch is split at v = 0.75"));
  EXPECT_EQ(f.size(), 2u);
}

TEST(CadChecks, CollapsedEdge) {
  auto s = biquadratic();
  for (int i = 0; i < 3; ++i) s.points[static_cast<std::size_t>(s.index(i, 2))] = Vec3(0.5, 1, 0);
  const auto f = io::check_patch(patch_of(s));
  ASSERT_EQ(f.size(), 1u);
  EXPECT_TRUE(has(f, Severity::warning, "collapsed edge at v = 1"));
}

// Found by fuzzing (#15): a subnormal domain evaluates to NaN, a domain of 1 at 1e10 keeps 6
// digits of its knot differences, weights of 1e-317 lose theirs in refinement.
TEST(CadChecks, NumbersADoubleCannotCarry) {
  auto domain = [](std::vector<double> knots) {
    auto s = biquadratic();
    s.u = geometry::KnotVector(2, std::move(knots));
    return io::check_patch(patch_of(s));
  };
  const double tiny = 5e-315;
  auto f = domain({0, 0, 0, tiny, tiny, tiny});
  ASSERT_EQ(f.size(), 1u);
  EXPECT_TRUE(has(f, Severity::error, "the parameter domain in u is [0, 5e-315]: too small"))
      << f[0].issue;
  f = domain({1e10, 1e10, 1e10, 1e10 + 1, 1e10 + 1, 1e10 + 1});
  EXPECT_TRUE(has(f, Severity::error, "the parameter domain in u is [1e+10, 1e+10]"));
  EXPECT_TRUE(domain({0, 0, 0, 1e6, 1e6, 1e6}).empty());  // any domain of sound numbers is fine

  auto s = biquadratic();  // a span 1e-9 of the domain
  s.v = geometry::KnotVector(2, {0, 0, 0, 0.5, 0.5 + 1e-9, 1, 1, 1});
  s.points.clear();
  for (int j = 0; j < 5; ++j)
    for (int i = 0; i < 3; ++i) s.points.emplace_back(0.5 * i, 0.25 * j, 0.0);
  s.weights.assign(15, 1.0);
  f = io::check_patch(patch_of(s));
  ASSERT_EQ(f.size(), 1u);
  EXPECT_TRUE(has(f, Severity::warning, "a knot span in v is 1e-09 of the parameter domain"))
      << f[0].issue;

  auto weights = [](double w) {
    auto s = biquadratic();
    s.weights[4] = w;
    return io::check_patch(patch_of(s));
  };
  f = weights(1e-317);
  ASSERT_EQ(f.size(), 1u);
  EXPECT_TRUE(has(f, Severity::error, "weights from 1e-317 to 1: the homogeneous coordinates"))
      << f[0].issue;
  EXPECT_TRUE(has(weights(1e200), Severity::error, "weights from 1 to 1e+200"));
  EXPECT_TRUE(has(weights(1e-9), Severity::warning, "weights from 1e-09 to 1 (ratio 1.0e+09)"));
  EXPECT_TRUE(weights(1e-3).empty());
}

// --- Errors --------------------------------------------------------------------------------------

// what() of the CadError thrown for `file`, checked to be one line naming the file.
std::string error_of(const fs::path& file) {
  try {
    read_cad(file);
  } catch (const CadError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    EXPECT_EQ(what.rfind(file.string() + ": ", 0), 0u) << what;
    EXPECT_EQ(e.file(), file.string());
    return what;
  }
  ADD_FAILURE() << "no CadError for " << file;
  return {};
}

TEST(CadReader, MissingFile) {
  EXPECT_NE(error_of("/no/such/dir/part.igs").find("no such file"), std::string::npos);
}

TEST(CadReader, UnknownExtension) {
  EXPECT_NE(error_of(kData + "README.md").find("unknown extension '.md'"), std::string::npos);
}

TEST(CadReader, MalformedFiles) {
  const fs::path d = temp_dir("malformed");
  test::write_text(d / "garbage.igs", "this is not an IGES file\n");
  test::write_text(d / "garbage.stp", "this is not a STEP file\n");
  const std::string stp = test::read_text(kData + "quarter_cylinder_R1_L2_deg2.stp");
  test::write_text(d / "truncated.stp", stp.substr(0, stp.size() / 2));
  EXPECT_NE(error_of(d / "garbage.igs").find("cannot be read as IGES"), std::string::npos);
  EXPECT_NE(error_of(d / "garbage.stp").find("cannot be read as STEP"), std::string::npos);
  EXPECT_NE(error_of(d / "truncated.stp").find("cannot be read as STEP"), std::string::npos);
  fs::remove_all(d);
}

TEST(CadReader, FileWithoutSurfaces) {
  const fs::path d = temp_dir("nosurface");
  write_step(BRepBuilderAPI_MakeEdge(gp_Pnt(0, 0, 0), gp_Pnt(1, 0, 0)).Edge(), d / "edge.stp");
  EXPECT_NE(error_of(d / "edge.stp").find("no surfaces"), std::string::npos);
  fs::remove_all(d);
}

}  // namespace
