// The kl_shells, kl_supports and kl_loads blocks and probes on Kirchhoff–Love shells
// (docs/model-files.md "kl_shells"): what they read into and their located errors.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "isoflex/io/model_reader.hpp"
#include "support/model_errors.hpp"

using namespace isoflex;
using test::error_of;

namespace {
// A quarter cylinder of radius 2 (degree 2 along the arc) and a flat rectangle (degree 1) on
// lines 1–8, a shell on the cylinder on lines 9–12, then `more` from line 13.
std::string kl_model(const std::string& more) {
  return "surfaces:\n"                                                              // 1
         "  - name: cyl\n"                                                          // 2
         "    builtin: {type: cylinder_sector, radius: 2, length: 3, angle: 90}\n"  // 3
         "    refine: {elevate: [0, 1], knots_per_span: [3, 3]}\n"                  // 4
         "  - name: flat\n"                                                         // 5
         "    builtin: {type: rectangle, size: [2, 1]}\n"                           // 6
         "  - name: flat2\n"                                                        // 7
         "    builtin: {type: rectangle, size: [2, 1]}\n"                           // 8
         "kl_shells:\n"                                                             // 9
         "  - name: roof\n"                                                         // 10
         "    surface: cyl\n"                                                       // 11
         "    material: {E: 1e6, nu: 0.3, thickness: 0.01, density: 10}\n" +        // 12
         more;
}
}  // namespace

TEST(KLShellReader, ReadsShellsSupportsLoadsAndProbes) {
  const model::Model m = io::read_model_string(
      kl_model(
          "    quadrature: [4, 5]\n"
          "gravity: [0, 0, -9.81]\n"
          "kl_supports:\n"
          "  - {shell: roof, edge: v0, clamped: [x, z]}\n"
          "  - {shell: roof, edge: u1, symmetry: [1, 0, 0]}\n"
          "  - {shell: roof, control_points: [0, 3], fixed: all}\n"
          "  - {shell: roof, edge: v1, displacement: [0, 0, \"0.1*t\"]}\n"
          "kl_loads:\n"
          "  - {name: p, shell: roof, pressure: \"-2*t\", follower: true}\n"
          "  - {shell: roof, self_weight: t}\n"
          "  - {shell: roof, edge: u0, force_per_length: [0, 1, 0]}\n"
          "  - {shell: roof, point: [0, 2, 1.5], force: [0, \"-t\", 0]}\n"
          "  - {shell: roof, edge: v1, moment_per_length: \"3*t\", axis: [0, 0, 2]}\n"
          "probes:\n"
          "  - {name: ref, shell: roof, point: [1.4142135623730951, 1.4142135623730951, 3]}\n"),
      "m.yaml");
  ASSERT_EQ(m.kl_shells.size(), 1u);
  const model::KLShell& s = m.kl_shells[0];
  EXPECT_EQ(s.surface, "cyl");
  EXPECT_EQ(s.E, 1e6);
  EXPECT_EQ(s.nu, 0.3);
  EXPECT_EQ(s.thickness, 0.01);
  EXPECT_EQ(s.density, 10);
  EXPECT_EQ(s.eta, 0.0);  // no material damping unless given
  EXPECT_EQ(s.quadrature[0], 4);
  EXPECT_EQ(s.quadrature[1], 5);
  ASSERT_EQ(m.kl_supports.size(), 4u);
  EXPECT_EQ(m.kl_supports[0].kind, model::KLSupportKind::clamped);
  EXPECT_EQ(m.kl_supports[0].edge, "v0");
  EXPECT_EQ(m.kl_supports[0].components, (std::array<bool, 3>{true, false, true}));
  EXPECT_EQ(m.kl_supports[1].kind, model::KLSupportKind::symmetry);
  EXPECT_EQ(m.kl_supports[1].normal, Vec3(1, 0, 0));
  EXPECT_EQ(m.kl_supports[2].kind, model::KLSupportKind::fixed);
  EXPECT_EQ(m.kl_supports[2].control_points, (std::vector<int>{0, 3}));
  EXPECT_EQ(m.kl_supports[2].components, (std::array<bool, 3>{true, true, true}));
  EXPECT_EQ(m.kl_supports[3].kind, model::KLSupportKind::displacement);
  EXPECT_EQ(m.kl_supports[3].displacement[2], "0.1*t");
  ASSERT_EQ(m.kl_loads.size(), 5u);
  EXPECT_EQ(m.kl_loads[4].kind, model::KLLoadKind::edge_moment);
  EXPECT_EQ(m.kl_loads[4].moment, "3*t");
  EXPECT_EQ(m.kl_loads[4].axis, Vec3(0, 0, 1));
  EXPECT_EQ(m.kl_loads[0].kind, model::KLLoadKind::pressure);
  EXPECT_EQ(m.kl_loads[0].pressure, "-2*t");
  EXPECT_TRUE(m.kl_loads[0].follower);
  EXPECT_EQ(m.kl_loads[1].kind, model::KLLoadKind::self_weight);
  EXPECT_EQ(m.kl_loads[1].factor, "t");
  EXPECT_EQ(m.kl_loads[2].kind, model::KLLoadKind::edge_force);
  EXPECT_EQ(m.kl_loads[2].edge, "u0");
  EXPECT_EQ(m.kl_loads[3].kind, model::KLLoadKind::point_force);
  EXPECT_EQ(m.kl_loads[3].force[1], "-t");
  // The builtin cylinder sector starts at angle 0 on +x: (0, 2, 1.5) is the end of the arc (ξ = 1)
  // half way along the axis (η = 0.5).
  EXPECT_NEAR(m.kl_loads[3].xi, 1.0, 1e-9);
  EXPECT_NEAR(m.kl_loads[3].eta, 0.5, 1e-9);
  ASSERT_EQ(m.probes.size(), 1u);
  EXPECT_EQ(m.probes[0].kl_shell, "roof");
  EXPECT_TRUE(m.probes[0].body.empty());
  EXPECT_NEAR(m.probes[0].eta, 1.0, 1e-9);
  EXPECT_GT(m.probes[0].xi, 0.3);
  EXPECT_LT(m.probes[0].xi, 0.7);
}

TEST(KLShellReader, LocatedErrors) {
  EXPECT_EQ(error_of(kl_model("    thickness: 1\n")),
            "m.yaml:13: kl_shells[0].thickness: unknown key (valid keys: name, surface, material, "
            "quadrature, seam, velocity, angular_velocity, velocity_point, node_velocities)");
  // Missing material.
  EXPECT_EQ(error_of("surfaces:\n  - name: cyl\n"
                     "    builtin: {type: cylinder_sector, radius: 2, length: 3, angle: 90}\n"
                     "    refine: {elevate: [0, 1]}\n"
                     "kl_shells:\n  - name: roof\n    surface: cyl\n"),
            "m.yaml:6: kl_shells[0].material: missing required key");
  EXPECT_EQ(error_of(kl_model("  - name: s2\n    surface: nowhere\n    material: {E: 1, nu: 0, "
                              "thickness: 1}\n")),
            "m.yaml:14: kl_shells[1].surface: no surface named \"nowhere\"");
  // Degree 1 geometry.
  const std::string degree1 = error_of(
      kl_model("  - name: s2\n    surface: flat\n    material: {E: 1, nu: 0, thickness: 1}\n"));
  EXPECT_NE(degree1.find("m.yaml:14: kl_shells[1].surface: surface \"flat\" has degrees (1, 1): "
                         "a Kirchhoff–Love shell needs degree ≥ 2"),
            std::string::npos)
      << degree1;
  EXPECT_EQ(error_of(kl_model("    material: {E: 1, nu: 0.5, thickness: 1}\n")),
            "m.yaml:13: kl_shells[0].material: duplicate key (first at line 12)");
  // The Kelvin–Voigt damping factor (IGA-thesis (3.51)).
  EXPECT_EQ(io::read_model_string(kl_model("  - name: s2\n    surface: cyl\n    material: {E: 1, "
                                           "nu: 0, thickness: 0.1, eta: 0.25}\n"),
                                  "m.yaml")
                .kl_shells[1]
                .eta,
            0.25);
  EXPECT_EQ(error_of(kl_model("  - name: s2\n    surface: cyl\n    material: {E: 1, nu: 0, "
                              "thickness: 0.1, eta: -1}\n")),
            "m.yaml:15: kl_shells[1].material.eta: the damping factor η must be >= 0 (seconds)");
  EXPECT_EQ(error_of(kl_model("kl_supports:\n  - {shell: roof, edge: u2, fixed: all}\n")),
            "m.yaml:14: kl_supports[0].edge: unknown edge \"u2\" (expected u0, u1, v0 or v1)");
  EXPECT_EQ(error_of(kl_model("kl_supports:\n  - {shell: roof, edge: u0}\n")),
            "m.yaml:14: kl_supports[0]: give exactly one of fixed, clamped, symmetry or "
            "displacement");
  EXPECT_EQ(
      error_of(kl_model("kl_supports:\n  - {shell: roof, control_points: [99], fixed: all}\n")),
      "m.yaml:14: kl_supports[0].control_points[0]: control point 99 out of range: shell "
      "\"roof\" has 36");
  EXPECT_EQ(
      error_of(kl_model("kl_supports:\n  - {shell: roof, control_points: [1], clamped: all}\n")),
      "m.yaml:14: kl_supports[0]: clamped, symmetry and displacement act on an edge: give "
      "edge");
  EXPECT_EQ(error_of(kl_model("kl_loads:\n  - {shell: wall, pressure: 1}\n")),
            "m.yaml:14: kl_loads[0].shell: no kl_shell named \"wall\"");
  EXPECT_EQ(error_of(kl_model("kl_loads:\n  - {shell: roof, self_weight: 1}\n")),
            "m.yaml:14: kl_loads[0].self_weight: the model has no gravity: self-weight needs it");
  EXPECT_EQ(error_of(kl_model("kl_loads:\n  - {shell: roof, edge: u0, force: [0, 0, 1]}\n")),
            "m.yaml:14: kl_loads[0].edge: only with force_per_length or moment_per_length");
  // A load point off the surface names its distance.
  const std::string off =
      error_of(kl_model("kl_loads:\n  - {shell: roof, point: [0, 2.1, 1.5], "
                        "force: [0, 0, 1]}\n"));
  EXPECT_NE(off.find("m.yaml:14: kl_loads[0].point: the point (0, 2.1, 1.5) is not on surface "
                     "\"cyl\": its closest point ("),
            std::string::npos)
      << off;
  EXPECT_NE(off.find(", 2, 1.5) is 0.1 away (tolerance "), std::string::npos) << off;
  EXPECT_EQ(error_of(kl_model("probes:\n  - {name: a, shell: roof}\n")),
            "m.yaml:14: probes[0].point: missing required key");
  EXPECT_EQ(error_of(kl_model("probes:\n  - {name: a, shell: roof, body: x, point: [0, 2, 0]}\n")),
            "m.yaml:14: probes[0]: give exactly one of body (a body or node) or shell (a "
            "kl_shell, with point)");
}
