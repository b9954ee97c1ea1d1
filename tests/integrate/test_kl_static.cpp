// The static solver on a Kirchhoff–Love shell patch (integrate/static_newton.hpp on
// support/kl_static_problem.hpp): the clamped square plate under uniform pressure against
// Kirchhoff plate theory, elimination vs multipliers, linear vs nonlinear kinematics at a small
// load. Built as its own executable (test_kl_static) only when elements/kl_shell_patch.cpp exists
// (tests/CMakeLists.txt).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

#include "isoflex/geometry/builders.hpp"
#include "isoflex/geometry/refinement.hpp"
#include "isoflex/system/kl_boundary_conditions.hpp"
#include "support/geometry.hpp"
#include "support/kl_static_problem.hpp"

using namespace isoflex;
using namespace isoflex::integrate;
using namespace isoflex::loads;
using loads::PatchEdge;
using system::kCompX;
using system::kCompXYZ;
using system::kCompY;
using system::kCompZ;
using system::KLBoundaryConditions;

namespace {

constexpr double kE = 1.0e7, kNu = 0.3, kT = 0.01, kA = 1.0, kQ = 1.0;

double plate_D() {
  return kE * kT * kT * kT / (12.0 * (1.0 - kNu * kNu));
}

// Degree p, n × n elements on [0, a]².
geometry::NurbsSurface square(int p, int n) {
  return geometry::k_refine(geometry::planar_rectangle(kA, kA), p - 1, p - 1, n - 1, n - 1);
}

elements::KLShellPatch make_patch(const geometry::NurbsSurface& s) {
  return elements::KLShellPatch(s, elements::KLShellSection{kE, kNu, kT, 1.0});
}

double centre_deflection(const geometry::NurbsSurface& s, const VecX& x) {
  geometry::NurbsSurface c = s;
  for (std::size_t a = 0; a < c.points.size(); ++a)
    c.points[a] = x.segment<3>(3 * static_cast<int>(a));
  return geometry::evaluate(c, 0.5, 0.5).x.z() - geometry::evaluate(s, 0.5, 0.5).x.z();
}

PatchLoads pressure(const geometry::NurbsSurface& s, double p) {
  return {std::make_shared<loads::DeadPressure>(s, p)};
}

// The static solver on the bare patch (no System): its provider with the patch's conditions.
StaticNewtonSolver solver_of(const elements::KLShellPatch& patch, PatchLoads loads,
                             const KLBoundaryConditions& bc, const StaticSettings& set,
                             elements::KLKinematics kin = elements::KLKinematics::nonlinear) {
  return StaticNewtonSolver(test::kl_static_problem(patch, std::move(loads), kin), bc.constraints(),
                            set);
}

}  // namespace

// Timoshenko & Woinowsky-Krieger, Table 35: clamped square plate, ν = 0.3: w = 0.00126 q a⁴/D.
TEST(KLStatic, ClampedSquarePlateCentreDeflection) {
  const auto s = square(3, 8);
  const auto patch = make_patch(s);
  KLBoundaryConditions bc(s);
  for (PatchEdge e : {PatchEdge::u0, PatchEdge::u1, PatchEdge::v0, PatchEdge::v1}) bc.clamp_edge(e);
  StaticSettings set;
  StaticNewtonSolver solver =
      solver_of(patch, pressure(s, kQ), bc, set, elements::KLKinematics::linear);
  const StaticResult res = solver.solve();
  ASSERT_EQ(res.steps.size(), 1u);
  EXPECT_EQ(res.steps[0].iterations, 1);
  const double w = centre_deflection(s, res.x);
  const double w_ref = 0.00126 * kQ * kA * kA * kA * kA / plate_D();
  RecordProperty("w_over_wref", std::to_string(w / w_ref));
  RecordProperty("assembly_s", isoflex::test::sci(res.steps[0].assembly_seconds));
  RecordProperty("solve_s", isoflex::test::sci(res.steps[0].solve_seconds));
  EXPECT_NEAR(w / w_ref, 1.0, 0.01) << "w = " << w << ", w_ref = " << w_ref;
}

// Pinned edges (row 0 fixed) by elimination and by multipliers on the edges with ū = 0.
TEST(KLStatic, MultipliersMatchElimination) {
  const auto s = square(2, 4);
  const auto patch = make_patch(s);
  KLBoundaryConditions elim(s), weak(s);
  for (PatchEdge e : {PatchEdge::u0, PatchEdge::u1, PatchEdge::v0, PatchEdge::v1}) {
    elim.fix_edge(e);
    weak.prescribe_edge(e, [](double, const Vec3&) { return Vec3::Zero(); });
  }
  StaticSettings set;
  set.steps = 2;
  StaticNewtonSolver a = solver_of(patch, pressure(s, kQ), elim, set);
  StaticNewtonSolver b = solver_of(patch, pressure(s, kQ), weak, set);
  const StaticResult ra = a.solve(), rb = b.solve();
  const double w = centre_deflection(s, ra.x);
  EXPECT_GT(std::abs(w), 1e-4);
  EXPECT_LT((ra.x - rb.x).lpNorm<Eigen::Infinity>(), 1e-8 * std::abs(w));
  EXPECT_GT(rb.mu.size(), 0);
}

// At a small load the nonlinear solution approaches the linear one (relative O(load)).
TEST(KLStatic, NonlinearApproachesLinearAtSmallLoad) {
  const auto s = square(2, 4);
  const auto patch = make_patch(s);
  KLBoundaryConditions bc(s);
  for (PatchEdge e : {PatchEdge::u0, PatchEdge::u1, PatchEdge::v0, PatchEdge::v1}) bc.clamp_edge(e);
  const double q = 1e-3;
  StaticSettings set;
  StaticNewtonSolver lin =
      solver_of(patch, pressure(s, q), bc, set, elements::KLKinematics::linear);
  StaticNewtonSolver non = solver_of(patch, pressure(s, q), bc, set);
  const double wl = centre_deflection(s, lin.solve().x);
  const StaticResult rn = non.solve();
  const double wn = centre_deflection(s, rn.x);
  RecordProperty("relative_difference", isoflex::test::sci(std::abs(wn / wl - 1.0)));
  EXPECT_NEAR(wn / wl, 1.0, 1e-3);
  EXPECT_LE(rn.steps[0].iterations, 6);
}

// A large follower pressure, adaptive load stepping: converges, stiffening (membrane action)
// makes the deflection smaller than the linear one.
TEST(KLStatic, FollowerPressureLargeDeflection) {
  const auto s = square(2, 4);
  const auto patch = make_patch(s);
  KLBoundaryConditions bc(s);
  for (PatchEdge e : {PatchEdge::u0, PatchEdge::u1, PatchEdge::v0, PatchEdge::v1}) bc.clamp_edge(e);
  const double q = 50.0;
  StaticSettings set;
  set.steps = 4;
  set.adaptive = true;
  StaticNewtonSolver lin =
      solver_of(patch, pressure(s, q), bc, set, elements::KLKinematics::linear);
  PatchLoads follower{std::make_shared<loads::FollowerPressure>(s, q)};
  StaticNewtonSolver non = solver_of(patch, follower, bc, set);
  const double wl = centre_deflection(s, lin.solve().x);
  const StaticResult rn = non.solve();
  const double wn = centre_deflection(s, rn.x);
  RecordProperty("w_nonlinear_over_linear", std::to_string(wn / wl));
  EXPECT_GT(wn, 0.0);
  EXPECT_LT(wn, 0.9 * wl);
}
