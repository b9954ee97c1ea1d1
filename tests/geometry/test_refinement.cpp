// Refinement (IGA-thesis §4.1.4, §4.2.2): knot insertion, knot refinement, degree elevation,
// uniform h- and k-refinement leave curves and surfaces unchanged (positions and parametric
// derivatives at random points), and produce the knot vectors and control-point counts the
// definitions predict (worked out here independently of the algorithms).
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <string>

#include "isoflex/geometry/nurbs_curve.hpp"
#include "isoflex/geometry/nurbs_surface.hpp"
#include "isoflex/geometry/refinement.hpp"
#include "support/finite_difference.hpp"
#include "support/geometry.hpp"

using namespace isoflex;
using namespace isoflex::geometry;
using namespace isoflex::test;

namespace {

// This file's random curves and surfaces: knots on [0, 1] drawn from [0.05, 0.95], weights in
// [0.4, 2].
NurbsCurve random_curve(std::mt19937& g, int p, int n_interior, bool rational) {
  return random_nurbs_curve(g, random_knots(g, p, n_interior, 0.0, 1.0, 0.05, 0.95), rational, 0.4,
                            2.0);
}

NurbsSurface random_surface(std::mt19937& g, int p, int q, bool rational) {
  KnotVector u = random_knots(g, p, 2, 0.0, 1.0, 0.05, 0.95);
  KnotVector v = random_knots(g, q, 3, 0.0, 1.0, 0.05, 0.95);
  return random_nurbs_surface(g, std::move(u), std::move(v), rational, 0.4, 2.0);
}

// Largest deviation of b from a at random parameters (and the domain corners): position
// (absolute) and first/second derivatives (relative to their size). Parameters closer than 1e-9
// to a knot of either curve are skipped for the derivatives (one-sided there).
struct Deviation {
  double x = 0.0, d1 = 0.0, d2 = 0.0;
};

Deviation compare(const NurbsCurve& a, const NurbsCurve& b, std::mt19937& g) {
  std::uniform_real_distribution<double> U(0.0, 1.0);
  Deviation dev;
  std::vector<double> us = {0.0, 1.0};
  for (int k = 0; k < 300; ++k) us.push_back(U(g));
  for (double u : us) {
    const CurvePoint pa = evaluate(a, u), pb = evaluate(b, u);
    dev.x = std::max(dev.x, (pa.x - pb.x).norm());
    if (u == 0.0 || u == 1.0 || a.knots.multiplicity(u) > 0) continue;
    dev.d1 = std::max(dev.d1, (pa.x1 - pb.x1).norm() / std::max(1.0, pa.x1.norm()));
    dev.d2 = std::max(dev.d2, (pa.x2 - pb.x2).norm() / std::max(1.0, pa.x2.norm()));
  }
  return dev;
}

Deviation compare(const NurbsSurface& a, const NurbsSurface& b, std::mt19937& g) {
  std::uniform_real_distribution<double> U(0.0, 1.0);
  Deviation dev;
  for (int k = 0; k < 300; ++k) {
    const double u = k < 4 ? (k & 1) : U(g), v = k < 4 ? (k >> 1) : U(g);
    const SurfacePoint pa = evaluate(a, u, v), pb = evaluate(b, u, v);
    dev.x = std::max(dev.x, (pa.x - pb.x).norm());
    if (k < 4) continue;
    for (auto [x, y] : {std::pair{&pa.xu, &pb.xu}, {&pa.xv, &pb.xv}})
      dev.d1 = std::max(dev.d1, (*x - *y).norm() / std::max(1.0, x->norm()));
    for (auto [x, y] : {std::pair{&pa.xuu, &pb.xuu}, {&pa.xuv, &pb.xuv}, {&pa.xvv, &pb.xvv}})
      dev.d2 = std::max(dev.d2, (*x - *y).norm() / std::max(1.0, x->norm()));
  }
  return dev;
}

// Positions to 1e-13 absolute (control points are O(1)); derivatives relative to their size,
// looser because random knots can be close (1/Δξ² amplifies round-off in x'').
void expect_same(const Deviation& d, const std::string& what) {
  EXPECT_LT(d.x, 1e-13) << what;
  EXPECT_LT(d.d1, 1e-11) << what;
  EXPECT_LT(d.d2, 1e-9) << what;
}

// Expected knot vector after raising every distinct knot's multiplicity by t (degree p + t).
std::vector<double> elevated_knots(const KnotVector& kv, int t) {
  std::map<double, int> mult;
  for (double k : kv.knots()) ++mult[k];
  std::vector<double> out;
  for (auto [k, m] : mult) out.insert(out.end(), m + t, k);
  return out;
}

std::vector<double> merged(std::vector<double> a, const std::vector<double>& b) {
  a.insert(a.end(), b.begin(), b.end());
  std::sort(a.begin(), a.end());
  return a;
}

int n_distinct_interior(const KnotVector& kv) {
  return static_cast<int>(kv.breakpoints().size()) - 2;
}

}  // namespace

TEST(Refinement, KnotInsertionKeepsCurveAndCountsKnots) {
  std::mt19937 g(21);
  std::uniform_real_distribution<double> U(0.01, 0.99);
  Deviation worst;
  for (int p = 1; p <= 5; ++p) {
    for (bool rational : {false, true}) {
      const NurbsCurve c = random_curve(g, p, 3, rational);
      // A fresh knot, and an existing knot raised to multiplicity p.
      const double fresh = U(g);
      const double existing = c.knots.breakpoints()[1];
      for (auto [u, r] :
           {std::pair{fresh, std::max(1, p - 1)}, {existing, p - c.knots.multiplicity(existing)}}) {
        if (r < 1) continue;
        const NurbsCurve d = insert_knot(c, u, r);
        EXPECT_EQ(d.n(), c.n() + r);
        EXPECT_EQ(d.knots.knots(), merged(c.knots.knots(), std::vector<double>(r, u)));
        EXPECT_EQ(d.knots.multiplicity(u), c.knots.multiplicity(u) + r);
        const Deviation dev = compare(c, d, g);
        expect_same(dev, "p=" + std::to_string(p));
        worst.x = std::max(worst.x, dev.x);
      }
    }
  }
  RecordProperty("worst_position_error", sci(worst.x));
}

TEST(Refinement, KnotRefinementEqualsRepeatedInsertion) {
  // A5.4 (all at once) and Boehm (one by one) are different algorithms for the same result;
  // the control points of the refined curve are unique, so they must agree.
  std::mt19937 g(22);
  std::uniform_real_distribution<double> U(0.01, 0.99);
  for (int p = 0; p <= 5; ++p) {
    for (bool rational : {false, true}) {
      const NurbsCurve c = random_curve(g, p, 2, rational);
      std::vector<double> X = {U(g), U(g), U(g), U(g)};
      if (p >= 2) X.push_back(X[1]);                      // a repeated new knot
      if (p >= 2) X.push_back(c.knots.breakpoints()[1]);  // at an existing knot
      if (c.knots.multiplicity(c.knots.breakpoints()[1]) + 1 > std::max(p, 1)) X.pop_back();
      const NurbsCurve a = refine_knots(c, X);
      NurbsCurve b = c;
      for (double x : X) b = insert_knot(b, x);
      EXPECT_EQ(a.n(), c.n() + static_cast<int>(X.size()));
      EXPECT_EQ(a.knots.knots(), merged(c.knots.knots(), X));
      ASSERT_EQ(a.knots.knots(), b.knots.knots());
      for (int i = 0; i < a.n(); ++i) {
        EXPECT_LT((a.points[i] - b.points[i]).norm(), 1e-13) << "p=" << p << " i=" << i;
        EXPECT_NEAR(a.weights[i], b.weights[i], 1e-13);
      }
      expect_same(compare(c, a, g), "p=" + std::to_string(p));
    }
  }
}

TEST(Refinement, InsertionOnNonOpenKnotVector) {
  // Boehm and A5.4 need no open knot vector: a uniform (floating) cubic on its domain [3, 5].
  std::mt19937 g(29);
  NurbsCurve c;
  c.knots = KnotVector(3, {0, 1, 2, 3, 4, 5, 6, 7, 8});
  for (int i = 0; i < c.knots.n_basis(); ++i) {
    c.points.push_back(random_vector(g, 3));
    c.weights.push_back(0.5 + 0.3 * i);
  }
  const NurbsCurve a = insert_knot(c, 3.5, 2);
  const NurbsCurve b = refine_knots(c, {4.5, 3.5, 3.5});
  std::uniform_real_distribution<double> U(3.0, 5.0);
  for (int k = 0; k < 200; ++k) {
    const double u = U(g);
    EXPECT_LT((evaluate(a, u).x - evaluate(c, u).x).norm(), 1e-14);
    EXPECT_LT((evaluate(b, u).x - evaluate(c, u).x).norm(), 1e-14);
  }
  EXPECT_EQ(b.knots.knots(), (std::vector<double>{0, 1, 2, 3, 3.5, 3.5, 4, 4.5, 5, 6, 7, 8}));
}

TEST(Refinement, DegreeElevationKeepsCurveAndRaisesEveryMultiplicity) {
  std::mt19937 g(23);
  double worst = 0.0;
  for (int p = 1; p <= 5; ++p) {
    for (int t = 1; t <= 3; ++t) {
      for (bool rational : {false, true}) {
        for (int n_int : {0, 1, 4}) {
          const NurbsCurve c = random_curve(g, p, n_int, rational);
          const NurbsCurve e = elevate_degree(c, t);
          EXPECT_EQ(e.degree(), p + t);
          EXPECT_EQ(e.knots.knots(), elevated_knots(c.knots, t));
          // n grows by t per distinct interior knot plus t (IGA-thesis §4.1.4).
          EXPECT_EQ(e.n(), c.n() + t * (n_distinct_interior(c.knots) + 1));
          ASSERT_NO_THROW(e.validate());
          const Deviation dev = compare(c, e, g);
          expect_same(dev, "p=" + std::to_string(p) + " t=" + std::to_string(t));
          worst = std::max(worst, dev.x);
          // End points are interpolated exactly by both (4.10).
          EXPECT_LT((e.points.front() - c.points.front()).norm(), 1e-15);
          EXPECT_LT((e.points.back() - c.points.back()).norm(), 1e-15);
        }
      }
    }
  }
  RecordProperty("worst_position_error", sci(worst));
}

TEST(Refinement, BezierElevationByOneMatchesClosedForm) {
  // Bézier curve (4.1) elevated from p to p+1: Q_i = i/(p+1) P_{i−1} + (1 − i/(p+1)) P_i.
  std::mt19937 g(24);
  for (int p = 1; p <= 6; ++p) {
    NurbsCurve c;
    std::vector<double> k(p + 1, 0.0);
    k.insert(k.end(), p + 1, 1.0);
    c.knots = KnotVector(p, k);
    for (int i = 0; i <= p; ++i) {
      c.points.push_back(random_vector(g, 3));
      c.weights.push_back(1.0);
    }
    const NurbsCurve e = elevate_degree(c, 1);
    ASSERT_EQ(e.n(), p + 2);
    for (int i = 0; i <= p + 1; ++i) {
      const double a = static_cast<double>(i) / (p + 1);
      Vec3 ref = Vec3::Zero();
      if (i > 0) ref += a * c.points[i - 1];
      if (i <= p) ref += (1 - a) * c.points[i];
      EXPECT_LT((e.points[i] - ref).norm(), 1e-15) << "p=" << p << " i=" << i;
      EXPECT_DOUBLE_EQ(e.weights[i], 1.0);
    }
  }
}

TEST(Refinement, UniformAndKRefinementCountsAndOrder) {
  std::mt19937 g(25);
  for (int p = 1; p <= 4; ++p) {
    const NurbsCurve c = random_curve(g, p, 2, true);
    const int n_spans = static_cast<int>(c.knots.element_spans().size());
    const int s = n_distinct_interior(c.knots);
    for (int k = 0; k <= 3; ++k) {
      const NurbsCurve h = refine_uniform(c, k);
      EXPECT_EQ(h.n(), c.n() + k * n_spans);
      EXPECT_EQ(static_cast<int>(h.knots.element_spans().size()), (k + 1) * n_spans);
      expect_same(compare(c, h, g), "h");
      // k-refinement: elevation first keeps the new knots simple (continuity C^{p+t−1}) ...
      const int t = 2;
      const NurbsCurve kr = k_refine(c, t, k);
      EXPECT_EQ(kr.degree(), p + t);
      EXPECT_EQ(kr.n(), c.n() + t * (s + 1) + k * n_spans);
      for (double x : uniform_new_knots(c.knots, k)) EXPECT_EQ(kr.knots.multiplicity(x), 1);
      expect_same(compare(c, kr, g), "k");
      // ... the reverse order gives them multiplicity 1 + t and more control points.
      const NurbsCurve rev = elevate_degree(refine_uniform(c, k), t);
      EXPECT_EQ(rev.n(), c.n() + k * n_spans + t * (s + k * n_spans + 1));
      for (double x : uniform_new_knots(c.knots, k)) EXPECT_EQ(rev.knots.multiplicity(x), 1 + t);
      expect_same(compare(c, rev, g), "reverse");
    }
  }
  EXPECT_EQ(uniform_new_knots(KnotVector(1, {0, 0, 0.5, 1, 1}), 1),
            (std::vector<double>{0.25, 0.75}));
  EXPECT_EQ(uniform_new_knots(KnotVector(1, {0, 0, 1, 1}), 3),
            (std::vector<double>{0.25, 0.5, 0.75}));
}

TEST(Refinement, SurfacesInBothDirections) {
  std::mt19937 g(26);
  std::uniform_real_distribution<double> U(0.01, 0.99);
  for (auto [p, q] : {std::pair{1, 2}, {2, 2}, {3, 2}, {2, 3}}) {
    for (bool rational : {false, true}) {
      const NurbsSurface s = random_surface(g, p, q, rational);
      const std::string tag = "p=" + std::to_string(p) + " q=" + std::to_string(q);
      // Knot insertion in u, then in v.
      const double x = U(g);
      const NurbsSurface iu = insert_knot(s, Direction::u, x, 1);
      EXPECT_EQ(iu.n_u(), s.n_u() + 1);
      EXPECT_EQ(iu.n_v(), s.n_v());
      EXPECT_EQ(iu.u.knots(), merged(s.u.knots(), {x}));
      expect_same(compare(s, iu, g), tag + " insert u");
      const NurbsSurface iv = insert_knot(s, Direction::v, x, q);
      EXPECT_EQ(iv.n_v(), s.n_v() + q);
      EXPECT_EQ(iv.v.knots(), merged(s.v.knots(), std::vector<double>(q, x)));
      expect_same(compare(s, iv, g), tag + " insert v");
      // Knot refinement.
      const std::vector<double> X = {U(g), U(g), U(g)};
      const NurbsSurface rv = refine_knots(s, Direction::v, X);
      EXPECT_EQ(rv.n_v(), s.n_v() + 3);
      expect_same(compare(s, rv, g), tag + " refine v");
      // Degree elevation in each direction.
      const NurbsSurface eu = elevate_degree(s, Direction::u, 2);
      EXPECT_EQ(eu.degree_u(), p + 2);
      EXPECT_EQ(eu.degree_v(), q);
      EXPECT_EQ(eu.u.knots(), elevated_knots(s.u, 2));
      EXPECT_EQ(eu.n_u(), s.n_u() + 2 * (n_distinct_interior(s.u) + 1));
      expect_same(compare(s, eu, g), tag + " elevate u");
      const NurbsSurface ev = elevate_degree(s, Direction::v, 1);
      EXPECT_EQ(ev.v.knots(), elevated_knots(s.v, 1));
      EXPECT_EQ(ev.n_v(), s.n_v() + (n_distinct_interior(s.v) + 1));
      expect_same(compare(s, ev, g), tag + " elevate v");
      // Uniform h- and k-refinement.
      const int su = static_cast<int>(s.u.element_spans().size());
      const int sv = static_cast<int>(s.v.element_spans().size());
      const NurbsSurface h = refine_uniform(s, 2, 1);
      EXPECT_EQ(h.n_u(), s.n_u() + 2 * su);
      EXPECT_EQ(h.n_v(), s.n_v() + sv);
      expect_same(compare(s, h, g), tag + " uniform");
      const NurbsSurface k = k_refine(s, 1, 2, 1, 2);
      EXPECT_EQ(k.degree_u(), p + 1);
      EXPECT_EQ(k.degree_v(), q + 2);
      EXPECT_EQ(k.n_u(), s.n_u() + (n_distinct_interior(s.u) + 1) + su);
      EXPECT_EQ(k.n_v(), s.n_v() + 2 * (n_distinct_interior(s.v) + 1) + 2 * sv);
      EXPECT_EQ(static_cast<int>(k.points.size()), k.n_u() * k.n_v());
      expect_same(compare(s, k, g), tag + " k-refine");
    }
  }
}

TEST(Refinement, SurfaceLineAlgorithmMatchesCurveAlgorithm) {
  // Refining a surface in u is refining each row as a curve: check row 1 of the net.
  std::mt19937 g(27);
  const NurbsSurface s = random_surface(g, 2, 3, true);
  const NurbsCurve row = surface_row(s, 1);
  const NurbsSurface e = elevate_degree(s, Direction::u, 1);
  const NurbsCurve er = elevate_degree(row, 1);
  for (int i = 0; i < e.n_u(); ++i) {
    EXPECT_LT((e.points[e.index(i, 1)] - er.points[i]).norm(), 1e-15);
    EXPECT_EQ(e.weights[e.index(i, 1)], er.weights[i]);
  }
}

TEST(Refinement, InvalidInputThrowsWithClearMessage) {
  std::mt19937 g(28);
  NurbsCurve c = random_curve(g, 2, 0, true);  // (0,0,0,1,1,1)
  EXPECT_NE(message_of([&] { insert_knot(c, 1.0); }).find("not strictly inside the domain"),
            std::string::npos);
  EXPECT_NE(message_of([&] { insert_knot(c, -0.5); }).find("not strictly inside"),
            std::string::npos);
  EXPECT_NE(message_of([&] { insert_knot(c, 0.5, 3); }).find("multiplicity 3 > degree 2"),
            std::string::npos);
  EXPECT_NE(message_of([&] { insert_knot(c, 0.5, 0); }).find("r = 0"), std::string::npos);
  EXPECT_NE(message_of([&] {
              refine_knots(c, {0.5, 0.2, 0.5, 0.5});
            }).find("multiplicity 3"),
            std::string::npos);
  EXPECT_NE(message_of([&] { refine_knots(c, {std::nan("")}); }).find("not strictly inside"),
            std::string::npos);
  EXPECT_NE(message_of([&] { elevate_degree(c, -1); }).find("negative"), std::string::npos);
  EXPECT_NE(message_of([&] { elevate_degree(c, kMaxDegree); }).find("exceeds kMaxDegree"),
            std::string::npos);
  EXPECT_NE(message_of([&] { refine_uniform(c, -1); }).find("negative"), std::string::npos);
  NurbsCurve open = c;
  open.knots = KnotVector(2, {0, 1, 2, 3, 4, 5});
  EXPECT_NE(message_of([&] { elevate_degree(open, 1); }).find("open knot vector"),
            std::string::npos);
  NurbsCurve bad = c;
  bad.weights[1] = -1.0;
  EXPECT_NE(message_of([&] { insert_knot(bad, 0.5); }).find("weight 1"), std::string::npos);
  bad = c;
  bad.points.pop_back();
  EXPECT_NE(message_of([&] { elevate_degree(bad, 1); }).find("control points"), std::string::npos);
  const NurbsSurface s = random_surface(g, 2, 2, true);
  EXPECT_NE(message_of([&] { insert_knot(s, Direction::v, 2.0); }).find("not strictly inside"),
            std::string::npos);
  // A 4-fold start knot at degree 2 is refused, not elevated past the ends of the arrays
  // (issue #15, found by fuzz/cad_patch_fuzzer.cpp: an ASan heap-buffer-overflow before).
  NurbsCurve extra = c;
  extra.knots = KnotVector(2, {0, 0, 0, 0, 0.5, 1, 1, 1});
  for (const Vec3& x : {Vec3(1, 2, 3), Vec3(2, 0, 1)}) {  // 5 control points for 8 knots
    extra.points.push_back(x);
    extra.weights.push_back(1.0);
  }
  EXPECT_NE(message_of([&] { elevate_degree(extra, 1); }).find("open knot vector"),
            std::string::npos);
  // Elevation with a knot of multiplicity p + 1 inside (a discontinuous curve) is refused.
  NurbsCurve disc;
  disc.knots = KnotVector(1, {0, 0, 0.5, 0.5, 1, 1});
  disc.points.assign(4, Vec3::Zero());
  disc.weights.assign(4, 1.0);
  EXPECT_NE(message_of([&] { elevate_degree(disc, 1); }).find("multiplicity 2 > degree 1"),
            std::string::npos);
}
