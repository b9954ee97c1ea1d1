// Dirichlet conditions of a KL shell patch (system/kl_boundary_conditions.hpp): which control
// point components are eliminated, the reduced dof map, the multiplier rows of symmetry planes
// and of weakly prescribed edges.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>

#include "isoflex/geometry/builders.hpp"
#include "isoflex/geometry/refinement.hpp"
#include "isoflex/system/kl_boundary_conditions.hpp"

using namespace isoflex;
using namespace isoflex::system;

namespace {

constexpr double kPi = std::numbers::pi;

// Biquadratic 4 × 5 elements on [0, 2] × [0, 3]: n_u = 6, n_v = 7 control points.
geometry::NurbsSurface plate() {
  return geometry::k_refine(geometry::planar_rectangle(2.0, 3.0), 1, 1, 3, 4);
}

std::set<int> as_set(const std::vector<int>& v) {
  return {v.begin(), v.end()};
}

}  // namespace

TEST(KLBoundaryConditions, ClampedAndPinnedRowsAndDofMap) {
  const auto s = plate();
  ASSERT_EQ(s.n_u(), 6);
  ASSERT_EQ(s.n_v(), 7);
  KLBoundaryConditions bc(s);
  bc.clamp_edge(PatchEdge::u0).fix_edge(PatchEdge::v1, kCompZ);
  const LinearConstraints lc = bc.constraints();
  std::set<int> expected;
  // Clamped u0 (the edge x = 0 of a plate in the xy plane): row 0 held, row 1 held in y and z (the
  // slope across the edge keeps its direction x; the stretch across the edge, x of row 1, is
  // free). The slope rows reduce to eliminations, so there are no multipliers.
  for (int j = 0; j < s.n_v(); ++j) {
    for (int k = 0; k < 3; ++k) expected.insert(3 * (s.n_u() * j) + k);
    for (int k = 1; k < 3; ++k) expected.insert(3 * (1 + s.n_u() * j) + k);
  }
  for (int i = 0; i < s.n_u(); ++i) expected.insert(3 * (i + s.n_u() * (s.n_v() - 1)) + 2);
  EXPECT_EQ(as_set(lc.eliminated), expected);
  EXPECT_TRUE(std::is_sorted(lc.eliminated.begin(), lc.eliminated.end()));
  EXPECT_EQ(lc.eliminated.size(), expected.size());  // the shared corner counted once
  EXPECT_EQ(lc.multipliers(), 0);
  const DofMap m = DofMap::build(bc.dofs(), lc.eliminated);
  EXPECT_EQ(m.n_free(), bc.dofs() - static_cast<int>(expected.size()));
  for (int d = 0; d < bc.dofs(); ++d) {
    if (expected.count(d)) {
      EXPECT_EQ(m.full_to_free[static_cast<std::size_t>(d)], -1);
    } else {
      ASSERT_GE(m.full_to_free[static_cast<std::size_t>(d)], 0);
      EXPECT_EQ(m.free[static_cast<std::size_t>(m.full_to_free[static_cast<std::size_t>(d)])], d);
    }
  }
  // Rows on the other edges.
  EXPECT_EQ(loads::edge_control_points(s, PatchEdge::u1, 1),
            (std::vector<int>{4, 10, 16, 22, 28, 34, 40}));
  EXPECT_EQ(loads::edge_control_points(s, PatchEdge::v0, 0), (std::vector<int>{0, 1, 2, 3, 4, 5}));
  EXPECT_THROW(loads::edge_control_points(s, PatchEdge::v0, 7), std::invalid_argument);
}

// Quarter cylinder: the edge ξ = 0 lies in the plane y = 0, the edge ξ = 1 in x = 0. Row 0 loses
// its normal component; the slope rows hold for every displacement that is symmetric about both
// planes (uniform radial expansion, axial stretch: δ_A = (a X, a Y, b Z)) and fail for one that
// turns the edge (δ_A = ω e_z × X: a rigid rotation about the axis, antisymmetric about y = 0).
// A clamp of some components holds those components of rows 0 and 1.
TEST(KLBoundaryConditions, PartialClampHoldsRowsZeroAndOne) {
  const auto s = plate();
  KLBoundaryConditions bc(s);
  bc.clamp_edge(PatchEdge::v0, kCompZ);
  const LinearConstraints lc = bc.constraints();
  std::set<int> expected;
  for (int i = 0; i < s.n_u(); ++i)
    for (int r = 0; r < 2; ++r) expected.insert(3 * (i + s.n_u() * r) + 2);
  EXPECT_EQ(as_set(lc.eliminated), expected);
  EXPECT_EQ(lc.multipliers(), 0);
}

TEST(KLBoundaryConditions, SymmetryOnACylinder) {
  const auto s = geometry::k_refine(geometry::cylinder_sector(1.0, 2.0, kPi / 2.0), 1, 0, 2, 3);
  KLBoundaryConditions bc(s);
  bc.symmetry_edge(PatchEdge::u0, Vec3(0, 2, 0)).symmetry_edge(PatchEdge::u1, Vec3(-1, 0, 0));
  const LinearConstraints lc = bc.constraints();
  std::set<int> expected;
  for (int j = 0; j < s.n_v(); ++j) {
    const int a = s.index(0, j), b = s.index(s.n_u() - 1, j);
    expected.insert(3 * a + 1);  // y on the ξ = 0 side
    expected.insert(3 * b + 0);  // x on the ξ = 1 side
    EXPECT_NEAR(s.points[static_cast<std::size_t>(a)].y(), 0.0, 1e-14);
    EXPECT_NEAR(s.points[static_cast<std::size_t>(b)].x(), 0.0, 1e-14);
  }
  EXPECT_EQ(as_set(lc.eliminated), expected);
  // Two slope rows per control-point pair and edge.
  EXPECT_EQ(lc.multipliers(), 2 * 2 * s.n_v());
  VecX symmetric(bc.dofs()), turning(bc.dofs());
  for (std::size_t A = 0; A < s.points.size(); ++A) {
    const Vec3& X = s.points[A];
    symmetric.segment<3>(3 * static_cast<int>(A)) = Vec3(0.3 * X.x(), 0.3 * X.y(), -0.7 * X.z());
    turning.segment<3>(3 * static_cast<int>(A)) = 0.1 * Vec3::UnitZ().cross(X);
  }
  EXPECT_LT((lc.C * symmetric).lpNorm<Eigen::Infinity>(), 1e-14);
  EXPECT_GT((lc.C * turning).lpNorm<Eigen::Infinity>(), 1e-3);
}

// A plane that is not a coordinate plane: row 0's normal displacement is a multiplier row too.
TEST(KLBoundaryConditions, SymmetryWithAGeneralNormalUsesMultiplierRows) {
  const double th = 2.0 * kPi / 3.0;
  const auto s = geometry::k_refine(geometry::cylinder_sector(1.0, 2.0, th), 0, 1, 1, 2);
  const Vec3 n(-std::sin(th), std::cos(th), 0.0);  // normal of the plane through the axis at θ
  KLBoundaryConditions bc(s);
  bc.symmetry_edge(PatchEdge::u1, 3.0 * n);
  const LinearConstraints lc = bc.constraints();
  EXPECT_TRUE(lc.eliminated.empty());
  ASSERT_EQ(lc.multipliers(), 3 * s.n_v());
  const auto row0 = loads::edge_control_points(s, PatchEdge::u1, 0);
  for (const int a : row0) EXPECT_NEAR(n.dot(s.points[static_cast<std::size_t>(a)]), 0.0, 1e-14);
  // The first n_v rows are n·δ_A on row 0.
  const VecX d = VecX::LinSpaced(bc.dofs(), -1.0, 2.0);
  const VecX Cd = lc.C * d;
  for (int r = 0; r < s.n_v(); ++r)
    EXPECT_NEAR(Cd(r), n.dot(d.segment<3>(3 * row0[static_cast<std::size_t>(r)])), 1e-14) << r;
  // A symmetric field about the plane (radial expansion, axial stretch) satisfies all rows.
  VecX symmetric(bc.dofs());
  for (std::size_t A = 0; A < s.points.size(); ++A) {
    const Vec3& X = s.points[A];
    symmetric.segment<3>(3 * static_cast<int>(A)) = Vec3(0.3 * X.x(), 0.3 * X.y(), -0.7 * X.z());
  }
  EXPECT_LT((lc.C * symmetric).lpNorm<Eigen::Infinity>(), 1e-14);
}

// Two symmetry edges meeting at a corner fix the twist there twice: the dependent row is dropped.
TEST(KLBoundaryConditions, SymmetryCornerKeepsIndependentRows) {
  const auto s = geometry::k_refine(geometry::planar_rectangle(2.0, 1.0), 2, 2, 3, 3);
  KLBoundaryConditions bc(s);
  bc.symmetry_edge(PatchEdge::u1, Vec3(1, 0, 0)).symmetry_edge(PatchEdge::v0, Vec3(0, 1, 0));
  const LinearConstraints lc = bc.constraints();
  // Per edge 2 rows per pair, less: the in-plane slope row of each edge at the corner, whose two
  // control points both lie on the other edge's row 0 (that component is eliminated there), and
  // one of the four z-rows around the corner cell, which depends on the other three.
  EXPECT_EQ(lc.multipliers(), 2 * s.n_v() + 2 * s.n_u() - 3);
  EXPECT_EQ(Eigen::FullPivLU<MatX>(MatX(lc.C)).rank(), lc.multipliers());
}

TEST(KLBoundaryConditions, WeakPrescribedEdgeIsTheL2ProjectionOfTheTrace) {
  const auto s = plate();
  const Vec3 a(0.3, -0.2, 0.5);
  KLBoundaryConditions bc(s);
  // ū(t, X) = t (a·X) e_z + t (0.1, 0, 0): linear in X, reproduced exactly by the trace space.
  bc.prescribe_edge(PatchEdge::v0,
                    [&](double t, const Vec3& X) { return Vec3(0.1 * t, 0.0, t * a.dot(X)); });
  const LinearConstraints lc = bc.constraints();
  ASSERT_EQ(lc.multipliers(), 3 * s.n_u());
  const auto edge = loads::edge_control_points(s, PatchEdge::v0, 0);
  // Columns only on the edge row; the edge block per component is symmetric positive definite.
  const MatX C(lc.C);
  for (int col = 0; col < bc.dofs(); ++col) {
    const bool on_edge = std::find(edge.begin(), edge.end(), col / 3) != edge.end();
    if (!on_edge) {
      EXPECT_EQ(C.col(col).norm(), 0.0) << col;
    }
  }
  MatX G(s.n_u(), s.n_u());
  for (int i = 0; i < s.n_u(); ++i)
    for (int j = 0; j < s.n_u(); ++j) G(i, j) = C(i, 3 * edge[static_cast<std::size_t>(j)]);
  EXPECT_LT((G - G.transpose()).norm(), 1e-14);
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<MatX>(G).eigenvalues().minCoeff(), 0.0);
  EXPECT_NEAR(G.sum(), 2.0, 1e-13);  // ∫ Σ R_j Σ R_A ds = edge length
  // u_A = ū(t, X_A) on the edge row satisfies C u = d(t).
  const double t = 0.7;
  VecX u = VecX::Zero(bc.dofs());
  for (int A : edge)
    u.segment<3>(3 * A) = Vec3(0.1 * t, 0.0, t * a.dot(s.points[static_cast<std::size_t>(A)]));
  EXPECT_LT((lc.C * u - lc.rhs(t)).norm(), 1e-14);
  // A corner fixed by elimination drops its function (4.26); a second edge sharing a corner
  // does not repeat it.
  KLBoundaryConditions bc2(s);
  bc2.fix_edge(PatchEdge::u0)
      .prescribe_edge(PatchEdge::v0, [](double, const Vec3&) { return Vec3::Zero(); })
      .prescribe_edge(
          PatchEdge::u1, [](double, const Vec3&) { return Vec3::Zero(); }, kCompZ);
  const LinearConstraints lc2 = bc2.constraints();
  EXPECT_EQ(lc2.multipliers(), 3 * (s.n_u() - 1) + (s.n_v() - 1));
}
