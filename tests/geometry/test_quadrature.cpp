// Gauss–Legendre rules and the element loop (IGA-thesis §4.2.1, §4.3). Reference values are the
// closed-form nodes and weights of the low-order rules and the exact integrals of monomials.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "isoflex/geometry/nurbs_surface.hpp"
#include "isoflex/geometry/quadrature.hpp"
#include "support/geometry.hpp"

namespace isoflex::geometry {
namespace {

using namespace isoflex::test;

double integrate_monomial(const GaussRule& r, int k) {
  double s = 0.0;
  for (int i = 0; i < r.size(); ++i) s += r.weights[i] * std::pow(r.nodes[i], k);
  return s;
}

TEST(GaussLegendre, ClosedFormRules) {
  const double tol = 1e-15;
  {
    const auto r = gauss_legendre(1);
    ASSERT_EQ(r.size(), 1);
    EXPECT_NEAR(r.nodes[0], 0.0, tol);
    EXPECT_NEAR(r.weights[0], 2.0, tol);
  }
  {
    const auto r = gauss_legendre(2);
    EXPECT_NEAR(r.nodes[0], -1.0 / std::sqrt(3.0), tol);
    EXPECT_NEAR(r.nodes[1], 1.0 / std::sqrt(3.0), tol);
    EXPECT_NEAR(r.weights[0], 1.0, tol);
    EXPECT_NEAR(r.weights[1], 1.0, tol);
  }
  {
    const auto r = gauss_legendre(3);
    EXPECT_NEAR(r.nodes[0], -std::sqrt(0.6), tol);
    EXPECT_NEAR(r.nodes[1], 0.0, tol);
    EXPECT_NEAR(r.nodes[2], std::sqrt(0.6), tol);
    EXPECT_NEAR(r.weights[0], 5.0 / 9.0, tol);
    EXPECT_NEAR(r.weights[1], 8.0 / 9.0, tol);
  }
  {
    const auto r = gauss_legendre(4);
    const double a = std::sqrt(3.0 / 7.0 - 2.0 / 7.0 * std::sqrt(6.0 / 5.0));
    const double b = std::sqrt(3.0 / 7.0 + 2.0 / 7.0 * std::sqrt(6.0 / 5.0));
    EXPECT_NEAR(r.nodes[0], -b, tol);
    EXPECT_NEAR(r.nodes[1], -a, tol);
    EXPECT_NEAR(r.nodes[3], b, tol);
    EXPECT_NEAR(r.weights[0], (18.0 - std::sqrt(30.0)) / 36.0, tol);
    EXPECT_NEAR(r.weights[1], (18.0 + std::sqrt(30.0)) / 36.0, tol);
  }
  {
    const auto r = gauss_legendre(5);
    const double a = std::sqrt(5.0 - 2.0 * std::sqrt(10.0 / 7.0)) / 3.0;
    const double b = std::sqrt(5.0 + 2.0 * std::sqrt(10.0 / 7.0)) / 3.0;
    EXPECT_NEAR(r.nodes[0], -b, tol);
    EXPECT_NEAR(r.nodes[1], -a, tol);
    EXPECT_NEAR(r.nodes[2], 0.0, tol);
    EXPECT_NEAR(r.weights[0], (322.0 - 13.0 * std::sqrt(70.0)) / 900.0, tol);
    EXPECT_NEAR(r.weights[1], (322.0 + 13.0 * std::sqrt(70.0)) / 900.0, tol);
    EXPECT_NEAR(r.weights[2], 128.0 / 225.0, tol);
  }
}

TEST(GaussLegendre, ExactUpToDegree2nMinus1AndNotBeyond) {
  double worst = 0.0;
  for (int n = 1; n <= 40; ++n) {
    const auto r = gauss_legendre(n);
    for (int i = 1; i < n; ++i) ASSERT_LT(r.nodes[i - 1], r.nodes[i]);
    for (int k = 0; k <= 2 * n - 1; ++k) {
      const double exact = (k % 2 == 0) ? 2.0 / (k + 1) : 0.0;
      const double err = std::abs(integrate_monomial(r, k) - exact);
      worst = std::max(worst, err);
      EXPECT_LT(err, 2e-15) << "n = " << n << ", k = " << k;
    }
    // x^{2n} is not integrated exactly: the error is 2^{2n+1}(n!)^4/((2n+1)((2n)!)^3)·(2n)! > 0.
    if (n <= 12) {
      EXPECT_GT(std::abs(integrate_monomial(r, 2 * n) - 2.0 / (2 * n + 1)), 1e-9) << n;
    }
  }
  RecordProperty("worst_monomial_error", sci(worst));
}

TEST(GaussLegendre, HighOrderRuleIntegratesSmoothFunction) {
  for (const int n : {20, 64, 150}) {
    const auto r = gauss_legendre(n);
    double sw = 0.0, sc = 0.0;
    for (int i = 0; i < n; ++i) {
      sw += r.weights[i];
      sc += r.weights[i] * std::cos(r.nodes[i]);
      EXPECT_EQ(r.nodes[i], -r.nodes[n - 1 - i]);
      EXPECT_EQ(r.weights[i], r.weights[n - 1 - i]);
    }
    EXPECT_NEAR(sw, 2.0, 1e-14) << n;
    EXPECT_NEAR(sc, 2.0 * std::sin(1.0), 1e-14) << n;
  }
}

TEST(GaussLegendre, RejectsNonPositiveOrder) {
  EXPECT_THROW(gauss_legendre(0), std::invalid_argument);
  EXPECT_THROW(gauss_legendre(-3), std::invalid_argument);
}

// A flat B-spline sheet: ξ quadratic with a double interior knot, η linear with three spans.
NurbsSurface sheet() {
  NurbsSurface s;
  s.u = KnotVector(2, {0.0, 0.0, 0.0, 0.5, 0.5, 1.0, 1.0, 1.0});
  s.v = KnotVector(1, {0.0, 0.0, 0.2, 0.7, 1.0, 1.0});
  for (int j = 0; j < s.n_v(); ++j)
    for (int i = 0; i < s.n_u(); ++i) s.points.push_back(Vec3(i, j, 0.0));
  s.weights.assign(s.points.size(), 1.0);
  return s;
}

TEST(SurfaceElements, SpansAndBounds) {
  const NurbsSurface s = sheet();
  const auto eu = span_elements(s.u);
  ASSERT_EQ(eu.size(), 2u);
  EXPECT_EQ(eu[0].span, 2);
  EXPECT_EQ(eu[1].span, 4);  // span 3 = [0.5, 0.5) is empty
  EXPECT_EQ(eu[1].a, 0.5);
  EXPECT_EQ(eu[1].b, 1.0);
  const auto el = surface_elements(s);
  ASSERT_EQ(el.size(), 6u);
  const double v_bounds[] = {0.0, 0.2, 0.7, 1.0};
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 2; ++i) {
      const auto& e = el[i + 2 * j];
      EXPECT_EQ(e.span_u, i == 0 ? 2 : 4);
      EXPECT_EQ(e.span_v, 1 + j);
      EXPECT_EQ(e.u0, 0.5 * i);
      EXPECT_EQ(e.u1, 0.5 * (i + 1));
      EXPECT_EQ(e.v0, v_bounds[j]);
      EXPECT_EQ(e.v1, v_bounds[j + 1]);
      // The span of an interior point is the element's span.
      EXPECT_EQ(s.u.find_span(0.5 * (e.u0 + e.u1)), e.span_u);
      EXPECT_EQ(s.v.find_span(0.5 * (e.v0 + e.v1)), e.span_v);
    }
  }
}

TEST(SurfaceQuadrature, DefaultRuleIntegratesPolynomialsOfDegree2pPlus1) {
  const NurbsSurface s = sheet();  // p = 2, q = 1: default 3 × 2 points, exact to ξ^5 η^3
  const auto qp = surface_quadrature(s);
  ASSERT_EQ(qp.size(), 6u);
  double area = 0.0, m53 = 0.0, m63 = 0.0;
  for (const auto& e : qp) {
    ASSERT_EQ(e.size(), 6u);
    for (const auto& p : e) {
      area += p.weight;
      m53 += p.weight * std::pow(p.xi, 5) * std::pow(p.eta, 3);
      m63 += p.weight * std::pow(p.xi, 6) * std::pow(p.eta, 3);
    }
  }
  EXPECT_NEAR(area, 1.0, 1e-15);
  EXPECT_NEAR(m53, 1.0 / 24.0, 1e-15);
  EXPECT_GT(std::abs(m63 - 1.0 / 28.0), 1e-8);  // degree 6 in ξ is beyond the rule

  // A configured order: 4 × 3 points, exact to ξ^7 η^5.
  const auto q2 = surface_quadrature(s, {4, 3});
  double m75 = 0.0;
  for (const auto& e : q2) {
    ASSERT_EQ(e.size(), 12u);
    for (const auto& p : e) m75 += p.weight * std::pow(p.xi, 7) * std::pow(p.eta, 5);
  }
  EXPECT_NEAR(m75, 1.0 / 48.0, 1e-15);
}

TEST(SurfaceQuadrature, PointsLieInsideTheirElement) {
  const NurbsSurface s = sheet();
  const auto el = surface_elements(s);
  const auto qp = surface_quadrature(s, {5, 5});
  for (std::size_t e = 0; e < el.size(); ++e) {
    for (const auto& p : qp[e]) {
      EXPECT_GT(p.xi, el[e].u0);
      EXPECT_LT(p.xi, el[e].u1);
      EXPECT_GT(p.eta, el[e].v0);
      EXPECT_LT(p.eta, el[e].v1);
      EXPECT_GT(p.weight, 0.0);
    }
  }
}

// Area of a quarter cylinder (radius R, height H) from |S_ξ × S_η| at the quadrature points:
// R·H·π/2. The integrand is rational, so this converges (exponentially) rather than being exact.
TEST(SurfaceQuadrature, QuarterCylinderArea) {
  const double R = 1.3, H = 0.7, c = std::sqrt(0.5);
  NurbsSurface s;
  s.u = KnotVector(2, {0.0, 0.0, 0.0, 1.0, 1.0, 1.0});
  s.v = KnotVector(1, {0.0, 0.0, 1.0, 1.0});
  for (const double z : {0.0, H}) {
    s.points.push_back(Vec3(R, 0.0, z));
    s.points.push_back(Vec3(R, R, z));
    s.points.push_back(Vec3(0.0, R, z));
    s.weights.insert(s.weights.end(), {1.0, c, 1.0});
  }
  const double exact = R * H * std::numbers::pi / 2.0;
  double a_default = 0.0, a_fine = 0.0;
  for (const auto& e : surface_quadrature(s))
    for (const auto& p : e) {
      const SurfacePoint sp = evaluate(s, p.xi, p.eta);
      a_default += p.weight * sp.xu.cross(sp.xv).norm();
    }
  for (const auto& e : surface_quadrature(s, {16, 2}))
    for (const auto& p : e) {
      const SurfacePoint sp = evaluate(s, p.xi, p.eta);
      a_fine += p.weight * sp.xu.cross(sp.xv).norm();
    }
  EXPECT_NEAR(a_fine, exact, 1e-13 * exact);
  EXPECT_GT(std::abs(a_default - exact), 1e-6 * exact);  // 3 points are visibly not enough
  EXPECT_LT(std::abs(a_default - exact), 1e-2 * exact);
}

}  // namespace
}  // namespace isoflex::geometry
