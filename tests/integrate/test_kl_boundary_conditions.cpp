// Dirichlet conditions of a KL shell patch (integrate/kl_boundary_conditions.hpp): which control
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
#include "isoflex/integrate/kl_boundary_conditions.hpp"

using namespace isoflex;
using namespace isoflex::integrate;

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
  for (int j = 0; j < s.n_v(); ++j)
    for (int i = 0; i < 2; ++i)
      for (int k = 0; k < 3; ++k) expected.insert(3 * (i + s.n_u() * j) + k);
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

// Quarter cylinder: the edge ξ = 0 lies in the plane y = 0, the edge ξ = 1 in x = 0.
TEST(KLBoundaryConditions, SymmetryRowsOnACylinder) {
  const auto s = geometry::k_refine(geometry::cylinder_sector(1.0, 2.0, kPi / 2.0), 1, 0, 2, 3);
  KLBoundaryConditions bc(s);
  bc.symmetry_edge(PatchEdge::u0, Vec3(0, 2, 0)).symmetry_edge(PatchEdge::u1, Vec3(-1, 0, 0));
  const LinearConstraints lc = bc.constraints();
  EXPECT_EQ(lc.multipliers(), 0);  // axis-aligned normals: elimination
  std::set<int> expected;
  for (int j = 0; j < s.n_v(); ++j)
    for (int r = 0; r < 2; ++r) {
      const int a = s.index(r, j), b = s.index(s.n_u() - 1 - r, j);
      expected.insert(3 * a + 1);  // y on the ξ = 0 side
      expected.insert(3 * b + 0);  // x on the ξ = 1 side
      // The edge row lies in its plane.
      if (r == 0) {
        EXPECT_NEAR(s.points[static_cast<std::size_t>(a)].y(), 0.0, 1e-14);
        EXPECT_NEAR(s.points[static_cast<std::size_t>(b)].x(), 0.0, 1e-14);
      }
    }
  EXPECT_EQ(as_set(lc.eliminated), expected);
}

// A plane that is not a coordinate plane: one multiplier row n·(x_A − X_A) = 0 per control point.
TEST(KLBoundaryConditions, SymmetryWithAGeneralNormalUsesMultiplierRows) {
  const double th = 2.0 * kPi / 3.0;
  const auto s = geometry::k_refine(geometry::cylinder_sector(1.0, 2.0, th), 0, 1, 1, 2);
  const Vec3 n(-std::sin(th), std::cos(th), 0.0);  // normal of the plane through the axis at θ
  KLBoundaryConditions bc(s);
  bc.symmetry_edge(PatchEdge::u1, 3.0 * n);
  const LinearConstraints lc = bc.constraints();
  EXPECT_TRUE(lc.eliminated.empty());
  ASSERT_EQ(lc.multipliers(), 2 * s.n_v());
  const auto row0 = loads::edge_control_points(s, PatchEdge::u1, 0);
  const auto row1 = loads::edge_control_points(s, PatchEdge::u1, 1);
  for (const int a : row0) EXPECT_NEAR(n.dot(s.points[static_cast<std::size_t>(a)]), 0.0, 1e-14);
  // C δ = n·δ_A per row, for a random δ.
  const VecX d = VecX::LinSpaced(bc.dofs(), -1.0, 2.0);
  const VecX Cd = lc.C * d;
  for (int r = 0; r < lc.multipliers(); ++r) {
    const int a = r < s.n_v() ? row0[static_cast<std::size_t>(r)]
                              : row1[static_cast<std::size_t>(r - s.n_v())];
    EXPECT_NEAR(Cd(r), n.dot(d.segment<3>(3 * a)), 1e-14) << r;
  }
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
