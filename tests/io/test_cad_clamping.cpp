// Unclamped and periodic B-spline surfaces in CAD files (#17). OCCT writes both to STEP and IGES
// with knot vectors that are not open (a periodic surface with the knots of its periodic
// extension); read_cad keeps the file's knots and check_patch notes them (info); a model file's
// surface clamps them (geometry/clamping.hpp): open knot vectors, the same surface as OCCT
// evaluates it, an info finding saying what was converted, and refinement works on it.
#include <gtest/gtest.h>
#include <unistd.h>

#include <BRepBuilderAPI_MakeFace.hxx>
#include <Geom_BSplineSurface.hxx>
#include <IGESControl_Writer.hxx>
#include <STEPControl_Writer.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColStd_Array2OfReal.hxx>
#include <TColgp_Array2OfPnt.hxx>
#include <TopoDS_Face.hxx>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "isoflex/geometry/nurbs_surface.hpp"
#include "isoflex/io/cad/cad_checks.hpp"
#include "isoflex/io/cad/cad_reader.hpp"
#include "isoflex/io/cad/occt_messages.hpp"
#include "isoflex/io/model_reader.hpp"
#include "support/files.hpp"

using namespace isoflex;
namespace fs = std::filesystem;

namespace {

using Surface = opencascade::handle<Geom_BSplineSurface>;

TColStd_Array1OfReal reals(const std::vector<double>& x) {
  TColStd_Array1OfReal a(1, static_cast<int>(x.size()));
  for (std::size_t k = 0; k < x.size(); ++k) a(static_cast<int>(k) + 1) = x[k];
  return a;
}

TColStd_Array1OfInteger integers(const std::vector<int>& x) {
  TColStd_Array1OfInteger a(1, static_cast<int>(x.size()));
  for (std::size_t k = 0; k < x.size(); ++k) a(static_cast<int>(k) + 1) = x[k];
  return a;
}

// Not periodic, but unclamped in u: degree 2 on the uniform knots 0 … 6 (4 control points,
// domain [2, 4]); open biquadratic in v; rational. All numbers are multiples of 1/8, exact in the
// files.
Surface unclamped_surface() {
  TColgp_Array2OfPnt poles(1, 4, 1, 3);
  TColStd_Array2OfReal weights(1, 4, 1, 3);
  for (int i = 1; i <= 4; ++i)
    for (int j = 1; j <= 3; ++j) {
      poles(i, j) = gp_Pnt(i, j, 0.25 * ((i * j) % 3));
      weights(i, j) = 1.0 + 0.125 * ((i + j) % 3);
    }
  return new Geom_BSplineSurface(poles, weights, reals({0, 1, 2, 3, 4, 5, 6}), reals({0, 1}),
                                 integers({1, 1, 1, 1, 1, 1, 1}), integers({3, 3}), 2, 2);
}

// Periodic in u: a closed rational quadratic ring (knots 0 … 4, 4 control points on a square
// about the z axis, weights 1 and 0.75 alternating), open quadratic in v, widening upwards.
Surface periodic_surface() {
  TColgp_Array2OfPnt poles(1, 4, 1, 3);
  TColStd_Array2OfReal weights(1, 4, 1, 3);
  const double corner[4][2] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};
  for (int i = 1; i <= 4; ++i)
    for (int j = 1; j <= 3; ++j) {
      const double r = 1.0 + 0.25 * (j - 1);
      poles(i, j) = gp_Pnt(r * corner[i - 1][0], r * corner[i - 1][1], 0.5 * (j - 1));
      weights(i, j) = i % 2 == 1 ? 1.0 : 0.75;
    }
  return new Geom_BSplineSurface(poles, weights, reals({0, 1, 2, 3, 4}), reals({0, 1}),
                                 integers({1, 1, 1, 1, 1}), integers({3, 3}), 2, 2, Standard_True,
                                 Standard_False);
}

void write_both(const Surface& s, const fs::path& stem) {
  const io::detail::OcctMessageCapture quiet;
  const TopoDS_Face face = BRepBuilderAPI_MakeFace(s, 1e-7);
  STEPControl_Writer step;
  ASSERT_EQ(step.Transfer(face, STEPControl_AsIs), IFSelect_RetDone);
  ASSERT_EQ(step.Write((stem.string() + ".stp").c_str()), IFSelect_RetDone);
  IGESControl_Writer iges("MM", 0);
  iges.AddShape(face);
  iges.ComputeModel();
  ASSERT_TRUE(iges.Write((stem.string() + ".igs").c_str()));
}

// Largest distance between `ours` and OCCT's evaluation of `occt` on a 13 × 13 grid of OCCT's
// parameter bounds (the same parameters: clamping keeps the parametrization).
double distance_to_occt(const geometry::NurbsSurface& ours, const Surface& occt) {
  double u0 = 0, u1 = 0, v0 = 0, v1 = 0;
  occt->Bounds(u0, u1, v0, v1);
  double d = 0.0;
  for (int a = 0; a <= 12; ++a)
    for (int b = 0; b <= 12; ++b) {
      const double u = u0 + (u1 - u0) * a / 12.0, v = v0 + (v1 - v0) * b / 12.0;
      const gp_Pnt p = occt->Value(u, v);
      d = std::max(d, (geometry::evaluate(ours, u, v).x - Vec3(p.X(), p.Y(), p.Z())).norm());
    }
  return d;
}

bool mentions(const std::vector<model::SurfaceFinding>& fs, const std::string& severity,
              const std::string& text) {
  return std::any_of(fs.begin(), fs.end(), [&](const model::SurfaceFinding& f) {
    return f.severity == severity && f.issue.find(text) != std::string::npos;
  });
}

}  // namespace

// What the files hold: the knot vectors as OCCT wrote them, not open; cad-info's check notes it.
TEST(CadClamping, FilesHoldKnotVectorsThatAreNotOpen) {
  const test::TempDir dir(fs::temp_directory_path() /
                          ("isoflex_cad_clamp_files_" + std::to_string(::getpid())));
  write_both(unclamped_surface(), dir.path() / "unclamped");
  write_both(periodic_surface(), dir.path() / "periodic");
  for (const char* file : {"unclamped.stp", "unclamped.igs", "periodic.stp", "periodic.igs"}) {
    SCOPED_TRACE(file);
    const io::CadModel m = io::read_cad(dir.path() / file);
    ASSERT_EQ(m.patches.size(), 1u);
    const io::CadPatch& p = m.patches[0];
    EXPECT_FALSE(p.surface.u.is_open());
    EXPECT_TRUE(p.surface.v.is_open());
    const bool periodic = std::string(file).rfind("periodic", 0) == 0;
    // The file's patch is the surface on its domain (OCCT's bounds), unclamped as it is.
    EXPECT_EQ(p.surface.u.front(), periodic ? 0.0 : 2.0);
    EXPECT_EQ(p.surface.u.back(), 4.0);
    EXPECT_LT(distance_to_occt(p.surface, periodic ? periodic_surface() : unclamped_surface()),
              1e-14);
    const auto findings = io::check_patch(p);
    ASSERT_EQ(findings.size(), 1u);
    EXPECT_EQ(findings[0].severity, io::Severity::info);
    EXPECT_NE(findings[0].issue.find("knot vector in u is not open"), std::string::npos);
    EXPECT_NE(findings[0].fix.find("a model file's surface clamps it exactly"), std::string::npos);
  }
}

// A model file's surface on such a patch is clamped: open knots, the same surface, a note.
TEST(CadClamping, ModelFileSurfaceIsClamped) {
  const test::TempDir dir(fs::temp_directory_path() /
                          ("isoflex_cad_clamp_model_" + std::to_string(::getpid())));
  write_both(unclamped_surface(), dir.path() / "unclamped");
  write_both(periodic_surface(), dir.path() / "periodic");
  std::ofstream(dir.path() / "m.yaml")
      << "bodies: [{name: b, mass: 1, inertia: [1, 1, 1], position: [0, 0, 0]}]\n"
         "surfaces:\n"
         "  - {name: open_step, cad: {file: unclamped.stp}}\n"
         "  - {name: open_iges, cad: {file: unclamped.igs}}\n"
         "  - {name: ring_step, cad: {file: periodic.stp}}\n"
         "  - {name: ring_iges, cad: {file: periodic.igs}}\n"
         "  - name: ring_fine\n"
         "    cad: {file: periodic.stp}\n"
         "    refine: {elevate: [1, 0], knots_per_span: [2, 1]}\n";
  const model::Model m = io::read_model((dir.path() / "m.yaml").string());
  ASSERT_EQ(m.surfaces.size(), 5u);
  double worst = 0.0;
  for (std::size_t k = 0; k < 4; ++k) {
    const model::Surface& s = m.surfaces[k];
    SCOPED_TRACE(s.name);
    const bool periodic = k >= 2;
    EXPECT_TRUE(s.surface.u.is_open());
    EXPECT_TRUE(s.surface.v.is_open());
    // Clamped on the domain, the interior knots kept: [2, 4] with the knot 3, or [0, 4] with 1,
    // 2, 3; as many control points as before.
    EXPECT_EQ(s.surface.u.knots(), periodic ? (std::vector<double>{0, 0, 0, 1, 2, 3, 4, 4, 4})
                                            : (std::vector<double>{2, 2, 2, 3, 4, 4, 4}));
    EXPECT_EQ(s.surface.n_u(), periodic ? 6 : 4);
    const double d =
        distance_to_occt(s.surface, periodic ? periodic_surface() : unclamped_surface());
    EXPECT_LT(d, 1e-14);
    worst = std::max(worst, d);
    // No warning about the knots; the note says what was done.
    EXPECT_FALSE(std::any_of(s.findings.begin(), s.findings.end(),
                             [](const auto& f) { return f.severity != "info"; }));
    ASSERT_EQ(s.findings.size(), 1u);
    EXPECT_EQ(s.findings[0].issue,
              periodic ? "the knot vector in u is not open in the file (end knots not repeated 3 "
                         "times: an unclamped or periodic B-spline); clamped on its domain [0, 4] "
                         "by knot insertion, the same surface and parametrization: 6 → 6 control "
                         "points in u"
                       : "the knot vector in u is not open in the file (end knots not repeated 3 "
                         "times: an unclamped or periodic B-spline); clamped on its domain [2, 4] "
                         "by knot insertion, the same surface and parametrization: 4 → 4 control "
                         "points in u");
    EXPECT_EQ(s.findings[0].fix, "nothing to do");
    if (periodic) {
      // A closed ring: the seam edges u = 0 and u = 4 have the same control points now.
      for (int j = 0; j < s.surface.n_v(); ++j)
        EXPECT_LT((s.surface.points[s.surface.index(0, j)] -
                   s.surface.points[s.surface.index(s.surface.n_u() - 1, j)])
                      .norm(),
                  1e-15);
    }
  }
  // Clamped first, the patch can be elevated: degree 3, 6 + 4 + 2·4 control points in u.
  const model::Surface& fine = m.surfaces[4];
  EXPECT_EQ(fine.surface.degree_u(), 3);
  EXPECT_EQ(fine.surface.n_u(), 18);
  const double d_fine = distance_to_occt(fine.surface, periodic_surface());
  EXPECT_LT(d_fine, 1e-14);
  EXPECT_TRUE(mentions(fine.findings, "info", "clamped on its domain [0, 4]"));
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.2e (refined %.2e)", worst, d_fine);
  RecordProperty("max_distance_to_occt", buf);
}
