// A Kirchhoff–Love patch inside System: the discrete force's tangent in the fixed global pattern
// against central differences (patch element, follower pressure, a body and its load together),
// control points joined to bodies, and the located errors of what is not supported.
#include <gtest/gtest.h>

#include <string>

#include "isoflex/io/model_reader.hpp"
#include "isoflex/system/system.hpp"
#include "support/finite_difference.hpp"

using namespace isoflex;

namespace {

std::string kl_model_text(const std::string& extra) {
  return "solver: {dt: 0.01, t_end: 0.1}\n"
         "surfaces:\n"
         "  - name: sheet\n"
         "    builtin: {type: rectangle, size: [1, 0.5]}\n"
         "    refine: {elevate: [1, 1], knots_per_span: [2, 1]}\n"
         "bodies:\n"
         "  - {name: hub, mass: 2, inertia: [0.1, 0.2, 0.3], position: [0, 0.25, 0]}\n"
         "kl_shells:\n"
         "  - {name: plate, surface: sheet, material: {E: 1.0e4, nu: 0.3, thickness: 0.05, "
         "density: 1000}}\n" +
         extra;
}

std::string compile_error(const std::string& text) {
  try {
    system::System::compile(io::read_model_string(text, "m.yaml"));
  } catch (const system::CompileError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(KLSystem, DiscreteForceTangentInTheFixedPattern) {
  const auto sys = system::System::compile(io::read_model_string(
      kl_model_text("kl_supports: [{shell: plate, edge: u0, clamped: all, body: hub}]\n"
                    "kl_loads: [{shell: plate, pressure: \"3*t\", follower: true}]\n"
                    "loads: [{body: hub, force: [0, 0, 1], moment: [\"t\", 0, 2]}]\n"),
      "m.yaml"));
  std::mt19937 g(3);
  const VecX qn = sys.q0() + test::random_vector(g, sys.n(), 0.05);
  const VecX qn1 = qn + test::random_vector(g, sys.n(), 0.05);
  system::SpMat K;
  const VecX f = sys.discrete_force(qn, qn1, 0.7, &K);
  // The pattern is the system's, fixed: a second call keeps K's storage.
  const double* storage = K.valuePtr();
  sys.discrete_force(qn, qn1, 0.7, &K);
  EXPECT_EQ(K.valuePtr(), storage);
  EXPECT_EQ(K.nonZeros(), sys.stiffness_pattern().pattern().nonZeros());
  auto F = [&](const VecX& x) -> VecX { return sys.discrete_force(qn, x, 0.7, nullptr); };
  EXPECT_LT(test::rel_diff(MatX(K), test::central_jacobian(F, qn1)), 1e-6);
  EXPECT_LT((f - F(qn1)).norm(), 1e-14 * f.norm());
}

TEST(KLSystem, ControlPointsJoinedToBodies) {
  const auto sys = system::System::compile(io::read_model_string(
      kl_model_text("joints:\n  - {type: spherical, body_a: hub, body_b: \"plate[0]\"}\n"
                    "  - {type: rigid, body_a: hub, body_b: \"plate[4]\"}\n"),
      "m.yaml"));
  EXPECT_EQ(sys.node_count(NodeKind::point), 5 * 4);
  EXPECT_EQ(sys.m_selected(), 6 + 6);
  int tree = 0;
  for (const auto& J : sys.joints()) tree += J.tree;
  EXPECT_EQ(tree, 2);
  EXPECT_LT(sys.constraints(sys.q0(), 0.0).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(KLSystem, LocatedErrors) {
  EXPECT_EQ(
      compile_error(kl_model_text(
          "joints:\n  - {type: revolute, body_a: hub, body_b: \"plate[3]\", point: [1, 0, 0], "
          "axis: [0, 0, 1]}\n")),
      "m.yaml:11: joints[0].type: 'plate[3]' is a control point: it is attached (rigid, "
      "fixed or spherical, which coincide for a point), not revolute");
  // A dynamic run starts from the reference configuration.
  EXPECT_EQ(compile_error(kl_model_text(
                "kl_supports: [{shell: plate, edge: u0, displacement: [0, 0, \"0.5+t\"]}]\n")),
            "m.yaml:10: kl_supports[0].displacement[2]: '0.5+t' is 0.5 at t = 0: a dynamic run "
            "starts from the reference configuration, so a prescribed displacement starts at 0");
  // A prescribed motion of what a symmetry plane holds (x on the edge u0, normal x).
  EXPECT_EQ(
      compile_error(kl_model_text("kl_supports:\n"
                                  "  - {shell: plate, edge: u0, symmetry: [1, 0, 0]}\n"
                                  "  - {shell: plate, edge: u0, displacement: [\"t\", 0, 0]}\n")),
      "m.yaml:12: kl_supports[1]: row 0 of the prescribed motion depends on the other rows "
      "of the model (it acts on what other supports or joints already hold); a prescribed "
      "motion must act on free coordinates only");
  // Fixed supports take the functions of a moving edge they hold (as in statics): nothing left.
  EXPECT_EQ(
      compile_error(kl_model_text("kl_supports:\n"
                                  "  - {shell: plate, edge: u0, fixed: all}\n"
                                  "  - {shell: plate, edge: u0, displacement: [0, 0, \"t\"]}\n")),
      "m.yaml:12: kl_supports[1]: the support holds nothing");
  EXPECT_EQ(compile_error(
                kl_model_text("kl_supports: [{shell: plate, edge: u0, fixed: [z], body: hub}]\n")),
            "m.yaml:10: kl_supports[0]: a Kirchhoff–Love support to a body holds all components, "
            "fixed or clamped");
}
