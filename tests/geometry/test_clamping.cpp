// Clamping (geometry/clamping.hpp): a curve or surface with a knot vector that is not open — an
// unclamped uniform B-spline, a periodic rational closed one, an end knot more than p+1-fold —
// becomes one with open knot vectors and the same geometry and parametrization on the same
// domain (positions and parametric derivatives at many parameters); the knot vectors after are
// the ones worked out by hand here. Open knot vectors are left alone.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "isoflex/geometry/clamping.hpp"
#include "isoflex/geometry/refinement.hpp"
#include "support/geometry.hpp"

using namespace isoflex;
using namespace isoflex::geometry;
using namespace isoflex::test;

namespace {

// Uniform knots 0, 1, …, count − 1 (unclamped: the domain is [p, count − 1 − p]).
KnotVector uniform_knots(int p, int count) {
  std::vector<double> k;
  for (int i = 0; i < count; ++i) k.push_back(i);
  return KnotVector(p, k);
}

// A closed, periodic rational quadratic: m control points on a regular m-gon of radius ρ about
// `centre` in the xy-plane, the first p repeated at the end, weights alternating 1 and 0.7 (a
// "circle-like" closed curve, C¹ everywhere including the seam), on uniform knots 0 … m + 2p.
NurbsCurve periodic_ring(int m, double rho, const Vec3& centre) {
  const int p = 2;
  NurbsCurve c;
  c.knots = uniform_knots(p, m + 2 * p + 1);
  for (int i = 0; i < m + p; ++i) {
    const double t = 2.0 * kPi * (i % m) / m;
    c.points.push_back(centre + rho * Vec3(std::cos(t), std::sin(t), 0.0));
    c.weights.push_back((i % m) % 2 == 0 ? 1.0 : 0.7);
  }
  return c;
}

// Largest difference of position and first and second derivatives (relative to their size) of
// a and b at random parameters of a's domain and at its ends.
double max_difference(const NurbsCurve& a, const NurbsCurve& b, std::mt19937& g) {
  std::uniform_real_distribution<double> U(a.knots.front(), a.knots.back());
  double d = 0.0;
  for (int k = 0; k < 500; ++k) {
    const double u = k == 0 ? a.knots.front() : (k == 1 ? a.knots.back() : U(g));
    const CurvePoint pa = evaluate(a, u), pb = evaluate(b, u);
    d = std::max({d, (pa.x - pb.x).norm(), (pa.x1 - pb.x1).norm() / std::max(1.0, pa.x1.norm()),
                  (pa.x2 - pb.x2).norm() / std::max(1.0, pa.x2.norm())});
  }
  return d;
}

double max_difference(const NurbsSurface& a, const NurbsSurface& b, std::mt19937& g) {
  std::uniform_real_distribution<double> U(a.u.front(), a.u.back());
  std::uniform_real_distribution<double> V(a.v.front(), a.v.back());
  double d = 0.0;
  for (int k = 0; k < 1000; ++k) {
    // The four corners first, then random points.
    const double u = k < 4 ? (k & 1 ? a.u.back() : a.u.front()) : U(g);
    const double v = k < 4 ? (k & 2 ? a.v.back() : a.v.front()) : V(g);
    const SurfacePoint pa = evaluate(a, u, v), pb = evaluate(b, u, v);
    d = std::max(d, (pa.x - pb.x).norm());
    for (auto [x, y] : {std::pair{&pa.xu, &pb.xu},
                        {&pa.xv, &pb.xv},
                        {&pa.xuu, &pb.xuu},
                        {&pa.xuv, &pb.xuv},
                        {&pa.xvv, &pb.xvv}})
      d = std::max(d, (*x - *y).norm() / std::max(1.0, x->norm()));
  }
  return d;
}

}  // namespace

TEST(Clamping, UnclampedUniformCubicCurve) {
  std::mt19937 g(71);
  NurbsCurve c = random_nurbs_curve(g, uniform_knots(3, 11), false, 1.0, 1.0);  // 7 points
  ASSERT_FALSE(c.knots.is_open());
  EXPECT_EQ(c.knots.front(), 3.0);
  EXPECT_EQ(c.knots.back(), 7.0);
  const NurbsCurve k = clamped(c);
  ASSERT_NO_THROW(k.validate());
  EXPECT_TRUE(k.knots.is_open());
  // The domain's ends 4-fold, the interior knots 4, 5, 6 kept: 11 knots, 7 control points.
  EXPECT_EQ(k.knots.knots(), (std::vector<double>{3, 3, 3, 3, 4, 5, 6, 7, 7, 7, 7}));
  EXPECT_EQ(k.n(), 7);
  const double d = max_difference(c, k, g);
  EXPECT_LT(d, 1e-13);
  // Open: the ends interpolate the end control points.
  EXPECT_LT((k.points.front() - evaluate(c, 3.0).x).norm(), 1e-14);
  EXPECT_LT((k.points.back() - evaluate(c, 7.0).x).norm(), 1e-14);
  RecordProperty("max_difference", sci(d));
}

TEST(Clamping, PeriodicRationalClosedCurve) {
  std::mt19937 g(72);
  const NurbsCurve c = periodic_ring(8, 1.5, Vec3(0.2, -0.1, 0.4));  // 10 points, knots 0 … 12
  ASSERT_FALSE(c.knots.is_open());
  // Periodic: closed, and C¹ across the seam (the same tangent at both ends of the domain).
  EXPECT_LT((evaluate(c, 2.0).x - evaluate(c, 10.0).x).norm(), 1e-15);
  EXPECT_LT((evaluate(c, 2.0).x1 - evaluate(c, 10.0).x1).norm(), 1e-14);
  const NurbsCurve k = clamped(c);
  ASSERT_NO_THROW(k.validate());
  EXPECT_TRUE(k.knots.is_open());
  EXPECT_EQ(k.knots.knots(), (std::vector<double>{2, 2, 2, 3, 4, 5, 6, 7, 8, 9, 10, 10, 10}));
  EXPECT_EQ(k.n(), 10);
  EXPECT_TRUE(k.is_rational());
  const double d = max_difference(c, k, g);
  EXPECT_LT(d, 1e-13);
  // Closed and clamped: the first and last control points are the same point, the seam.
  EXPECT_LT((k.points.front() - k.points.back()).norm(), 1e-15);
  EXPECT_NEAR(k.weights.front(), k.weights.back(), 1e-15);
  RecordProperty("max_difference", sci(d));
}

TEST(Clamping, EndKnotMoreThanPPlusOneFold) {
  // Degree 2 with a 4-fold start knot: N_0 has the support [0, 0] and vanishes on the domain.
  std::mt19937 g(73);
  const NurbsCurve c =
      random_nurbs_curve(g, KnotVector(2, {0, 0, 0, 0, 1, 2, 2, 2}), true, 0.5, 2.0);
  ASSERT_FALSE(c.knots.is_open());
  const NurbsCurve k = clamped(c);
  EXPECT_EQ(k.knots.knots(), (std::vector<double>{0, 0, 0, 1, 2, 2, 2}));
  ASSERT_EQ(k.n(), 4);
  // Nothing inserted: the other control points as they were, to the round-off of the trip
  // through homogeneous coordinates (w P / w is exact in some builds, one ulp off in others).
  for (int i = 0; i < 4; ++i) {
    EXPECT_LT((k.points[i] - c.points[i + 1]).norm(), 1e-15 * c.points[i + 1].norm());
    EXPECT_NEAR(k.weights[i], c.weights[i + 1], 1e-15 * c.weights[i + 1]);
  }
  EXPECT_LT(max_difference(c, k, g), 1e-14);
}

TEST(Clamping, OpenKnotVectorsAreLeftAlone) {
  std::mt19937 g(74);
  const NurbsSurface s =
      random_nurbs_surface(g, random_knots(g, 3, 3), random_knots(g, 2, 2), true, 0.5, 2.0);
  const NurbsSurface k = clamped(s);
  EXPECT_EQ(k.u.knots(), s.u.knots());
  EXPECT_EQ(k.v.knots(), s.v.knots());
  EXPECT_EQ(k.points, s.points);
  EXPECT_EQ(k.weights, s.weights);
}

TEST(Clamping, UnclampedUniformSurfaceInBothDirections) {
  std::mt19937 g(75);
  // u: cubic, knots 0 … 10 (7 functions, domain [3, 7]); v: quadratic, knots 0 … 7 (5
  // functions, domain [2, 5]); rational.
  const NurbsSurface s =
      random_nurbs_surface(g, uniform_knots(3, 11), uniform_knots(2, 8), true, 0.5, 2.0);
  const NurbsSurface k = clamped(s);
  ASSERT_NO_THROW(k.validate());
  EXPECT_TRUE(k.u.is_open());
  EXPECT_TRUE(k.v.is_open());
  EXPECT_EQ(k.u.knots(), (std::vector<double>{3, 3, 3, 3, 4, 5, 6, 7, 7, 7, 7}));
  EXPECT_EQ(k.v.knots(), (std::vector<double>{2, 2, 2, 3, 4, 5, 5, 5}));
  EXPECT_EQ(k.n_u(), 7);
  EXPECT_EQ(k.n_v(), 5);
  const double d = max_difference(s, k, g);
  EXPECT_LT(d, 1e-12);
  // One direction only: the other knot vector stays as it was.
  const NurbsSurface ku = clamped(s, Direction::u);
  EXPECT_EQ(ku.u.knots(), k.u.knots());
  EXPECT_EQ(ku.v.knots(), s.v.knots());
  EXPECT_LT(max_difference(s, ku, g), 1e-12);
  RecordProperty("max_difference", sci(d));
}

TEST(Clamping, PeriodicRationalTubeThenRefined) {
  // A closed tube: the periodic ring of PeriodicRationalClosedCurve in u (rational), scaled and
  // lifted along z by a linear open v.
  std::mt19937 g(76);
  const NurbsCurve ring = periodic_ring(6, 2.0, Vec3::Zero());  // 8 points, knots 0 … 10
  NurbsSurface s;
  s.u = ring.knots;
  s.v = KnotVector(1, {0, 0, 1, 1});
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < ring.n(); ++i) {
      s.points.push_back((1.0 + 0.5 * j) * ring.points[i] + Vec3(0, 0, 3.0 * j));
      s.weights.push_back(ring.weights[i]);
    }
  const NurbsSurface k = clamped(s);
  EXPECT_EQ(k.u.knots(), (std::vector<double>{2, 2, 2, 3, 4, 5, 6, 7, 8, 8, 8}));
  EXPECT_EQ(k.v.knots(), s.v.knots());
  const double d = max_difference(s, k, g);
  EXPECT_LT(d, 1e-13);
  // The seam edges u = 2 and u = 8 of the clamped surface have the same control points.
  for (int j = 0; j < k.n_v(); ++j)
    EXPECT_LT((k.points[k.index(0, j)] - k.points[k.index(k.n_u() - 1, j)]).norm(), 1e-14);
  // Clamped, the surface can be k-refined (elevation needs an open knot vector) and stays the
  // same surface.
  EXPECT_THROW(k_refine(s, 1, 1, 1, 1), std::invalid_argument);
  const NurbsSurface r = k_refine(k, 1, 1, 2, 2);
  EXPECT_EQ(r.degree_u(), 3);
  EXPECT_LT(max_difference(s, r, g), 1e-12);
  RecordProperty("max_difference", sci(d));
}

TEST(Clamping, InvalidInputThrows) {
  NurbsCurve c = periodic_ring(5, 1.0, Vec3::Zero());
  c.weights[2] = -1.0;
  EXPECT_NE(message_of([&] { clamped(c); }).find("weight"), std::string::npos);
}
