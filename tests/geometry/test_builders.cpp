// Geometry builders: exactness of the rational conics (radius error at random parameters),
// orientation, end points, the closed shapes (full cylinder, annulus, spherical cap) and their
// seams, the disc of IGA-thesis Fig. 4.3 and its refined weights (Fig. 4.3b, §4.1.3.2), and
// refinement of the exact shapes keeping them exact.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "isoflex/geometry/builders.hpp"
#include "isoflex/geometry/refinement.hpp"
#include "support/geometry.hpp"

using namespace isoflex;
using namespace isoflex::geometry;
using namespace isoflex::test;

namespace {

// Largest |‖x(ξ) − c‖ − R| over random parameters and the ends, for a curve.
double curve_radius_error(const NurbsCurve& c, const Vec3& center, double R, std::mt19937& g) {
  std::uniform_real_distribution<double> U(0.0, 1.0);
  double e = 0.0;
  for (int k = 0; k < 2000; ++k) {
    const double u = k == 0 ? 0.0 : (k == 1 ? 1.0 : U(g));
    const CurvePoint P = evaluate(c, u);
    e = std::max(e, std::abs((P.x - center).norm() - R));
    // The tangent of a circle is orthogonal to the radius.
    e = std::max(e, std::abs(P.x1.dot(P.x - center)) / P.x1.norm());
  }
  return e;
}

// The knot vector of an arc of n quadratic segments (builders.hpp): 0 0 0, k/n double, 1 1 1.
std::vector<double> arc_knots(int n) {
  std::vector<double> k = {0, 0, 0};
  for (int s = 1; s < n; ++s) k.insert(k.end(), 2, static_cast<double>(s) / n);
  k.insert(k.end(), 3, 1.0);
  return k;
}

// Segments of an arc through `degrees`: one per started 90°.
int started_quarters(double degrees) {
  return static_cast<int>(std::ceil(degrees / 90.0));
}

// Along ξ at fixed η the polar angle of (x, y) grows from 0 to `angle` (unwrapped): the arc runs
// counter-clockwise from +x. Returns the largest error of the end angles (or 1 if it turns back).
double polar_sweep_error(const NurbsSurface& s, double eta, double angle) {
  double prev = 0.0, err = 0.0;
  for (int k = 0; k <= 400; ++k) {
    const Vec3 x = evaluate(s, k / 400.0, eta).x;
    double phi = std::atan2(x.y(), x.x());
    while (phi < prev - 1e-9) phi += 2.0 * kPi;  // unwrap
    if (k == 0) err = std::abs(phi);
    if (k > 0 && !(phi > prev)) return 1.0;
    prev = phi;
  }
  return std::max(err, std::abs(prev - angle));
}

// Whether the control points of the edges ξ = 0 and ξ = 1 are the same, bit for bit.
bool seam_points_equal(const NurbsSurface& s) {
  for (int j = 0; j < s.n_v(); ++j)
    if (s.points[s.index(0, j)] != s.points[s.index(s.n_u() - 1, j)] ||
        s.weights[s.index(0, j)] != s.weights[s.index(s.n_u() - 1, j)])
      return false;
  return true;
}

}  // namespace

TEST(Builders, CircleAndArcsAreExact) {
  std::mt19937 g(41);
  double worst = 0.0;
  const NurbsCurve full = circle(1.0);
  EXPECT_EQ(full.n(), 9);
  EXPECT_EQ(full.knots.knots(),
            (std::vector<double>{0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1}));
  worst = std::max(worst, curve_radius_error(full, Vec3::Zero(), 1.0, g));
  EXPECT_EQ(full.points.front(), full.points.back());  // closed: the same point, bit for bit
  EXPECT_LT((evaluate(full, 0.0).x - evaluate(full, 1.0).x).norm(), 1e-15);
  EXPECT_LT((evaluate(full, 0.25).x - Vec3(0, 1, 0)).norm(), 1e-15);
  for (double sweep : {0.3, kPi / 2, 2.0, kPi, 4.0, 2 * kPi}) {
    const Vec3 c(0.3, -1.2, 0.7);
    const double R = 0.8, start = 0.4;
    const NurbsCurve a = circle_arc(R, start, sweep, c);
    ASSERT_NO_THROW(a.validate());
    const int n_arcs = static_cast<int>(std::ceil(sweep / (kPi / 2) - 1e-12));
    EXPECT_EQ(a.n(), 2 * n_arcs + 1) << sweep;
    const double e = curve_radius_error(a, c, R, g);
    worst = std::max(worst, e);
    EXPECT_LT(e, 1e-14) << "sweep " << sweep;
    const Vec3 end = c + R * Vec3(std::cos(start + sweep), std::sin(start + sweep), 0);
    EXPECT_LT((evaluate(a, 1.0).x - end).norm(), 1e-15);
    // Counter-clockwise: the tangent at the start is R·(−sin, cos)·(positive factor).
    const Vec3 t0 = evaluate(a, 0.0).x1;
    EXPECT_GT(t0.dot(Vec3(-std::sin(start), std::cos(start), 0)), 0.0);
    EXPECT_NEAR(t0.normalized().dot(Vec3(-std::sin(start), std::cos(start), 0)), 1.0, 1e-15);
  }
  // A 90° arc is the textbook single segment: middle weight cos 45°.
  const NurbsCurve q = circle_arc(2.0, 0.0, kPi / 2);
  EXPECT_EQ(q.n(), 3);
  EXPECT_NEAR(q.weights[1], std::sqrt(0.5), 1e-16);
  EXPECT_LT((q.points[1] - Vec3(2, 2, 0)).norm(), 1e-15);
  RecordProperty("worst_radius_error", sci(worst));
}

TEST(Builders, CylinderSectorIsExact) {
  std::mt19937 g(42);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  double worst = 0.0;
  for (double angle : {kPi / 6, kPi / 2, 2 * kPi / 3, kPi}) {
    const double R = 1.3, L = 2.5;
    const NurbsSurface s = cylinder_sector(R, L, angle);
    ASSERT_NO_THROW(s.validate());
    EXPECT_EQ(s.n_u(), angle <= kPi / 2 ? 3 : 5);
    EXPECT_EQ(s.n_v(), 2);
    for (int k = 0; k < 1000; ++k) {
      const double u = U(g), v = U(g);
      const SurfacePoint P = evaluate(s, u, v);
      const double e = std::abs(std::hypot(P.x.x(), P.x.y()) - R);
      worst = std::max(worst, e);
      EXPECT_LT(e, 1e-14) << "angle " << angle;
      EXPECT_NEAR(P.x.z(), v * L, 1e-15);
      // Outward normal: S_ξ × S_η ∥ +(x, y, 0).
      const Vec3 n = P.xu.cross(P.xv).normalized();
      EXPECT_NEAR(n.dot(Vec3(P.x.x(), P.x.y(), 0).normalized()), 1.0, 1e-14);
    }
    const Vec3 end = evaluate(s, 1.0, 1.0).x;
    EXPECT_LT((end - Vec3(R * std::cos(angle), R * std::sin(angle), L)).norm(), 1e-15);
  }
  RecordProperty("worst_radius_error", sci(worst));
}

// Beyond 180° up to the full turn: one segment per started 90°, double knots between them.
TEST(Builders, CylinderSectorsUpToTheFullCylinder) {
  std::mt19937 g(46);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  const double R = 1.3, L = 2.5;
  double worst = 0.0;
  for (double degrees : {200.0, 270.0, 300.0, 360.0}) {
    SCOPED_TRACE(degrees);
    const double angle = degrees / 180.0 * kPi;
    const NurbsSurface s = cylinder_sector(R, L, angle);
    ASSERT_NO_THROW(s.validate());
    const int n = started_quarters(degrees);
    EXPECT_EQ(s.u.knots(), arc_knots(n));
    EXPECT_TRUE(s.u.is_open());
    EXPECT_TRUE(s.v.is_open());
    EXPECT_EQ(s.n_u(), 2 * n + 1);
    for (int k = 0; k < 1000; ++k) {
      const double u = U(g), v = U(g);
      const SurfacePoint P = evaluate(s, u, v);
      const double e = std::abs(std::hypot(P.x.x(), P.x.y()) - R);
      worst = std::max(worst, e);
      EXPECT_LT(e, 1e-14);
      EXPECT_NEAR(P.x.z(), v * L, 1e-15);
      const Vec3 nrm = P.xu.cross(P.xv).normalized();
      EXPECT_NEAR(nrm.dot(Vec3(P.x.x(), P.x.y(), 0).normalized()), 1.0, 1e-14);
    }
    EXPECT_LT(polar_sweep_error(s, 0.3, angle), 1e-14);
    for (double v : {0.0, 0.4, 1.0}) {
      EXPECT_LT((evaluate(s, 0.0, v).x - Vec3(R, 0, v * L)).norm(), 1e-15);
      EXPECT_LT(
          (evaluate(s, 1.0, v).x - Vec3(R * std::cos(angle), R * std::sin(angle), v * L)).norm(),
          1e-15);
    }
    if (degrees == 360.0) {
      // Closed: the edges ξ = 0 and ξ = 1 are one seam, with the same control points and the
      // same tangent (the geometry is smooth across it; the patch is not joined there).
      EXPECT_TRUE(seam_points_equal(s));
      for (double v : {0.0, 0.7}) {
        EXPECT_EQ(evaluate(s, 0.0, v).x, evaluate(s, 1.0, v).x);
        const Vec3 t0 = evaluate(s, 0.0, v).xu, t1 = evaluate(s, 1.0, v).xu;
        EXPECT_LT((t0 - t1).norm(), 1e-14 * t0.norm());
      }
    } else {
      EXPECT_FALSE(seam_points_equal(s));
    }
  }
  // The full cylinder: four 90° segments, the quadrant points at ξ = k/4.
  const NurbsSurface c = cylinder(R, L);
  EXPECT_EQ(c.points, cylinder_sector(R, L, 2.0 * kPi).points);
  EXPECT_EQ(c.u.knots(), arc_knots(4));
  for (int k = 0; k <= 4; ++k)
    EXPECT_LT((evaluate(c, k / 4.0, 0.5).x -
               Vec3(R * std::cos(k * kPi / 2), R * std::sin(k * kPi / 2), L / 2))
                  .norm(),
              1e-15)
        << k;
  RecordProperty("worst_radius_error", sci(worst));
}

// The annulus of Sze et al.'s slit annular plate (inner radius 6, outer radius 10), as a quarter,
// beyond 180° and closed.
TEST(Builders, AnnulusIsExact) {
  std::mt19937 g(47);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  const double ri = 6.0, ro = 10.0;
  double worst = 0.0;
  for (double degrees : {90.0, 200.0, 360.0}) {
    SCOPED_TRACE(degrees);
    const double angle = degrees / 180.0 * kPi;
    const NurbsSurface s = annulus(ri, ro, angle);
    ASSERT_NO_THROW(s.validate());
    const int n = started_quarters(degrees);
    EXPECT_EQ(s.u.knots(), arc_knots(n));
    EXPECT_EQ(s.v.knots(), (std::vector<double>{0, 0, 1, 1}));
    EXPECT_EQ(s.n_u(), 2 * n + 1);
    for (int k = 0; k < 1000; ++k) {
      const double u = U(g), v = U(g);
      const SurfacePoint P = evaluate(s, u, v);
      // η runs inwards: radius ro + η (ri − ro), on the same ray as the outer edge's point.
      const double r = ro + v * (ri - ro);
      const double e = std::abs(P.x.norm() - r);
      worst = std::max(worst, e);
      EXPECT_LT(e, 1e-14);
      EXPECT_EQ(P.x.z(), 0.0);
      EXPECT_LT((P.x - r / ro * evaluate(s, u, 0.0).x).norm(), 1e-14);
      // Normal along +z.
      EXPECT_NEAR(P.xu.cross(P.xv).normalized().z(), 1.0, 1e-15);
      EXPECT_GT(P.xu.cross(P.xv).z(), 0.0);
    }
    for (double v : {0.0, 0.5}) EXPECT_LT(polar_sweep_error(s, v, angle), 1e-14);
    // Edges: ξ = 0 the radial segment on +x, η = 0 the outer circle, η = 1 the inner one.
    for (double t : {0.0, 0.25, 1.0}) {
      EXPECT_LT((evaluate(s, 0.0, t).x - Vec3(ro + t * (ri - ro), 0, 0)).norm(), 1e-14);
      EXPECT_NEAR(evaluate(s, t, 0.0).x.norm(), ro, 1e-14);
      EXPECT_NEAR(evaluate(s, t, 1.0).x.norm(), ri, 1e-14);
    }
    // Closed at 360°: the radial edges ξ = 0 and ξ = 1 coincide (a slit while unjoined).
    EXPECT_EQ(seam_points_equal(s), degrees == 360.0);
    if (degrees == 360.0) {
      for (double v : {0.0, 0.3, 1.0}) EXPECT_EQ(evaluate(s, 0.0, v).x, evaluate(s, 1.0, v).x);
    }
  }
  RecordProperty("worst_radius_error", sci(worst));
}

TEST(Builders, SphericalCapIsExact) {
  std::mt19937 g(48);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  const double R = 2.0;
  double worst = 0.0;
  for (double degrees : {30.0, 90.0, 135.0}) {
    SCOPED_TRACE(degrees);
    const double polar = degrees / 180.0 * kPi;
    const NurbsSurface s = spherical_cap(R, polar);
    ASSERT_NO_THROW(s.validate());
    EXPECT_EQ(s.u.knots(), arc_knots(4));  // the full turn in azimuth
    EXPECT_EQ(s.v.knots(), arc_knots(started_quarters(degrees)));
    for (int k = 0; k < 1000; ++k) {
      const double u = U(g), v = U(g);
      const SurfacePoint P = evaluate(s, u, v);
      const double e = std::abs(P.x.norm() - R);
      worst = std::max(worst, e);
      EXPECT_LT(e, 1e-14);
      // Inside the cap: polar angle ≤ the rim's.
      EXPECT_GE(P.x.z(), R * std::cos(polar) - 1e-14);
      const Vec3 nrm = P.xu.cross(P.xv);
      if (nrm.norm() > 1e-3) {
        EXPECT_NEAR(nrm.normalized().dot(P.x.normalized()), 1.0, 1e-13);
      }
    }
    for (int k = 0; k <= 20; ++k) {
      const double u = k / 20.0;
      // The rim (η = 0) at polar angle `polar`; the pole (η = 1) a point.
      EXPECT_NEAR(evaluate(s, u, 0.0).x.z(), R * std::cos(polar), 1e-14);
      EXPECT_NEAR(evaluate(s, u, 0.0).x.head<2>().norm(), R * std::sin(polar), 1e-14);
      EXPECT_LT((evaluate(s, u, 1.0).x - Vec3(0, 0, R)).norm(), 1e-15);
    }
    // The pole row of control points is collapsed to one point (sphere_sector at a pole).
    for (int i = 1; i < s.n_u(); ++i)
      EXPECT_LT((s.points[s.index(i, s.n_v() - 1)] - s.points[s.index(0, s.n_v() - 1)]).norm(),
                1e-15);
    EXPECT_TRUE(seam_points_equal(s));
  }
  // 90° is the hemisphere, control point for control point.
  EXPECT_EQ(spherical_cap(R, kPi / 2).points, hemisphere(R).points);
  RecordProperty("worst_radius_error", sci(worst));
}

TEST(Builders, SphereSectorsAreExact) {
  std::mt19937 g(43);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  const double R = 0.9;
  double worst = 0.0;
  struct Case {
    NurbsSurface s;
    int nu, nv;
  };
  const Case cases[] = {{sphere_octant(R), 3, 3},
                        {hemisphere(R), 9, 3},
                        {sphere_sector(R, 2.0, -1.2, 0.7), 5, 5},
                        {sphere_sector(R, 2 * kPi, -kPi / 2, kPi / 2), 9, 5}};
  for (const Case& c : cases) {
    ASSERT_NO_THROW(c.s.validate());
    EXPECT_EQ(c.s.n_u(), c.nu);
    EXPECT_EQ(c.s.n_v(), c.nv);
    for (int k = 0; k < 1000; ++k) {
      const double u = U(g), v = U(g);
      const SurfacePoint P = evaluate(c.s, u, v);
      const double e = std::abs(P.x.norm() - R);
      worst = std::max(worst, e);
      EXPECT_LT(e, 1e-14);
      // Outward normal (away from the poles, where S_ξ vanishes).
      const Vec3 n = P.xu.cross(P.xv);
      if (n.norm() > 1e-3) {
        EXPECT_NEAR(n.normalized().dot(P.x.normalized()), 1.0, 1e-13);
      }
    }
  }
  // The octant lies in x, y, z ≥ 0 with its corners on the axes and the pole.
  const NurbsSurface o = sphere_octant(R);
  EXPECT_LT((evaluate(o, 0, 0).x - Vec3(R, 0, 0)).norm(), 1e-15);
  EXPECT_LT((evaluate(o, 1, 0).x - Vec3(0, R, 0)).norm(), 1e-15);
  EXPECT_LT((evaluate(o, 0.3, 1).x - Vec3(0, 0, R)).norm(), 1e-15);
  for (int k = 0; k < 100; ++k) EXPECT_GE(evaluate(o, U(g), U(g)).x.minCoeff(), -1e-16);
  RecordProperty("worst_radius_error", sci(worst));
}

TEST(Builders, DiscOfThesisFigure43) {
  std::mt19937 g(44);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  const double R = 1.0, s2 = 1.0 / std::sqrt(2.0);
  const NurbsSurface d = disc(R);
  ASSERT_NO_THROW(d.validate());
  // Fig. 4.3a: knots (0,0,0,1,1,1), w00 = w02 = w11 = w20 = w22 = 1, the others 1/√2.
  EXPECT_EQ(d.u.knots(), (std::vector<double>{0, 0, 0, 1, 1, 1}));
  EXPECT_EQ(d.v.knots(), d.u.knots());
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i)
      EXPECT_NEAR(d.weights[d.index(i, j)], (i + j) % 2 == 0 ? 1.0 : s2, 1e-16) << i << j;
  // Boundary edges on the circle, interior inside, all in the plane z = 0.
  double worst = 0.0;
  for (int k = 0; k < 500; ++k) {
    const double t = U(g);
    for (auto [u, v] : {std::pair{t, 0.0}, {t, 1.0}, {0.0, t}, {1.0, t}}) {
      const double e = std::abs(evaluate(d, u, v).x.norm() - R);
      worst = std::max(worst, e);
      EXPECT_LT(e, 1e-14);
    }
    const SurfacePoint P = evaluate(d, U(g), U(g));
    EXPECT_LT(P.x.norm(), R);
    EXPECT_EQ(P.x.z(), 0.0);
    EXPECT_GT(P.xu.cross(P.xv).z(), 0.0);  // oriented along +z, no fold inside
  }
  EXPECT_LT(evaluate(d, 0.5, 0.5).x.norm(), 1e-16);
  // Fig. 4.3b: one knot 0.5 in each direction → 4 × 4 = 16 control points (§4.1.4), corner
  // weights 1 and all others (1 + 1/√2)/2 (the thesis lists w22 also among the 1s — a typo,
  // as w22 is interior; all twelve others and the four inner ones are (1 + 1/√2)/2).
  const NurbsSurface r = refine_knots(refine_knots(d, Direction::u, {0.5}), Direction::v, {0.5});
  EXPECT_EQ(r.u.knots(), (std::vector<double>{0, 0, 0, 0.5, 1, 1, 1}));
  EXPECT_EQ(r.n_u() * r.n_v(), 16);
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) {
      const bool corner = (i == 0 || i == 3) && (j == 0 || j == 3);
      EXPECT_NEAR(r.weights[r.index(i, j)], corner ? 1.0 : (1.0 + s2) / 2.0, 1e-15) << i << j;
    }
  for (int k = 0; k < 200; ++k) {
    const double u = U(g), v = U(g);
    EXPECT_LT((evaluate(r, u, v).x - evaluate(d, u, v).x).norm(), 1e-15);
  }
  RecordProperty("worst_radius_error", sci(worst));
}

TEST(Builders, PlanarRectangle) {
  const Vec3 c(1, 2, 3), eu(2, 0.5, 0), ev(-0.3, 1, 0.4);
  const NurbsSurface s = planar_rectangle(c, eu, ev);
  ASSERT_NO_THROW(s.validate());
  EXPECT_FALSE(s.is_rational());
  for (double u : {0.0, 0.3, 1.0})
    for (double v : {0.0, 0.55, 1.0}) {
      const SurfacePoint P = evaluate(s, u, v);
      EXPECT_LT((P.x - (c + u * eu + v * ev)).norm(), 1e-15);
      EXPECT_LT((P.xu - eu).norm(), 1e-15);
      EXPECT_LT((P.xv - ev).norm(), 1e-15);
      EXPECT_EQ(P.xuu.norm() + P.xuv.norm() + P.xvv.norm(), 0.0);
    }
  const NurbsSurface r = planar_rectangle(3.0, 2.0);
  EXPECT_LT((evaluate(r, 1, 1).x - Vec3(3, 2, 0)).norm(), 1e-15);
  EXPECT_GT(evaluate(r, 0.5, 0.5).xu.cross(evaluate(r, 0.5, 0.5).xv).z(), 0.0);
}

TEST(Builders, RefinedExactShapesStayExact) {
  std::mt19937 g(45);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  const NurbsSurface cyl = k_refine(cylinder_sector(1.0, 2.0, kPi), 1, 2, 3, 4);
  const NurbsSurface sph = k_refine(sphere_octant(1.0), 2, 1, 2, 2);
  const NurbsCurve circ = k_refine(circle(1.0), 3, 2);
  EXPECT_EQ(cyl.degree_u(), 3);
  EXPECT_EQ(cyl.degree_v(), 3);
  // Cylinder: ξ (0,0,0,½,½,1,1,1) elevated by 1 → n_u = 5 + 1·(1 + 1) = 7, plus 3 knots in each
  // of 2 spans → 13; η linear elevated by 2 → 4, plus 4 knots → 8.
  EXPECT_EQ(cyl.n_u(), 13);
  EXPECT_EQ(cyl.n_v(), 8);
  double worst = 0.0;
  for (int k = 0; k < 1000; ++k) {
    const double u = U(g), v = U(g);
    const Vec3 x = evaluate(cyl, u, v).x;
    worst = std::max({worst, std::abs(std::hypot(x.x(), x.y()) - 1.0),
                      std::abs(evaluate(sph, u, v).x.norm() - 1.0),
                      std::abs(evaluate(circ, u).x.norm() - 1.0)});
  }
  EXPECT_LT(worst, 1e-14);
  RecordProperty("worst_radius_error", sci(worst));
}

// k-refinement of the closed shapes keeps them exact and closed; the double knots between the
// 90° segments stay C⁰ (multiplicity = degree) after elevation.
TEST(Builders, ClosedShapesStayExactUnderRefinement) {
  std::mt19937 g(49);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  const NurbsSurface cyl = k_refine(cylinder(1.0, 2.0), 1, 1, 3, 2);
  const NurbsSurface ann = k_refine(annulus(6.0, 10.0, 2.0 * kPi), 1, 1, 2, 3);
  const NurbsSurface cap = k_refine(spherical_cap(2.0, 0.75 * kPi), 2, 1, 2, 2);
  EXPECT_EQ(cyl.degree_u(), 3);
  // ξ: 9 points + 1 per distinct knot but one (4 spans → 5 distinct) + 3 per span: 9 + 4 + 12.
  EXPECT_EQ(cyl.n_u(), 25);
  for (const NurbsSurface* s : {&cyl, &ann, &cap})
    for (double k : {0.25, 0.5, 0.75}) EXPECT_EQ(s->u.multiplicity(k), s->degree_u()) << k;
  EXPECT_EQ(cap.v.multiplicity(0.5), cap.degree_v());  // the meridian of 135°: two segments
  double worst = 0.0;
  for (int k = 0; k < 1000; ++k) {
    const double u = U(g), v = U(g);
    const Vec3 xc = evaluate(cyl, u, v).x, xa = evaluate(ann, u, v).x;
    worst = std::max({worst, std::abs(std::hypot(xc.x(), xc.y()) - 1.0),
                      std::abs(xa.norm() - (10.0 - 4.0 * v)),
                      std::abs(evaluate(cap, u, v).x.norm() - 2.0)});
  }
  EXPECT_LT(worst, 1e-14);
  for (const NurbsSurface* s : {&cyl, &ann, &cap})
    for (int j = 0; j < s->n_v(); ++j)
      EXPECT_LT((s->points[s->index(0, j)] - s->points[s->index(s->n_u() - 1, j)]).norm(), 1e-14);
  RecordProperty("worst_radius_error", sci(worst));
}

TEST(Builders, InvalidInputThrowsWithClearMessage) {
  EXPECT_NE(message_of([] { circle(-1.0); }).find("radius = -1 must be positive"),
            std::string::npos);
  EXPECT_NE(message_of([] { circle_arc(1.0, 0.0, 0.0); }).find("sweep = 0 outside (0, 2π]"),
            std::string::npos);
  EXPECT_NE(message_of([] { circle_arc(1.0, 0.0, 7.0); }).find("sweep = 7"), std::string::npos);
  EXPECT_NE(message_of([] { cylinder_sector(1.0, 2.0, 7.0); }).find("angle = 7 outside (0, 2π]"),
            std::string::npos);
  EXPECT_EQ(message_of([] { cylinder_sector(1.0, 2.0, 2.0 * kPi); }), "");
  EXPECT_NE(message_of([] { cylinder(1.0, 0.0); }).find("length = 0 must be positive"),
            std::string::npos);
  EXPECT_NE(message_of([] {
              annulus(6.0, 6.0, 1.0);
            }).find("inner_radius = 6 must be smaller than outer_radius = 6"),
            std::string::npos);
  EXPECT_NE(message_of([] { annulus(-1.0, 6.0, 1.0); }).find("inner_radius = -1 must be positive"),
            std::string::npos);
  EXPECT_NE(message_of([] { annulus(1.0, 2.0, 0.0); }).find("angle = 0 outside (0, 2π]"),
            std::string::npos);
  EXPECT_NE(message_of([] { spherical_cap(1.0, kPi); }).find("outside (0, π)"), std::string::npos);
  EXPECT_NE(message_of([] { spherical_cap(1.0, 0.0); }).find("polar_angle = 0 outside"),
            std::string::npos);
  EXPECT_NE(message_of([] { cylinder_sector(1.0, std::nan(""), 1.0); }).find("length = nan"),
            std::string::npos);
  EXPECT_NE(message_of([] { sphere_sector(1.0, 1.0, 0.5, 0.2); }).find("latitudes"),
            std::string::npos);
  EXPECT_NE(message_of([] { sphere_sector(1.0, 1.0, -2.0, 0.2); }).find("latitudes"),
            std::string::npos);
  EXPECT_NE(message_of([] {
              planar_rectangle(Vec3::Zero(), Vec3(1, 0, 0), Vec3(2, 0, 0));
            }).find("parallel"),
            std::string::npos);
  EXPECT_NE(message_of([] { planar_rectangle(0.0, 1.0); }).find("lx = 0"), std::string::npos);
  EXPECT_NE(message_of([] { disc(0.0); }).find("radius = 0"), std::string::npos);
}
