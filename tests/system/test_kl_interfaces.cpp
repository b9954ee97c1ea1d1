// Interfaces between Kirchhoff–Love patches (system/kl_interfaces.hpp, IGA-thesis §4.4): found
// from the geometry alone, in either orientation and at any angle; made conforming by degree
// elevation and knot insertion without changing the surfaces; the triples across them; and a
// located error for edges that meet but cannot be joined control point to control point.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "isoflex/geometry/builders.hpp"
#include "isoflex/geometry/refinement.hpp"
#include "isoflex/system/kl_interfaces.hpp"

using namespace isoflex;
using geometry::NurbsSurface;
using loads::PatchEdge;

namespace {

// A rectangle corner + ξ e_u + η e_v, degrees (p, q), k knots per span in each direction.
NurbsSurface plate(const Vec3& corner, const Vec3& eu, const Vec3& ev, int p, int q, int ku,
                   int kv) {
  return geometry::k_refine(geometry::planar_rectangle(corner, eu, ev), p - 1, q - 1, ku, kv);
}

const std::vector<std::string> kNames = {"left", "right", "third"};

std::vector<std::string> names(std::size_t n) {
  return {kNames.begin(), kNames.begin() + n};
}

// How many control points lie in groups of more than one (joined points).
int joined_points(const system::KLPatchJoining& J) {
  std::map<int, int> size;
  for (const auto& g : J.point_group)
    for (int id : g) ++size[id];
  int out = 0;
  for (const auto& [id, n] : size) out += n > 1 ? n : 0;
  return out;
}

}  // namespace

// Two plates side by side, [0, 5] × [0, 1] and [5, 10] × [0, 1], bicubic × quadratic: one
// interface, a's u1 against b's u0, in the same direction, flat (180°), one triple per control
// point along the edge (4 = q + 1 + 1 knot), those pairs joined, nothing refined.
TEST(KLInterfaces, TwoPlatesSideBySideShareOneEdge) {
  const NurbsSurface a = plate(Vec3::Zero(), Vec3(5, 0, 0), Vec3(0, 1, 0), 3, 2, 2, 1);
  const NurbsSurface b = plate(Vec3(5, 0, 0), Vec3(5, 0, 0), Vec3(0, 1, 0), 3, 2, 2, 1);
  const system::KLPatchJoining J = system::join_kl_patches({a, b}, 1e-6, names(2));
  ASSERT_EQ(J.interfaces.size(), 1u);
  const system::KLInterface& f = J.interfaces[0];
  EXPECT_EQ(f.a, 0);
  EXPECT_EQ(f.b, 1);
  EXPECT_EQ(f.edge_a, PatchEdge::u1);
  EXPECT_EQ(f.edge_b, PatchEdge::u0);
  EXPECT_FALSE(f.reversed);
  EXPECT_EQ(f.triples(), 4);
  EXPECT_NEAR(f.angle_min, 180.0, 1e-12);
  EXPECT_NEAR(f.angle_max, 180.0, 1e-12);
  EXPECT_TRUE(J.refinements.empty());
  EXPECT_EQ(joined_points(J), 8);
  EXPECT_NEAR(J.tolerance, 1e-6 * std::sqrt(101.0), 1e-15);
  for (int k = 0; k < f.triples(); ++k) {
    EXPECT_EQ(J.point_group[0][f.shared_a[k]], J.point_group[1][f.shared_b[k]]);
    // The triple runs across the interface: a's inner row, the shared point, b's inner row.
    const Vec3 xa = J.surfaces[0].points[f.inner_a[k]], x = J.surfaces[0].points[f.shared_a[k]],
               xb = J.surfaces[1].points[f.inner_b[k]];
    EXPECT_LT(xa.x(), x.x());
    EXPECT_GT(xb.x(), x.x());
    EXPECT_NEAR(xa.y(), x.y(), 1e-14);
    EXPECT_NEAR(xb.y(), x.y(), 1e-14);
  }
}

// An L: the second plate stands up at x = 5 (its ξ along −y, so its edge v0 runs against the
// first's u1) — found as reversed, at 90°; three plates around one edge give three interfaces and
// one point group per control point of the edge.
TEST(KLInterfaces, ReversedEdgesAtAnAngleAndThreePatchesOnOneEdge) {
  const NurbsSurface a = plate(Vec3::Zero(), Vec3(5, 0, 0), Vec3(0, 1, 0), 3, 3, 1, 1);
  const NurbsSurface up = plate(Vec3(5, 1, 0), Vec3(0, -1, 0), Vec3(0, 0, 2), 3, 3, 1, 2);
  const system::KLPatchJoining J = system::join_kl_patches({a, up}, 1e-6, names(2));
  ASSERT_EQ(J.interfaces.size(), 1u);
  const system::KLInterface& f = J.interfaces[0];
  EXPECT_EQ(f.edge_a, PatchEdge::u1);
  EXPECT_EQ(f.edge_b, PatchEdge::v0);
  EXPECT_TRUE(f.reversed);
  EXPECT_NEAR(f.angle_min, 90.0, 1e-12);
  EXPECT_NEAR(f.angle_max, 90.0, 1e-12);
  for (int k = 0; k < f.triples(); ++k)
    EXPECT_LT((J.surfaces[0].points[f.shared_a[k]] - J.surfaces[1].points[f.shared_b[k]]).norm(),
              1e-15);

  const NurbsSurface down = plate(Vec3(5, 0, 0), Vec3(0, 0, -1), Vec3(0, 1, 0), 2, 3, 0, 1);
  const system::KLPatchJoining T = system::join_kl_patches({a, up, down}, 1e-6, names(3));
  ASSERT_EQ(T.interfaces.size(), 3u);
  std::set<int> groups;
  for (int id : T.point_group[0]) groups.insert(id);
  for (int id : T.point_group[1]) groups.insert(id);
  for (int id : T.point_group[2]) groups.insert(id);
  const int total = static_cast<int>(a.points.size() + up.points.size() + down.points.size());
  EXPECT_EQ(static_cast<int>(groups.size()), total - 2 * T.interfaces[0].triples());
}

// Non-matching discretizations of one edge: the right plate quadratic along the edge with 3
// knots per span, the left cubic with 1. Both get degree 3 and the union of the knots along the
// edge; the surfaces are the same functions as before (checked at points, also off the edge).
TEST(KLInterfaces, DegreeAndKnotsAreMadeToMatchWithoutChangingTheSurfaces) {
  const NurbsSurface a = plate(Vec3::Zero(), Vec3(5, 0, 0), Vec3(0, 1, 0), 3, 3, 1, 1);
  const NurbsSurface b = plate(Vec3(5, 0, 0), Vec3(5, 0, 0), Vec3(0, 1, 0), 2, 2, 1, 3);
  const system::KLPatchJoining J = system::join_kl_patches({a, b}, 1e-6, names(2));
  ASSERT_EQ(J.interfaces.size(), 1u);
  EXPECT_EQ(J.surfaces[1].degree_v(), 3);
  EXPECT_EQ(J.surfaces[0].v.knots(), J.surfaces[1].v.knots());
  EXPECT_EQ(J.surfaces[1].degree_u(), 2);  // across the edge: untouched
  EXPECT_EQ(J.interfaces[0].triples(), J.surfaces[1].n_v());
  ASSERT_GE(J.refinements.size(), 2u);
  for (const std::string& r : J.refinements) std::printf("  %s\n", r.c_str());
  double worst = 0.0;
  for (double xi : {0.0, 0.3, 0.77, 1.0})
    for (double eta : {0.0, 0.15, 0.5, 0.9}) {
      worst = std::max(
          worst,
          (geometry::evaluate(J.surfaces[0], xi, eta).x - geometry::evaluate(a, xi, eta).x).norm());
      worst = std::max(
          worst,
          (geometry::evaluate(J.surfaces[1], xi, eta).x - geometry::evaluate(b, xi, eta).x).norm());
    }
  EXPECT_LT(worst, 1e-13);
}

// Edges that meet but cannot be joined control point to control point are located errors naming
// both edges: a plate whose edge covers half of its neighbour's (a T-junction), and the same
// straight edge parametrized differently (control points moved along it).
TEST(KLInterfaces, EdgesThatCannotBeJoinedAreLocatedErrors) {
  const NurbsSurface a = plate(Vec3::Zero(), Vec3(5, 0, 0), Vec3(0, 1, 0), 2, 2, 1, 1);
  const NurbsSurface half = plate(Vec3(5, 0, 0), Vec3(5, 0, 0), Vec3(0, 0.5, 0), 2, 2, 1, 1);
  try {
    system::join_kl_patches({a, half}, 1e-6, names(2));
    ADD_FAILURE() << "no error for a T-junction";
  } catch (const system::KLInterfaceError& e) {
    EXPECT_EQ(e.patch_a, 0);
    EXPECT_EQ(e.patch_b, 1);
    const std::string msg = e.what();
    EXPECT_NE(msg.find("\"right\" edge u0 lies along part of \"left\" edge u1"), std::string::npos)
        << msg;
  }
  NurbsSurface skewed = plate(Vec3(5, 0, 0), Vec3(5, 0, 0), Vec3(0, 1, 0), 2, 2, 1, 1);
  for (int A : loads::edge_control_points(skewed, PatchEdge::u0, 0))
    if (skewed.points[A].y() > 0.0 && skewed.points[A].y() < 1.0) skewed.points[A].y() *= 0.8;
  try {
    system::join_kl_patches({a, skewed}, 1e-6, names(2));
    ADD_FAILURE() << "no error for a different parametrization";
  } catch (const system::KLInterfaceError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("parametrized differently"), std::string::npos) << msg;
  }
  EXPECT_THROW(system::join_kl_patches({a, half}, 0.5, names(2)), std::invalid_argument);
}

// Patches that touch only at a corner, or lie apart, or meet along a collapsed edge, have no
// interface; points closer than the tolerance are moved to their mean.
TEST(KLInterfaces, CornersAndGapsAreNoInterfaceAndNearPointsAreSnapped) {
  const NurbsSurface a = plate(Vec3::Zero(), Vec3(5, 0, 0), Vec3(0, 1, 0), 2, 2, 1, 1);
  const NurbsSurface corner = plate(Vec3(5, 1, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), 2, 2, 0, 0);
  const NurbsSurface apart = plate(Vec3(5.01, 0, 0), Vec3(5, 0, 0), Vec3(0, 1, 0), 2, 2, 1, 1);
  EXPECT_TRUE(system::join_kl_patches({a, corner}, 1e-6, names(2)).interfaces.empty());
  EXPECT_TRUE(system::join_kl_patches({a, apart}, 1e-6, names(2)).interfaces.empty());
  NurbsSurface near = plate(Vec3(5, 0, 0), Vec3(5, 0, 0), Vec3(0, 1, 0), 2, 2, 1, 1);
  near.points[0].x() += 1e-7;  // the tolerance is 1e-6 × √101 ≈ 1e-5
  const system::KLPatchJoining J = system::join_kl_patches({a, near}, 1e-6, names(2));
  ASSERT_EQ(J.interfaces.size(), 1u);
  const int A = J.interfaces[0].shared_a[0], B = J.interfaces[0].shared_b[0];
  EXPECT_EQ(J.surfaces[0].points[A], J.surfaces[1].points[B]);
  EXPECT_NEAR(J.surfaces[1].points[B].x(), 5.0 + 0.5e-7, 1e-15);
}
