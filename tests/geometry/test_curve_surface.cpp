// evaluate() for NURBS curves (IGA-thesis (4.10)) and surfaces (4.13): derivatives against
// central differences, rational and polynomial; the homogeneous evaluation against Σ R_i P_i
// from the rational bases (a different code path); end-point interpolation and end tangents
// (4.11); affine invariance; validate() and size checks.
#include <gtest/gtest.h>

#include <random>
#include <string>

#include "isoflex/geometry/nurbs_curve.hpp"
#include "isoflex/geometry/nurbs_surface.hpp"
#include "support/finite_difference.hpp"
#include "support/geometry.hpp"

using namespace isoflex;
using namespace isoflex::geometry;
using namespace isoflex::test;

namespace {

// This file's random curves and surfaces: jittered knots, weights in [0.3, 2.5].
NurbsCurve random_curve(std::mt19937& g, int p, bool rational) {
  return random_nurbs_curve(g, jittered_knots(g, p, 3, -0.5, 2.0), rational, 0.3, 2.5);
}

NurbsSurface random_surface(std::mt19937& g, int p, int q, bool rational) {
  KnotVector u = jittered_knots(g, p, 2, 0.0, 1.0);
  KnotVector v = jittered_knots(g, q, 2, 1.0, 3.0);
  return random_nurbs_surface(g, std::move(u), std::move(v), rational, 0.3, 2.5);
}

// Richardson-extrapolated central difference (4 D(h/2) − D(h))/3, truncation O(h⁴): the plain
// central difference with ∛ε steps is too coarse for degree-5 pieces on short random spans.
template <class F>
Vec3 richardson(F&& f, double u, double h) {
  auto D = [&](double k) -> Vec3 { return (f(u + k) - f(u - k)) / (2.0 * k); };
  return (4.0 * D(h / 2) - D(h)) / 3.0;
}

}  // namespace

TEST(CurveEvaluate, DerivativesMatchCentralDifferences) {
  std::mt19937 g(31);
  std::uniform_real_distribution<double> U(-0.5, 2.0);
  double worst = 0.0;
  for (int p = 1; p <= 5; ++p) {
    for (bool rational : {false, true}) {
      const NurbsCurve c = random_curve(g, p, rational);
      for (int k = 0; k < 20; ++k) {
        const double u = U(g);
        const double h = 1e-3;
        if (knot_distance(c.knots, u) < h) continue;  // stay inside one polynomial piece
        const CurvePoint P = evaluate(c, u);
        auto f0 = [&](double x) -> Vec3 { return evaluate(c, x).x; };
        auto f1 = [&](double x) -> Vec3 { return evaluate(c, x).x1; };
        const double e1 = rel_diff(P.x1, richardson(f0, u, h));
        const double e2 = rel_diff(P.x2, richardson(f1, u, h));
        worst = std::max({worst, e1, e2});
        EXPECT_LT(e1, 1e-8) << "p=" << p << " u=" << u;
        EXPECT_LT(e2, 1e-8) << "p=" << p << " u=" << u;
      }
    }
  }
  RecordProperty("worst_fd_rel_error", sci(worst));
}

TEST(CurveEvaluate, HomogeneousFormEqualsRationalBasisSum) {
  std::mt19937 g(32);
  std::uniform_real_distribution<double> U(-0.5, 2.0);
  for (int p = 1; p <= 4; ++p) {
    const NurbsCurve c = random_curve(g, p, true);
    for (int k = 0; k < 30; ++k) {
      const double u = U(g);
      const CurvePoint P = evaluate(c, u);
      const CurveBasis B = curve_basis(c, u);
      Vec3 x = Vec3::Zero(), x1 = Vec3::Zero(), x2 = Vec3::Zero();
      for (int a = 0; a <= p; ++a) {
        const Vec3& Pa = c.points[B.global_index(c, a)];
        x += B.R(0, a) * Pa;
        x1 += B.R(1, a) * Pa;
        x2 += B.R(2, a) * Pa;
      }
      EXPECT_LT((P.x - x).norm(), 1e-14);
      EXPECT_LT((P.x1 - x1).norm(), 1e-13 * std::max(1.0, x1.norm()));
      EXPECT_LT((P.x2 - x2).norm(), 1e-12 * std::max(1.0, x2.norm()));
    }
  }
}

TEST(CurveEvaluate, EndPointsAndEndTangentsOfThesis411) {
  // (4.10) interpolates P_0 and P_n; (4.11): C'(a) = p/(ξ_{p+1} − a) · w_1/w_0 · (P_1 − P_0)
  // (the thesis writes ξ_{p+1} for a = 0, b = 1), and symmetrically at b.
  std::mt19937 g(33);
  for (int p = 1; p <= 5; ++p) {
    const NurbsCurve c = random_curve(g, p, true);
    const auto& U = c.knots.knots();
    const int n = c.n() - 1, m = static_cast<int>(U.size()) - 1;
    const double a = c.knots.front(), b = c.knots.back();
    const CurvePoint Pa = evaluate(c, a), Pb = evaluate(c, b);
    EXPECT_LT((Pa.x - c.points[0]).norm(), 1e-15);
    EXPECT_LT((Pb.x - c.points[n]).norm(), 1e-15);
    const Vec3 ta = p / (U[p + 1] - a) * c.weights[1] / c.weights[0] * (c.points[1] - c.points[0]);
    const Vec3 tb =
        p / (b - U[m - p - 1]) * c.weights[n - 1] / c.weights[n] * (c.points[n] - c.points[n - 1]);
    EXPECT_LT((Pa.x1 - ta).norm(), 1e-12 * ta.norm()) << "p=" << p;
    EXPECT_LT((Pb.x1 - tb).norm(), 1e-12 * tb.norm()) << "p=" << p;
  }
}

TEST(CurveEvaluate, AffineInvariance) {
  std::mt19937 g(34);
  NurbsCurve c = random_curve(g, 3, true);
  const Mat3 Q = random_rotation(g);
  const Vec3 t = random_vector(g, 3);
  NurbsCurve d = c;
  for (Vec3& P : d.points) P = Q * P + t;
  for (double u : {-0.5, 0.1, 0.7, 1.3, 2.0}) {
    const CurvePoint a = evaluate(c, u), b = evaluate(d, u);
    EXPECT_LT((b.x - (Q * a.x + t)).norm(), 1e-14);
    EXPECT_LT((b.x1 - Q * a.x1).norm(), 1e-12 * std::max(1.0, a.x1.norm()));
    EXPECT_LT((b.x2 - Q * a.x2).norm(), 1e-12 * std::max(1.0, a.x2.norm()));
  }
}

TEST(SurfaceEvaluate, DerivativesMatchCentralDifferences) {
  std::mt19937 g(35);
  std::uniform_real_distribution<double> U(0.0, 1.0), V(1.0, 3.0);
  double worst = 0.0;
  for (auto [p, q] : {std::pair{1, 1}, {2, 1}, {2, 2}, {3, 2}, {2, 4}}) {
    for (bool rational : {false, true}) {
      const NurbsSurface s = random_surface(g, p, q, rational);
      for (int k = 0; k < 15; ++k) {
        const double u = U(g), v = V(g);
        if (knot_distance(s.u, u) < 1e-3 || knot_distance(s.v, v) < 1e-3) continue;
        const SurfacePoint P = evaluate(s, u, v);
        const VecX x0 = (VecX(2) << u, v).finished();
        auto fx = [&](const VecX& x) -> VecX { return evaluate(s, x(0), x(1)).x; };
        auto fu = [&](const VecX& x) -> VecX { return evaluate(s, x(0), x(1)).xu; };
        auto fv = [&](const VecX& x) -> VecX { return evaluate(s, x(0), x(1)).xv; };
        const MatX Jx = central_jacobian(fx, x0), Ju = central_jacobian(fu, x0),
                   Jv = central_jacobian(fv, x0);
        const double e[] = {rel_diff(P.xu, Jx.col(0)),  rel_diff(P.xv, Jx.col(1)),
                            rel_diff(P.xuu, Ju.col(0)), rel_diff(P.xuv, Ju.col(1)),
                            rel_diff(P.xuv, Jv.col(0)), rel_diff(P.xvv, Jv.col(1))};
        for (double ei : e) {
          worst = std::max(worst, ei);
          EXPECT_LT(ei, 1e-7) << "p=" << p << " q=" << q << " (" << u << ", " << v << ")";
        }
      }
    }
  }
  RecordProperty("worst_fd_rel_error", sci(worst));
}

TEST(SurfaceEvaluate, HomogeneousFormEqualsRationalBasisSumAndCorners) {
  std::mt19937 g(36);
  std::uniform_real_distribution<double> U(0.0, 1.0), V(1.0, 3.0);
  for (auto [p, q] : {std::pair{1, 2}, {2, 2}, {3, 3}}) {
    const NurbsSurface s = random_surface(g, p, q, true);
    for (int k = 0; k < 30; ++k) {
      const double u = U(g), v = V(g);
      const SurfacePoint P = evaluate(s, u, v);
      const SurfaceBasis B = surface_basis(s, u, v);
      Mat<3, 6> sum = Mat<3, 6>::Zero();
      for (int c = 0; c < B.R.cols(); ++c)
        sum += s.points[B.global_index(s, c)] * B.R.col(c).transpose();
      const Vec3* mine[6] = {&P.x, &P.xu, &P.xv, &P.xuu, &P.xuv, &P.xvv};
      for (int r = 0; r < 6; ++r)
        EXPECT_LT((*mine[r] - sum.col(r)).norm(), 1e-13 * std::max(1.0, sum.col(r).norm()))
            << "row " << r;
    }
    // The four corners are interpolated (§4.1.3.2).
    const int nu = s.n_u(), nv = s.n_v();
    EXPECT_LT((evaluate(s, 0, 1).x - s.points[s.index(0, 0)]).norm(), 1e-15);
    EXPECT_LT((evaluate(s, 1, 1).x - s.points[s.index(nu - 1, 0)]).norm(), 1e-15);
    EXPECT_LT((evaluate(s, 0, 3).x - s.points[s.index(0, nv - 1)]).norm(), 1e-15);
    EXPECT_LT((evaluate(s, 1, 3).x - s.points[s.index(nu - 1, nv - 1)]).norm(), 1e-15);
  }
}

TEST(SurfaceEvaluate, IsoLineIsTheCurveOfItsRow) {
  // At η = a knot where N_j(η) = 1 (the open end), S(ξ, η) is the NURBS curve of row j.
  std::mt19937 g(37);
  const NurbsSurface s = random_surface(g, 3, 2, true);
  const NurbsCurve row = surface_row(s, 0);
  for (double u : {0.0, 0.21, 0.5, 0.93, 1.0}) {
    const SurfacePoint P = evaluate(s, u, 1.0);
    const CurvePoint C = evaluate(row, u);
    EXPECT_LT((P.x - C.x).norm(), 1e-15);
    EXPECT_LT((P.xu - C.x1).norm(), 1e-13 * std::max(1.0, C.x1.norm()));
    EXPECT_LT((P.xuu - C.x2).norm(), 1e-12 * std::max(1.0, C.x2.norm()));
  }
}

TEST(NurbsValidate, RationalFlagAndInvalidInput) {
  std::mt19937 g(38);
  NurbsCurve c = random_curve(g, 2, false);
  EXPECT_FALSE(c.is_rational());
  EXPECT_NO_THROW(c.validate());
  c.weights[2] = 1.5;
  EXPECT_TRUE(c.is_rational());
  NurbsCurve bad = c;
  bad.weights[1] = 0.0;
  EXPECT_NE(message_of([&] { bad.validate(); }).find("weight 1 = 0"), std::string::npos);
  bad.weights[1] = std::nan("");
  EXPECT_NE(message_of([&] { bad.validate(); }).find("weight 1"), std::string::npos);
  bad = c;
  bad.points[0].x() = std::nan("");
  EXPECT_NE(message_of([&] { bad.validate(); }).find("control point 0"), std::string::npos);
  bad = c;
  bad.points.pop_back();
  const std::string m = message_of([&] { bad.validate(); });
  EXPECT_NE(m.find("control points but the knot vector defines"), std::string::npos) << m;
  EXPECT_THROW(evaluate(bad, 0.5), std::invalid_argument);
  bad = c;
  bad.weights.push_back(1.0);
  EXPECT_NE(message_of([&] { bad.validate(); }).find("weights"), std::string::npos);

  NurbsSurface s = random_surface(g, 2, 2, true);
  EXPECT_TRUE(s.is_rational());
  EXPECT_NO_THROW(s.validate());
  NurbsSurface sb = s;
  sb.weights[4] = -2.0;
  EXPECT_NE(message_of([&] { sb.validate(); }).find("weight 4 = -2"), std::string::npos);
  sb = s;
  sb.points.pop_back();
  EXPECT_NE(message_of([&] { sb.validate(); }).find("control points but the knot vectors"),
            std::string::npos);
  EXPECT_THROW(surface_basis(sb, 0.5, 1.5), std::invalid_argument);
  EXPECT_THROW(evaluate(sb, 0.5, 1.5), std::invalid_argument);
  s.weights.assign(s.weights.size(), 0.7);
  EXPECT_FALSE(s.is_rational());
}
