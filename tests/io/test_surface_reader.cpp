// The `surfaces` list of model files (io/surface_reader.cpp): CAD patches and built-in shapes,
// refinement and placement, the suitability findings, and every error with its located message.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <numbers>
#include <string>
#include <string_view>

#include "isoflex/geometry/builders.hpp"
#include "isoflex/io/cad/cad_reader.hpp"
#include "isoflex/io/model_error.hpp"
#include "isoflex/io/model_reader.hpp"
#include "support/files.hpp"
#include "support/model_errors.hpp"

using namespace isoflex;
using io::ModelError;
using io::read_model;
using io::read_model_string;
using test::error_of;
namespace fs = std::filesystem;

namespace {

const std::string kData = ISOFLEX_SOURCE_DIR "/tests/data/cad/";
const std::string kCylinder = kData + "quarter_cylinder_R1_L2_deg2_fullprec.stp";  // 1 patch
const std::string kPlate = kData + "l_angle_plate_2patch_L10_b1_b3_deg1.igs";      // 2 patches

// A valid body (lines 1-5), then `surfaces:` (line 6), then `more` from line 7.
std::string with_surfaces(std::initializer_list<std::string_view> more) {
  std::string s =
      "bodies:\n  - name: top\n    mass: 1\n    inertia: [1, 1, 1]\n    position: [0, 0, 0]\n"
      "surfaces:\n";
  for (const auto l : more) s += std::string(l) + '\n';
  return s;
}

fs::path temp_dir(const std::string& name) {
  return test::temp_dir("isoflex_surf_", name);
}

// Largest distance between a and b at a 7 × 7 grid of parameters of their (common) domain.
double max_distance(const geometry::NurbsSurface& a, const geometry::NurbsSurface& b) {
  double d = 0.0;
  for (int i = 0; i <= 6; ++i)
    for (int j = 0; j <= 6; ++j) {
      const double xi = a.u.front() + (a.u.back() - a.u.front()) * i / 6.0;
      const double eta = a.v.front() + (a.v.back() - a.v.front()) * j / 6.0;
      d = std::max(d, (geometry::evaluate(a, xi, eta).x - geometry::evaluate(b, xi, eta).x).norm());
    }
  return d;
}

}  // namespace

// A CAD patch named relative to the model file's directory; the geometry is the file's patch.
TEST(SurfaceReader, CadPatchRelativeToTheModelFile) {
  const fs::path d = temp_dir("cad");
  fs::create_directories(d / "cad");
  fs::copy_file(kCylinder, d / "cad" / "cyl.stp");
  std::ofstream(d / "m.yaml") << with_surfaces({
      "  - name: roof",                                         // 7
      "    cad: {file: cad/cyl.stp, patch: 0}",                 // 8
      "  - name: fine",                                         // 9
      "    cad: {file: cad/cyl.stp}",                           // 10: the only patch
      "    refine: {elevate: [1, 0], knots_per_span: [1, 2]}",  // 11
  });
  const model::Model m = read_model((d / "m.yaml").string());
  ASSERT_EQ(m.surfaces.size(), 2u);

  const model::Surface& s = m.surfaces[0];
  EXPECT_EQ(s.name, "roof");
  EXPECT_EQ(s.kind, model::SurfaceSourceKind::cad);
  EXPECT_EQ(s.cad_file, "cad/cyl.stp");
  EXPECT_EQ(fs::path(s.cad_path), d / "cad/cyl.stp");
  EXPECT_EQ(s.cad_patch, 0);
  EXPECT_EQ(s.cad_patch_name, "patch 0");
  EXPECT_FALSE(s.trimmed);
  EXPECT_FALSE(s.reversed_orientation);
  EXPECT_EQ(s.source.file, (d / "m.yaml").string());
  EXPECT_EQ(s.source.line, 7);
  EXPECT_TRUE(s.findings.empty());  // biquadratic, untrimmed: fit as it is
  const geometry::NurbsSurface file = io::read_cad(kCylinder).patches[0].surface;
  EXPECT_EQ(s.surface.u.knots(), file.u.knots());
  EXPECT_EQ(s.surface.v.knots(), file.v.knots());
  EXPECT_EQ(s.surface.points, file.points);  // bit for bit
  EXPECT_EQ(s.surface.weights, file.weights);
  EXPECT_EQ(s.element_count(), 1);

  // k-refinement: degree 3 x 2; u: 4 points + 1 knot, v: 3 points + 2 knots.
  const model::Surface& f = m.surfaces[1];
  EXPECT_EQ(f.cad_patch, 0);
  EXPECT_EQ(f.refine.elevate, (std::array<int, 2>{1, 0}));
  EXPECT_EQ(f.refine.knots_per_span, (std::array<int, 2>{1, 2}));
  EXPECT_EQ(f.surface.degree_u(), 3);
  EXPECT_EQ(f.surface.degree_v(), 2);
  EXPECT_EQ(f.surface.n_u(), 5);
  EXPECT_EQ(f.surface.n_v(), 5);
  EXPECT_EQ(f.element_count(), 2 * 3);
  EXPECT_LT(max_distance(f.surface, file), 1e-14);
  for (double xi : {0.1, 0.5, 0.77})  // still the quarter cylinder of radius 1
    EXPECT_NEAR(geometry::evaluate(f.surface, xi, 0.3).x.head<2>().norm(), 1.0, 1e-14);
  fs::remove_all(d);
}

// Patches by name and by index; the CAD checks' warnings on the final geometry.
TEST(SurfaceReader, CadPatchByNameAndFindings) {
  const model::Model m =
      read_model_string(with_surfaces({
                            "  - name: web",
                            "    cad: {file: \"" + kPlate + "\", patch: \"patch 1\"}",
                            "  - name: flange",
                            "    cad: {file: \"" + kPlate + "\", patch: 0}",
                            "    refine: {elevate: [1, 1]}",
                        }),
                        "m.yaml");
  ASSERT_EQ(m.surfaces.size(), 2u);
  EXPECT_EQ(m.surfaces[0].cad_patch, 1);
  EXPECT_EQ(m.surfaces[0].cad_patch_name, "patch 1");
  EXPECT_EQ(m.surfaces[0].surface.points.front(), Vec3(1, 0, 0));
  // Bilinear as read: a degree warning per direction.
  ASSERT_EQ(m.surfaces[0].findings.size(), 2u);
  for (const auto& f : m.surfaces[0].findings) {
    EXPECT_EQ(f.severity, "warning");
    EXPECT_NE(f.issue.find("degree 1"), std::string::npos) << f.issue;
    EXPECT_NE(f.fix.find("elevate"), std::string::npos) << f.fix;
  }
  // Elevated to degree 2 in the model file: nothing left to report.
  EXPECT_EQ(m.surfaces[1].cad_patch, 0);
  EXPECT_EQ(m.surfaces[1].surface.degree_u(), 2);
  EXPECT_EQ(m.surfaces[1].surface.points.size(), 9u);
  EXPECT_TRUE(m.surfaces[1].findings.empty());
}

TEST(SurfaceReader, ReversedStepFaceIsFlaggedAndWarned) {
  const fs::path d = temp_dir("reversed");
  std::string text = test::read_text(kCylinder);
  const std::string from = "#17 = ADVANCED_FACE('',(#18),#32,.T.);";
  ASSERT_NE(text.find(from), std::string::npos);
  text.replace(text.find(from), from.size(), "#17 = ADVANCED_FACE('',(#18),#32,.F.);");
  std::ofstream(d / "rev.stp") << text;
  std::ofstream(d / "m.yaml") << with_surfaces({"  - name: r", "    cad: {file: rev.stp}"});
  const model::Model m = read_model((d / "m.yaml").string());
  ASSERT_EQ(m.surfaces.size(), 1u);
  EXPECT_TRUE(m.surfaces[0].reversed_orientation);
  ASSERT_EQ(m.surfaces[0].findings.size(), 1u);
  EXPECT_EQ(m.surfaces[0].findings[0].severity, "warning");
  EXPECT_NE(m.surfaces[0].findings[0].issue.find("reversed"), std::string::npos);
  fs::remove_all(d);
}

// Built-in shapes with k-refinement keep their geometry; counts follow elevation and insertion.
TEST(SurfaceReader, BuiltinShapesAndRefinement) {
  const model::Model m = read_model_string(
      with_surfaces({
          "  - name: plate",                                        // 7
          "    builtin: {type: rectangle, size: [2, 1]}",           // 8
          "    refine: {elevate: [1, 1], knots_per_span: [3, 1]}",  // 9
          "  - name: shell",                                        // 10
          "    builtin: {type: cylinder_sector, radius: 1, length: 2, angle: 120}",
          "    refine: {elevate: [1, 1], knots_per_span: [2, 2]}",
          "  - name: cap",
          "    builtin: {type: sphere_sector, radius: 3, azimuth: 90, lat_from: -30, lat_to: 60}",
          "  - name: dome",
          "    builtin: {type: hemisphere, radius: 2}",
          "  - name: lid",
          "    builtin: {type: disc, radius: 0.5}",
          "    refine: {knots_per_span: [4, 4]}",
          "  - name: skew",
          "    builtin: {type: rectangle, corner: [1, 1, 1], edge_u: [1, 0, 0], edge_v: [1, 1, 0]}",
      }),
      "m.yaml");
  ASSERT_EQ(m.surfaces.size(), 6u);

  const model::Surface& plate = m.surfaces[0];
  EXPECT_EQ(plate.kind, model::SurfaceSourceKind::builtin);
  EXPECT_EQ(plate.builtin_type, "rectangle");
  EXPECT_EQ(plate.source.line, 7);
  EXPECT_EQ(plate.surface.degree_u(), 2);
  EXPECT_EQ(plate.surface.degree_v(), 2);
  EXPECT_EQ(plate.surface.n_u(), 3 + 3);  // 2 → 3 by elevation, + 3 knots in the one span
  EXPECT_EQ(plate.surface.n_v(), 3 + 1);
  EXPECT_EQ(plate.element_count(), 4 * 2);
  EXPECT_LT(max_distance(plate.surface, geometry::planar_rectangle(2, 1)), 1e-15);
  EXPECT_TRUE(plate.findings.empty());

  // 120°: two arc segments joined by a double knot (a C⁰ line of the basis).
  const model::Surface& shell = m.surfaces[1];
  const geometry::NurbsSurface exact = geometry::cylinder_sector(1, 2, 2 * std::numbers::pi / 3);
  EXPECT_EQ(exact.n_u(), 5);
  EXPECT_EQ(shell.surface.degree_u(), 3);
  EXPECT_EQ(shell.surface.n_u(), 5 + 2 + 2 * 2);  // elevation: +1 per distinct knot but one
  EXPECT_EQ(shell.surface.n_v(), 3 + 2);
  EXPECT_EQ(shell.element_count(), 6 * 3);
  EXPECT_LT(max_distance(shell.surface, exact), 1e-14);
  for (double xi : {0.05, 0.4, 0.5, 0.93})
    EXPECT_NEAR(geometry::evaluate(shell.surface, xi, 0.6).x.head<2>().norm(), 1.0, 1e-14);
  ASSERT_EQ(shell.findings.size(), 1u);
  EXPECT_NE(shell.findings[0].issue.find("C⁰ line inside the patch at u = 0.5"), std::string::npos)
      << shell.findings[0].issue;

  const model::Surface& cap = m.surfaces[2];
  EXPECT_LT(max_distance(cap.surface,
                         geometry::sphere_sector(3, std::numbers::pi / 2, -std::numbers::pi / 6,
                                                 std::numbers::pi / 3)),
            1e-15);
  EXPECT_NEAR(geometry::evaluate(cap.surface, 0.3, 0.7).x.norm(), 3.0, 1e-14);

  const model::Surface& dome = m.surfaces[3];
  EXPECT_EQ(dome.surface.points, geometry::hemisphere(2).points);
  ASSERT_FALSE(dome.findings.empty());  // the pole is a collapsed edge
  EXPECT_NE(dome.findings.back().issue.find("collapsed edge"), std::string::npos);

  const model::Surface& lid = m.surfaces[4];
  EXPECT_EQ(lid.surface.n_u(), 7);
  EXPECT_EQ(lid.element_count(), 25);
  EXPECT_LT(max_distance(lid.surface, geometry::disc(0.5)), 1e-15);

  const model::Surface& skew = m.surfaces[5];
  EXPECT_EQ(skew.surface.points.back(), Vec3(3, 2, 1));
  // Degree 1 in both directions, unrefined: the two degree warnings.
  EXPECT_EQ(skew.findings.size(), 2u);
}

// The closed shapes: cylinder_sector beyond 180°, cylinder, annulus (angle 360 by default),
// spherical_cap; their findings name the C⁰ lines between the 90° segments and the pole.
TEST(SurfaceReader, ClosedBuiltinShapes) {
  const model::Model m = read_model_string(
      with_surfaces({
          "  - name: three_quarters",
          "    builtin: {type: cylinder_sector, radius: 1, length: 2, angle: 270}",
          "  - name: tube",
          "    builtin: {type: cylinder, radius: 1, length: 2}",
          "  - name: slit_plate",  // Sze et al. 2004: inner radius 6, outer radius 10
          "    builtin: {type: annulus, inner_radius: 6, outer_radius: 10}",
          "    refine: {elevate: [0, 1]}",
          "  - name: quarter_ring",
          "    builtin: {type: annulus, inner_radius: 1, outer_radius: 3, angle: 90}",
          "  - name: cap",
          "    builtin: {type: spherical_cap, radius: 2, angle: 60}",
      }),
      "m.yaml");
  ASSERT_EQ(m.surfaces.size(), 5u);
  constexpr double pi = std::numbers::pi;

  const model::Surface& tq = m.surfaces[0];
  EXPECT_EQ(tq.surface.points, geometry::cylinder_sector(1, 2, 1.5 * pi).points);
  // Unrefined: degree 1 along the axis, and the double knots between the 90° segments.
  ASSERT_EQ(tq.findings.size(), 2u);
  EXPECT_NE(tq.findings[0].issue.find("C⁰ lines inside the patch at u = 0.333333, 0.666667"),
            std::string::npos)
      << tq.findings[0].issue;
  EXPECT_NE(tq.findings[1].issue.find("degree 1 in v"), std::string::npos);

  const model::Surface& tube = m.surfaces[1];
  EXPECT_EQ(tube.builtin_type, "cylinder");
  EXPECT_EQ(tube.surface.points, geometry::cylinder(1, 2).points);
  EXPECT_EQ(tube.surface.n_u(), 9);
  ASSERT_EQ(tube.findings.size(), 2u);
  EXPECT_NE(tube.findings[0].issue.find("C⁰ lines inside the patch at u = 0.25, 0.5, 0.75"),
            std::string::npos)
      << tube.findings[0].issue;

  const model::Surface& plate = m.surfaces[2];
  EXPECT_EQ(plate.builtin_type, "annulus");
  const geometry::NurbsSurface ring = geometry::annulus(6, 10, 2 * pi);
  EXPECT_EQ(plate.surface.degree_v(), 2);
  EXPECT_LT(max_distance(plate.surface, ring), 1e-14);
  EXPECT_EQ(plate.surface.points.front(), Vec3(10, 0, 0));  // ξ = 0, η = 0: outer radius on +x
  EXPECT_EQ(plate.surface.points[plate.surface.index(8, 0)], Vec3(10, 0, 0));  // the slit
  ASSERT_EQ(plate.findings.size(), 1u);  // elevated in v: only the C⁰ lines in u
  EXPECT_NE(plate.findings[0].issue.find("at u = 0.25, 0.5, 0.75"), std::string::npos);

  const model::Surface& quarter = m.surfaces[3];
  EXPECT_EQ(quarter.surface.points, geometry::annulus(1, 3, pi / 2).points);
  ASSERT_EQ(quarter.findings.size(), 1u);  // linear in v: the degree warning
  EXPECT_NE(quarter.findings[0].issue.find("degree 1 in v"), std::string::npos);

  const model::Surface& cap = m.surfaces[4];
  EXPECT_LT(max_distance(cap.surface, geometry::spherical_cap(2, pi / 3)), 1e-15);
  EXPECT_NEAR(geometry::evaluate(cap.surface, 0.3, 0.0).x.z(), 1.0, 1e-14);  // 2 cos 60°
  // The azimuth's C⁰ lines and the pole (the meridian of 60° is one segment).
  ASSERT_EQ(cap.findings.size(), 2u);
  EXPECT_NE(cap.findings[0].issue.find("C⁰ lines inside the patch at u = 0.25, 0.5, 0.75"),
            std::string::npos)
      << cap.findings[0].issue;
  EXPECT_NE(cap.findings[1].issue.find("collapsed edge at v = 1"), std::string::npos)
      << cap.findings[1].issue;
}

TEST(SurfaceReader, Placement) {
  const model::Model m = read_model_string(
      with_surfaces({
          "  - name: wall",
          "    builtin: {type: rectangle, size: [2, 1]}",
          "    placement:",
          "      origin: [0, 0, 5]",
          "      orientation: [[0, 1, 0], [0, 0, 1], [1, 0, 0]]  # local x → y, y → z",
      }),
      "m.yaml");
  const model::Surface& s = m.surfaces[0];
  EXPECT_EQ(s.origin, Vec3(0, 0, 5));
  EXPECT_EQ(s.surface.points[0], Vec3(0, 0, 5));
  EXPECT_EQ(s.surface.points[1], Vec3(0, 2, 5));
  EXPECT_EQ(s.surface.points[2], Vec3(0, 0, 6));
  EXPECT_EQ(s.surface.points[3], Vec3(0, 2, 6));
}

TEST(SurfaceReader, NoSurfaces) {
  EXPECT_TRUE(read_model_string(with_surfaces({}), "m.yaml").surfaces.empty());
  EXPECT_TRUE(read_model_string(with_surfaces({"  []"}), "m.yaml").surfaces.empty());
}

TEST(SurfaceReader, CadErrors) {
  const std::string plate = "\"" + kPlate + "\"";
  // Missing file, relative to the model file's directory ("m.yaml": the working directory).
  EXPECT_EQ(error_of(with_surfaces({"  - name: s", "    cad: {file: nope.igs, patch: 0}"})),
            "m.yaml:8: surfaces[0].cad.file: cannot read CAD file \"nope.igs\": no such file");
  EXPECT_EQ(error_of(with_surfaces({"  - name: s", "    cad: {file: roof.dxf}"})),
            "m.yaml:8: surfaces[0].cad.file: cannot read CAD file \"roof.dxf\": no such file");
  EXPECT_EQ(error_of(with_surfaces({"  - name: s", "    cad: {file: \"\"}"})),
            "m.yaml:8: surfaces[0].cad.file: must not be empty");
  EXPECT_EQ(error_of(with_surfaces({"  - name: s", "    cad: {patch: 0}"})),
            "m.yaml:8: surfaces[0].cad.file: missing required key");
  // Patches.
  EXPECT_EQ(error_of(with_surfaces(
                {"  - name: s", "    cad:", "      file: " + plate, "      patch: 2"})),
            "m.yaml:10: surfaces[0].cad.patch: patch 2 out of range: \"" + kPlate +
                "\" holds 2 patches (0 … 1)");
  EXPECT_EQ(error_of(with_surfaces({"  - name: s", "    cad: {file: " + plate + ", patch: -1}"})),
            "m.yaml:8: surfaces[0].cad.patch: must be >= 0, got -1");
  EXPECT_EQ(error_of(with_surfaces({"  - name: s", "    cad: {file: " + plate + ", patch: web}"})),
            "m.yaml:8: surfaces[0].cad.patch: no patch named \"web\" in \"" + kPlate +
                "\" (its patches: 0 \"patch 0\", 1 \"patch 1\")");
  EXPECT_EQ(
      error_of(with_surfaces({"  - name: s", "    cad: {file: " + plate + ", patch: \"1\"}"})),
      "m.yaml:8: surfaces[0].cad.patch: no patch named \"1\" in \"" + kPlate +
          "\" (its patches: 0 \"patch 0\", 1 \"patch 1\")");
  EXPECT_EQ(error_of(with_surfaces({"  - name: s", "    cad: {file: " + plate + ", patch: 0.5}"})),
            "m.yaml:8: surfaces[0].cad.patch: expected a patch index (an integer >= 0) or a patch "
            "name (quote a name that looks like a number)");
  EXPECT_EQ(error_of(with_surfaces({"  - name: s", "    cad: {file: " + plate + "}"})),
            "m.yaml:8: surfaces[0].cad.patch: missing required key: \"" + kPlate +
                "\" holds 2 patches (0 … 1); name one by index or name");
  EXPECT_EQ(error_of(with_surfaces({"  - name: s", "    cad: {file: " + plate + ", layer: 1}"})),
            "m.yaml:8: surfaces[0].cad.layer: unknown key (valid keys: file, patch)");
}

TEST(SurfaceReader, MalformedCadFiles) {
  const fs::path d = temp_dir("malformed");
  std::ofstream(d / "junk.stp") << "this is not STEP\n";
  std::ofstream(d / "roof.dxf") << "0\nSECTION\n";
  std::ofstream(d / "m.yaml") << with_surfaces({"  - name: a", "    cad: {file: junk.stp}"});
  std::ofstream(d / "n.yaml") << with_surfaces({"  - name: b", "    cad: {file: roof.dxf}"});
  for (const auto& [model, prefix] :
       {std::pair<std::string, std::string>{
            "m.yaml", ":8: surfaces[0].cad.file: cannot read CAD file \"" +
                          (d / "junk.stp").string() + "\": cannot be read as STEP: "},
        {"n.yaml", ":8: surfaces[0].cad.file: cannot read CAD file \"" + (d / "roof.dxf").string() +
                       "\": unknown extension '.dxf' (expected .igs, .iges, .stp or .step)"}}) {
    const std::string path = (d / model).string();
    std::string what = "(no error)";
    try {
      read_model(path);
    } catch (const ModelError& e) {
      what = e.what();
    }
    EXPECT_EQ(what.rfind(path + prefix, 0), 0u) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
  fs::remove_all(d);
}

TEST(SurfaceReader, EntryErrors) {
  EXPECT_EQ(error_of(with_surfaces(
                {"  - name: s", "    builtin: {type: disc, radius: 1}", "    colour: red"})),
            "m.yaml:9: surfaces[0].colour: unknown key (valid keys: name, cad, builtin, refine, "
            "placement)");
  EXPECT_EQ(error_of(with_surfaces({"  - builtin: {type: disc, radius: 1}"})),
            "m.yaml:7: surfaces[0].name: missing required key");
  EXPECT_EQ(error_of(with_surfaces({"  - name:", "    builtin: {type: disc, radius: 1}"})),
            "m.yaml:7: surfaces[0].name: expected a string");
  EXPECT_EQ(error_of(with_surfaces({"  - name: \"\"", "    builtin: {type: disc, radius: 1}"})),
            "m.yaml:7: surfaces[0].name: must not be empty");
  EXPECT_EQ(error_of(with_surfaces({"  - name: s", "    builtin: {type: disc, radius: 1}",
                                    "  - name: s", "    builtin: {type: disc, radius: 2}"})),
            "m.yaml:9: surfaces[1].name: duplicate surface name \"s\" (first at line 7)");
  EXPECT_EQ(error_of(with_surfaces({"  - name: s"})),
            "m.yaml:7: surfaces[0]: one of cad and builtin is required");
  EXPECT_EQ(error_of(with_surfaces(
                {"  - name: s", "    cad: {file: a.igs}", "    builtin: {type: disc, radius: 1}"})),
            "m.yaml:9: surfaces[0].builtin: give either cad or builtin, not both");
  EXPECT_EQ(error_of(with_surfaces(
                {"  - name: s", "    builtin: {type: disc, radius: 1}", "    name: t"})),
            "m.yaml:9: surfaces[0].name: duplicate key (first at line 7)");
  EXPECT_EQ(error_of(with_surfaces({"  name: s"})), "m.yaml:7: surfaces: expected a list");
  EXPECT_EQ(error_of(with_surfaces({"  - plate"})),
            "m.yaml:7: surfaces[0]: expected a mapping of keys");
}

TEST(SurfaceReader, BuiltinErrors) {
  auto builtin = [](std::string_view b) {
    return error_of(with_surfaces({"  - name: s", "    builtin: " + std::string(b)}));
  };
  EXPECT_EQ(builtin("{type: cone, radius: 1}"),
            "m.yaml:8: surfaces[0].builtin.type: unknown builtin type \"cone\" (valid: rectangle, "
            "cylinder_sector, cylinder, annulus, sphere_sector, spherical_cap, hemisphere, disc)");
  EXPECT_EQ(builtin("{radius: 1}"), "m.yaml:8: surfaces[0].builtin.type: missing required key");
  EXPECT_EQ(builtin("{type: disc, radius: 1, height: 2}"),
            "m.yaml:8: surfaces[0].builtin.height: unknown key (valid keys: type, radius)");
  EXPECT_EQ(builtin("{type: disc}"), "m.yaml:8: surfaces[0].builtin.radius: missing required key");
  EXPECT_EQ(builtin("{type: hemisphere, radius: -1}"),
            "m.yaml:8: surfaces[0].builtin.radius: must be > 0, got -1");
  EXPECT_EQ(builtin("{type: cylinder_sector, radius: 1, length: 2, angle: 400}"),
            "m.yaml:8: surfaces[0].builtin.angle: must be in (0, 360] degrees, got 400");
  EXPECT_EQ(builtin("{type: cylinder_sector, radius: 1, length: 2, angle: 0}"),
            "m.yaml:8: surfaces[0].builtin.angle: must be in (0, 360] degrees, got 0");
  EXPECT_EQ(builtin("{type: cylinder_sector, radius: 1, angle: 90}"),
            "m.yaml:8: surfaces[0].builtin.length: missing required key");
  EXPECT_EQ(builtin("{type: cylinder_sector, radius: 1, length: 2}"),
            "m.yaml:8: surfaces[0].builtin.angle: missing required key");
  // cylinder: the full turn, no angle.
  EXPECT_EQ(builtin("{type: cylinder, radius: 1}"),
            "m.yaml:8: surfaces[0].builtin.length: missing required key");
  EXPECT_EQ(builtin("{type: cylinder, length: 1}"),
            "m.yaml:8: surfaces[0].builtin.radius: missing required key");
  EXPECT_EQ(builtin("{type: cylinder, radius: 1, length: 2, angle: 90}"),
            "m.yaml:8: surfaces[0].builtin.angle: unknown key (valid keys: type, radius, length)");
  EXPECT_EQ(builtin("{type: cylinder, radius: 1, length: -2}"),
            "m.yaml:8: surfaces[0].builtin.length: must be > 0, got -2");
  // annulus.
  EXPECT_EQ(builtin("{type: annulus, outer_radius: 10}"),
            "m.yaml:8: surfaces[0].builtin.inner_radius: missing required key");
  EXPECT_EQ(builtin("{type: annulus, inner_radius: 6}"),
            "m.yaml:8: surfaces[0].builtin.outer_radius: missing required key");
  EXPECT_EQ(builtin("{type: annulus, inner_radius: 0, outer_radius: 10}"),
            "m.yaml:8: surfaces[0].builtin.inner_radius: must be > 0, got 0");
  EXPECT_EQ(builtin("{type: annulus, inner_radius: 6, outer_radius: 6}"),
            "m.yaml:8: surfaces[0].builtin.outer_radius: must be > inner_radius = 6, got 6");
  EXPECT_EQ(builtin("{type: annulus, inner_radius: 6, outer_radius: 10, angle: 361}"),
            "m.yaml:8: surfaces[0].builtin.angle: must be in (0, 360] degrees, got 361");
  EXPECT_EQ(builtin("{type: annulus, inner_radius: 6, outer_radius: 10, angle: -90}"),
            "m.yaml:8: surfaces[0].builtin.angle: must be in (0, 360] degrees, got -90");
  EXPECT_EQ(builtin("{type: annulus, inner_radius: 6, outer_radius: 10, radius: 8}"),
            "m.yaml:8: surfaces[0].builtin.radius: unknown key (valid keys: type, inner_radius, "
            "outer_radius, angle)");
  // … located at the key's own line in block style.
  EXPECT_EQ(error_of(with_surfaces({"  - name: s", "    builtin:", "      type: annulus",
                                    "      inner_radius: 6", "      outer_radius: 5.5",
                                    "      angle: 360"})),
            "m.yaml:11: surfaces[0].builtin.outer_radius: must be > inner_radius = 6, got 5.5");
  EXPECT_EQ(error_of(with_surfaces({"  - name: s", "    builtin:", "      type: annulus",
                                    "      inner_radius: 6", "      outer_radius: 10",
                                    "      angle: .nan"})),
            "m.yaml:12: surfaces[0].builtin.angle: must be a finite number");
  // spherical_cap.
  EXPECT_EQ(builtin("{type: spherical_cap, radius: 1, angle: 180}"),
            "m.yaml:8: surfaces[0].builtin.angle: must be in (0, 180) degrees (the polar angle of "
            "the rim), got 180");
  EXPECT_EQ(builtin("{type: spherical_cap, radius: 1, angle: 0}"),
            "m.yaml:8: surfaces[0].builtin.angle: must be in (0, 180) degrees (the polar angle of "
            "the rim), got 0");
  EXPECT_EQ(builtin("{type: spherical_cap, radius: 1}"),
            "m.yaml:8: surfaces[0].builtin.angle: missing required key");
  EXPECT_EQ(builtin("{type: spherical_cap, angle: 30}"),
            "m.yaml:8: surfaces[0].builtin.radius: missing required key");
  EXPECT_EQ(builtin("{type: sphere_sector, radius: 1, azimuth: 0, lat_from: 0, lat_to: 90}"),
            "m.yaml:8: surfaces[0].builtin.azimuth: must be in (0, 360] degrees, got 0");
  EXPECT_EQ(builtin("{type: sphere_sector, radius: 1, azimuth: 90, lat_from: -100, lat_to: 90}"),
            "m.yaml:8: surfaces[0].builtin.lat_from: must be in [-90, 90) degrees, got -100");
  EXPECT_EQ(builtin("{type: sphere_sector, radius: 1, azimuth: 90, lat_from: 10, lat_to: 10}"),
            "m.yaml:8: surfaces[0].builtin.lat_to: must be in (lat_from, 90] = (10, 90] degrees, "
            "got 10");
  EXPECT_EQ(builtin("{type: rectangle}"),
            "m.yaml:8: surfaces[0].builtin.size: missing required key (or give edge_u and edge_v)");
  EXPECT_EQ(builtin("{type: rectangle, size: [1, 0]}"),
            "m.yaml:8: surfaces[0].builtin.size[1]: must be > 0, got 0");
  EXPECT_EQ(builtin("{type: rectangle, size: 1}"),
            "m.yaml:8: surfaces[0].builtin.size: expected a list of 2 numbers [lx, ly]");
  EXPECT_EQ(builtin("{type: rectangle, size: [1, 1], edge_u: [1, 0, 0]}"),
            "m.yaml:8: surfaces[0].builtin.edge_u: give either size or edge_u and edge_v, not "
            "both");
  EXPECT_EQ(builtin("{type: rectangle, edge_u: [1, 0, 0]}"),
            "m.yaml:8: surfaces[0].builtin.edge_v: missing required key");
  EXPECT_EQ(builtin("{type: rectangle, edge_u: [1, 0, 0], edge_v: [-2, 0, 0]}"),
            "m.yaml:8: surfaces[0].builtin.edge_v: must be nonzero and not parallel to edge_u");
}

TEST(SurfaceReader, RefineAndPlacementErrors) {
  auto refine = [](std::string_view r) {
    return error_of(with_surfaces(
        {"  - name: s", "    builtin: {type: disc, radius: 1}", "    refine: " + std::string(r)}));
  };
  EXPECT_EQ(refine("{elevate: [-1, 0]}"),
            "m.yaml:9: surfaces[0].refine.elevate[0]: must be >= 0, got -1");
  EXPECT_EQ(refine("{elevate: [1]}"),
            "m.yaml:9: surfaces[0].refine.elevate: expected a list of 2 integers [u, v]");
  EXPECT_EQ(refine("{elevate: 1}"),
            "m.yaml:9: surfaces[0].refine.elevate: expected a list of 2 integers [u, v]");
  EXPECT_EQ(refine("{elevate: [0, 9]}"),
            "m.yaml:9: surfaces[0].refine.elevate[1]: degree 2 + 9 in v is above the maximum "
            "degree 10");
  // 2 + INT_MAX overflowed int before the check (found by UBSan on a fuzzed file).
  EXPECT_EQ(refine("{elevate: [2, 2147483647]}"),
            "m.yaml:9: surfaces[0].refine.elevate[1]: degree 2 + 2147483647 in v is above the "
            "maximum degree 10");
  EXPECT_EQ(refine("{knots_per_span: [1.5, 0]}"),
            "m.yaml:9: surfaces[0].refine.knots_per_span[0]: expected an integer");
  EXPECT_EQ(refine("{knots_per_span: [0, -2]}"),
            "m.yaml:9: surfaces[0].refine.knots_per_span[1]: must be >= 0, got -2");
  EXPECT_EQ(refine("{knots_per_span: [2000, 2000]}"),
            "m.yaml:9: surfaces[0].refine.knots_per_span: too many control points after "
            "refinement (2003 x 2003 = 4012009, at most 1000000)");
  EXPECT_EQ(refine("{h: 2}"),
            "m.yaml:9: surfaces[0].refine.h: unknown key (valid keys: elevate, knots_per_span)");
  EXPECT_EQ(refine("[1, 1]"), "m.yaml:9: surfaces[0].refine: expected a mapping of keys");

  auto place = [](std::string_view pl) {
    return error_of(with_surfaces({"  - name: s", "    builtin: {type: disc, radius: 1}",
                                   "    placement: " + std::string(pl)}));
  };
  EXPECT_EQ(place("{origin: [0, 0]}"),
            "m.yaml:9: surfaces[0].placement.origin: expected a list of 3 numbers [x, y, z]");
  EXPECT_EQ(place("{orientation: [[1, 0, 0], [0, 1, 0], [0, 0, -1]]}"),
            "m.yaml:9: surfaces[0].placement.orientation: orientation is not an orthonormal "
            "right-handed triad");
  EXPECT_EQ(place("{rotate: 90}"),
            "m.yaml:9: surfaces[0].placement.rotate: unknown key (valid keys: origin, "
            "orientation)");
}

// The example of docs/model-files.md "surfaces" reads (roof.stp: a roof of the test data).
TEST(SurfaceReader, DocumentationExampleIsValid) {
  const std::string doc = test::read_text(std::string(ISOFLEX_SOURCE_DIR) + "/docs/model-files.md");
  const auto section = doc.find("## `surfaces`");
  ASSERT_NE(section, std::string::npos);
  const auto begin = doc.find("```yaml\n", section);
  ASSERT_NE(begin, std::string::npos);
  const auto end = doc.find("```", begin + 8);
  ASSERT_NE(end, std::string::npos);
  // A model still needs a body: the example shows only its `surfaces`.
  std::string yaml = "bodies: [{name: b, mass: 1, inertia: [1, 1, 1], position: [0, 0, 0]}]\n" +
                     doc.substr(begin + 8, end - begin - 8);
  const auto roof = yaml.find("roof.stp");
  ASSERT_NE(roof, std::string::npos);
  yaml.replace(roof, 8, kData + "scordelis_lo_roof_2patch_split_x25_fullprec.stp");
  const model::Model m = read_model_string(yaml, "example.yaml");
  ASSERT_EQ(m.surfaces.size(), 3u);
  EXPECT_EQ(m.surfaces[0].kind, model::SurfaceSourceKind::cad);
  EXPECT_EQ(m.surfaces[1].builtin_type, "cylinder_sector");
  EXPECT_EQ(m.surfaces[0].cad_patch, 1);
  EXPECT_EQ(m.surfaces[0].surface.degree_u(), m.surfaces[0].surface.degree_v());
  EXPECT_EQ(m.surfaces[2].builtin_type, "rectangle");
  EXPECT_EQ(m.surfaces[2].surface.points.front(), Vec3(0, 0, 5));
}

// The example of docs/model-files.md "builtin" reads: the slit annular plate and the cap.
TEST(SurfaceReader, BuiltinDocumentationExampleIsValid) {
  const std::string doc = test::read_text(std::string(ISOFLEX_SOURCE_DIR) + "/docs/model-files.md");
  const auto section = doc.find("### `builtin`");
  ASSERT_NE(section, std::string::npos);
  const auto begin = doc.find("```yaml\n", section);
  ASSERT_LT(begin, doc.find("### `refine`"));
  const auto end = doc.find("```", begin + 8);
  ASSERT_NE(end, std::string::npos);
  const std::string yaml =
      "bodies: [{name: b, mass: 1, inertia: [1, 1, 1], position: [0, 0, 0]}]\n" +
      doc.substr(begin + 8, end - begin - 8);
  const model::Model m = read_model_string(yaml, "example.yaml");
  ASSERT_EQ(m.surfaces.size(), 2u);
  EXPECT_EQ(m.surfaces[0].builtin_type, "annulus");
  EXPECT_EQ(m.surfaces[1].builtin_type, "spherical_cap");
  // The slit plate: 4 × 4 elements in u, 8 in v; the outer radius on +x at both ends of u.
  const geometry::NurbsSurface& plate = m.surfaces[0].surface;
  EXPECT_EQ(m.surfaces[0].element_count(), 16 * 8);
  EXPECT_LT((geometry::evaluate(plate, 0.0, 0.0).x - Vec3(10, 0, 0)).norm(), 1e-14);
  EXPECT_LT((geometry::evaluate(plate, 1.0, 1.0).x - Vec3(6, 0, 0)).norm(), 1e-14);
}
