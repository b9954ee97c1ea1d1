// The one static solver (integrate/static_equilibrium.hpp) on models compiled as one System: its
// Newton matrix is the derivative of its residual (Kirchhoff–Love patch with a follower pressure,
// frame nodes and joints), and a cantilever plate clamped to the ground by eliminated control-point
// components (the static supports) is in equilibrium at the same configuration as the same plate
// on a rigid body that is itself fixed to the ground (PointOnFrame joints, multipliers, the body's
// internal rows): one solver for both kinds of models, and the two ways to hold an edge agree.
#include <gtest/gtest.h>

#include <random>
#include <string>

#include "isoflex/integrate/static_equilibrium.hpp"
#include "isoflex/io/model_reader.hpp"
#include "support/finite_difference.hpp"
#include "support/statics.hpp"

using namespace isoflex;

namespace {

// A plate 1 × 0.5 (p = 3, 4 × 2 elements) clamped along u0 by `support`, bent down by a pressure
// ("-0.05*t", follower if asked); `extra` adds bodies and joints.
std::string plate(const std::string& support, const std::string& extra, bool follower) {
  return std::string(
             "solver: {analysis: static, dt: 0.5, t_end: 1}\n"
             "surfaces:\n"
             "  - name: s\n"
             "    builtin: {type: rectangle, size: [1, 0.5]}\n"
             "    refine: {elevate: [2, 2], knots_per_span: [3, 1]}\n"
             "kl_shells:\n"
             "  - name: plate\n"
             "    surface: s\n"
             "    material: {E: 1.0e5, nu: 0.3, thickness: 0.02}\n"
             "kl_supports:\n"
             "  - ") +
         support + "\n" + "kl_loads:\n  - {name: q, shell: plate, pressure: \"-0.05*t\"" +
         (follower ? ", follower: true" : "") + "}\n" +
         "probes:\n  - {name: tip, shell: plate, point: [1, 0.25, 0]}\n" + extra;
}

// Rows 0 and 1 of edge u0 held entirely (n_u = 7, n_v = 5: control points i + 7 j, i = 0, 1): as
// eliminated components, or attached to the body (clamped: the same two rows).
const char* kOnGround =
    "{shell: plate, control_points: [0, 7, 14, 21, 28, 1, 8, 15, 22, 29], fixed: all}";
const char* kOnBody = "{shell: plate, edge: u0, clamped: all, body: base}";
const char* kBase =
    "bodies:\n"
    "  - {name: base, mass: 1, inertia: [1, 1, 1], position: [0, 0.25, 0]}\n"
    "joints:\n"
    "  - {name: hold, type: fixed, body_a: ground, body_b: base, point: [0, 0.25, 0]}\n";

model::Model read(const std::string& text) {
  return io::read_model_string(text, "m.yaml");
}

// J against central differences of R at a perturbed state x (every term of J exercised).
double tangent_error(const std::string& text, double t) {
  const model::Model m = read(text);
  const auto sys = system::System::compile(m);
  const integrate::StaticEquilibrium eq(sys, m.solver);
  std::mt19937 g(3);
  VecX x = VecX::Zero(sys.n() + sys.m_selected());
  x.head(sys.n()) = sys.q0();
  x += test::random_vector(g, static_cast<int>(x.size()), 1e-2);
  MatX J;
  eq.residual(t, x, &J);
  const MatX J_fd =
      test::central_jacobian([&](const VecX& y) { return eq.residual(t, y, nullptr); }, x);
  return test::rel_diff(J, J_fd);
}

}  // namespace

TEST(StaticEquilibrium, NewtonMatrixIsTheDerivativeOfTheResidual) {
  const double patch = tangent_error(plate(kOnGround, "", true), 0.7);
  const double mixed = tangent_error(plate(kOnBody, kBase, true), 0.7);
  std::printf("  [static] J vs FD (rel): patch with follower pressure %.2e, patch on a body %.2e\n",
              patch, mixed);
  EXPECT_LT(patch, 1e-7);
  EXPECT_LT(mixed, 1e-7);
}

TEST(StaticEquilibrium, EdgeOnTheGroundAndEdgeOnAFixedBodyAgree) {
  const model::Model a = read(plate(kOnGround, "", false));
  const model::Model b = read(plate(kOnBody, kBase, false));
  const auto sa = system::System::compile(a);
  const auto sb = system::System::compile(b);
  // Ground: 10 control points × 3 components eliminated, no rows. Body: 30 joint rows, the body's
  // 6 internal rows and the fixed joint's 6.
  EXPECT_EQ(static_cast<int>(sa.linear_constraints().eliminated.size()), 30);
  EXPECT_EQ(sa.m_selected(), 0);
  EXPECT_TRUE(sb.linear_constraints().eliminated.empty());
  EXPECT_EQ(sb.m_selected(), 30 + 6 + 6);
  const test::StaticRun ra = test::solve_static(sa, a), rb = test::solve_static(sb, b);
  ASSERT_EQ(ra.failure, "");
  ASSERT_EQ(rb.failure, "");
  ASSERT_EQ(ra.steps.size(), 2u);
  ASSERT_EQ(rb.steps.size(), 2u);
  const Vec3 ua = test::probe_at(sa, ra.steps.back().q, "tip") - test::probe_at(sa, sa.q0(), "tip");
  const Vec3 ub = test::probe_at(sb, rb.steps.back().q, "tip") - test::probe_at(sb, sb.q0(), "tip");
  std::printf("  [static] tip displacement %.10g (ground), %.10g (body); difference %.2e\n", ua.z(),
              ub.z(), (ua - ub).norm());
  EXPECT_LT(ua.z(), -1e-3);  // bent down, geometrically nonlinear
  EXPECT_LT((ua - ub).norm(), 1e-9 * ua.norm());
}
