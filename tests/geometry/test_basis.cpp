// B-spline and NURBS bases: compared with an independent, literal implementation of the
// Cox–de Boor recursion IGA-thesis (4.3), with the Bernstein polynomials (4.2) for the knot
// vector (4.5), with central finite differences, and checked for partition of unity and
// non-negativity.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "isoflex/geometry/bspline_basis.hpp"
#include "isoflex/geometry/nurbs_curve.hpp"
#include "isoflex/geometry/nurbs_surface.hpp"
#include "support/finite_difference.hpp"

using namespace isoflex;
using namespace isoflex::geometry;
using namespace isoflex::test;

namespace {

// Scientific notation for RecordProperty (std::to_string prints 0.000000 for 1e-15).
std::string sci(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2e", v);
  return buf;
}

// (4.3) literally, recursive, with 0/0 := 0; N_{i,0} = 1 on [ξ_i, ξ_{i+1}), and on the last
// non-empty span also at its right end (the convention of find_span for u = back()).
double cox_de_boor(const std::vector<double>& U, int i, int p, double u, int last_span) {
  if (p == 0) {
    if (U[i] <= u && u < U[i + 1]) return 1.0;
    return (i == last_span && u == U[i + 1]) ? 1.0 : 0.0;
  }
  double v = 0.0;
  const double d1 = U[i + p] - U[i], d2 = U[i + p + 1] - U[i + 1];
  if (d1 > 0.0) v += (u - U[i]) / d1 * cox_de_boor(U, i, p - 1, u, last_span);
  if (d2 > 0.0) v += (U[i + p + 1] - u) / d2 * cox_de_boor(U, i + 1, p - 1, u, last_span);
  return v;
}

// d^k N_{i,p} by differentiating (4.3b) k times: N' = p/(ξ_{i+p}−ξ_i) N_{i,p−1} −
// p/(ξ_{i+p+1}−ξ_{i+1}) N_{i+1,p−1} (The NURBS Book ch. 2).
double cox_de_boor_der(const std::vector<double>& U, int i, int p, double u, int k, int last) {
  if (k == 0) return cox_de_boor(U, i, p, u, last);
  if (p == 0) return 0.0;
  double v = 0.0;
  const double d1 = U[i + p] - U[i], d2 = U[i + p + 1] - U[i + 1];
  if (d1 > 0.0) v += p / d1 * cox_de_boor_der(U, i, p - 1, u, k - 1, last);
  if (d2 > 0.0) v -= p / d2 * cox_de_boor_der(U, i + 1, p - 1, u, k - 1, last);
  return v;
}

// Random open knot vector on [a, b] with some repeated interior knots (multiplicity ≤ p).
KnotVector random_knots(std::mt19937& g, int p, int n_interior, double a = 0.0, double b = 1.0) {
  std::uniform_real_distribution<double> U(a, b);
  std::vector<double> inner;
  for (int k = 0; k < n_interior; ++k) {
    const double x = U(g);
    const int m = 1 + static_cast<int>(g() % std::max(1, p));  // multiplicity 1..p
    for (int r = 0; r < m; ++r) inner.push_back(x);
  }
  std::sort(inner.begin(), inner.end());
  std::vector<double> k(p + 1, a);
  k.insert(k.end(), inner.begin(), inner.end());
  k.insert(k.end(), p + 1, b);
  return KnotVector(p, k);
}

// All n_basis functions (zeros outside the support) as one global vector.
VecX global_basis(const KnotVector& kv, double u, int order) {
  const Basis1D B = bspline_basis(kv, u, 2);
  VecX N = VecX::Zero(kv.n_basis());
  for (int j = 0; j <= kv.degree(); ++j) N(B.span - kv.degree() + j) = B.ders(order, j);
  return N;
}

// Distance of u to the nearest knot (finite differences must not straddle a knot).
double knot_distance(const KnotVector& kv, double u) {
  double d = 1e300;
  for (double k : kv.knots()) d = std::min(d, std::abs(u - k));
  return d;
}

}  // namespace

TEST(BsplineBasis, MatchesLiteralCoxDeBoorIncludingEndsAndRepeatedKnots) {
  std::mt19937 g(1);
  std::uniform_real_distribution<double> U01(0.0, 1.0);
  double worst = 0.0;
  for (int p = 0; p <= 6; ++p) {
    for (int trial = 0; trial < 5; ++trial) {
      const KnotVector kv = random_knots(g, p, 4);
      const int last = kv.element_spans().back();
      std::vector<double> us = {0.0, 1.0};
      for (double k : kv.breakpoints()) us.push_back(k);  // exactly at the knots
      for (int s = 0; s < 20; ++s) us.push_back(U01(g));
      for (double u : us) {
        const Basis1D B = bspline_basis(kv, u, 2);
        ASSERT_EQ(B.ders.rows(), 3);
        ASSERT_EQ(B.ders.cols(), p + 1);
        EXPECT_EQ(B.span, kv.find_span(u));
        for (int i = 0; i < kv.n_basis(); ++i) {
          const int j = i - (B.span - p);
          for (int k = 0; k <= 2; ++k) {
            const double ref = cox_de_boor_der(kv.knots(), i, p, u, k, last);
            const double got = (j >= 0 && j <= p) ? B.ders(k, j) : 0.0;
            // Derivatives scale like p!/Δξ^k; compare relative to the size of the row.
            const double scale = std::max(1.0, B.ders.row(k).cwiseAbs().maxCoeff());
            worst = std::max(worst, std::abs(got - ref) / scale);
            EXPECT_NEAR(got, ref, 1e-12 * scale)
                << "p=" << p << " i=" << i << " k=" << k << " u=" << u;
          }
        }
      }
    }
  }
  RecordProperty("worst_rel_error", sci(worst));
}

TEST(BsplineBasis, PartitionOfUnityAndNonNegativity) {
  std::mt19937 g(2);
  std::uniform_real_distribution<double> U(-2.0, 3.0);
  for (int p = 0; p <= kMaxDegree; ++p) {
    const KnotVector kv = random_knots(g, p, 5, -2.0, 3.0);
    for (int s = 0; s < 50; ++s) {
      const double u = U(g);
      const Basis1D B = bspline_basis(kv, u, 2);
      EXPECT_NEAR(B.ders.row(0).sum(), 1.0, 1e-14) << "p=" << p;
      EXPECT_GE(B.ders.row(0).minCoeff(), 0.0) << "p=" << p;
      // Derivatives of a partition of unity sum to zero.
      const double s1 = std::max(1.0, B.ders.row(1).cwiseAbs().sum());
      const double s2 = std::max(1.0, B.ders.row(2).cwiseAbs().sum());
      EXPECT_NEAR(B.ders.row(1).sum(), 0.0, 1e-13 * s1) << "p=" << p;
      EXPECT_NEAR(B.ders.row(2).sum(), 0.0, 1e-13 * s2) << "p=" << p;
    }
  }
}

TEST(BsplineBasis, BernsteinKnotVectorGivesBernsteinPolynomials) {
  // (4.5) yields the Bernstein polynomials (4.2): B_{i,p} = C(p,i) u^i (1−u)^{p−i}.
  for (int p = 1; p <= 7; ++p) {
    std::vector<double> k(p + 1, 0.0);
    k.insert(k.end(), p + 1, 1.0);
    const KnotVector kv(p, k);
    for (double u : {0.0, 0.13, 0.5, 0.77, 1.0}) {
      const Basis1D B = bspline_basis(kv, u, 2);
      for (int i = 0; i <= p; ++i) {
        const double c = std::tgamma(p + 1.0) / (std::tgamma(i + 1.0) * std::tgamma(p - i + 1.0));
        EXPECT_NEAR(B.ders(0, i), c * std::pow(u, i) * std::pow(1 - u, p - i), 1e-14);
      }
    }
  }
}

TEST(BsplineBasis, DerivativesMatchCentralDifferences) {
  std::mt19937 g(3);
  std::uniform_real_distribution<double> U01(0.0, 1.0);
  for (int p = 1; p <= 5; ++p) {
    const KnotVector kv = random_knots(g, p, 3);
    for (int s = 0; s < 20; ++s) {
      const double u = U01(g);
      if (knot_distance(kv, u) < 1e-3) continue;
      for (int order = 1; order <= 2; ++order) {
        auto f = [&](const VecX& x) -> VecX { return global_basis(kv, x(0), order - 1); };
        const MatX fd = central_jacobian(f, VecX::Constant(1, u));
        EXPECT_LT(rel_diff(global_basis(kv, u, order), fd), 1e-7) << "p=" << p << " u=" << u;
      }
    }
  }
}

TEST(BsplineBasis, FewerDerivativesAndDegreeZero) {
  const KnotVector kv(2, {0, 0, 0, 0.5, 1, 1, 1});
  const Basis1D B0 = bspline_basis(kv, 0.3, 0);
  EXPECT_EQ(B0.ders.rows(), 1);
  const Basis1D B2 = bspline_basis(kv, 0.3, 2);
  EXPECT_EQ(B0.ders.row(0), B2.ders.row(0));
  // Degree 0 and 1: derivatives above p are exactly zero.
  const Basis1D C = bspline_basis(KnotVector(1, {0, 0, 0.5, 1, 1}), 0.7, 2);
  EXPECT_EQ(C.ders.row(2).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_DOUBLE_EQ(C.ders(1, 0), -2.0);
  EXPECT_DOUBLE_EQ(C.ders(1, 1), 2.0);
}

TEST(BsplineBasis, InvalidInputThrows) {
  const KnotVector kv(2, {0, 0, 0, 1, 1, 1});
  EXPECT_THROW(bspline_basis(kv, 0.5, 3), std::invalid_argument);
  EXPECT_THROW(bspline_basis(kv, 0.5, -1), std::invalid_argument);
  EXPECT_THROW(bspline_basis(kv, std::nan(""), 1), std::invalid_argument);
  try {
    bspline_basis(kv, 0.5, 3);
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("n_derivatives = 3"), std::string::npos) << e.what();
  }
}

namespace {
NurbsCurve random_curve(std::mt19937& g, int p, bool rational) {
  NurbsCurve c;
  c.knots = random_knots(g, p, 3);
  std::uniform_real_distribution<double> W(0.3, 2.5);
  for (int i = 0; i < c.knots.n_basis(); ++i) {
    c.points.push_back(random_vector(g, 3));
    c.weights.push_back(rational ? W(g) : 1.0);
  }
  return c;
}
VecX global_curve_basis(const NurbsCurve& c, double u, int order) {
  const CurveBasis B = curve_basis(c, u);
  VecX R = VecX::Zero(c.n());
  for (int a = 0; a <= c.degree(); ++a) R(B.global_index(c, a)) = B.R(order, a);
  return R;
}
}  // namespace

TEST(NurbsBasis, CurveBasisIsRationalQuotientOfBsplines) {
  std::mt19937 g(4);
  std::uniform_real_distribution<double> U01(0.0, 1.0);
  for (int p = 1; p <= 5; ++p) {
    const NurbsCurve c = random_curve(g, p, true);
    for (int s = 0; s < 30; ++s) {
      const double u = U01(g);
      // (4.9) directly from the literal recursion.
      double W = 0.0;
      const int last = c.knots.element_spans().back();
      for (int i = 0; i < c.n(); ++i)
        W += c.weights[i] * cox_de_boor(c.knots.knots(), i, p, u, last);
      const VecX R = global_curve_basis(c, u, 0);
      for (int i = 0; i < c.n(); ++i)
        EXPECT_NEAR(R(i), c.weights[i] * cox_de_boor(c.knots.knots(), i, p, u, last) / W, 1e-14);
      EXPECT_NEAR(R.sum(), 1.0, 1e-14);
      EXPECT_GE(R.minCoeff(), 0.0);
      if (knot_distance(c.knots, u) < 1e-3) continue;
      for (int order = 1; order <= 2; ++order) {
        auto f = [&](const VecX& x) -> VecX { return global_curve_basis(c, x(0), order - 1); };
        EXPECT_LT(
            rel_diff(global_curve_basis(c, u, order), central_jacobian(f, VecX::Constant(1, u))),
            1e-7);
      }
    }
  }
}

TEST(NurbsBasis, EqualWeightsGiveBsplines) {
  std::mt19937 g(5);
  NurbsCurve c = random_curve(g, 3, false);
  for (double& w : c.weights) w = 2.7;  // equal, not 1: the weights cancel in (4.9)
  EXPECT_FALSE(c.is_rational());
  for (double u : {0.0, 0.2, 0.61, 1.0}) {
    const CurveBasis R = curve_basis(c, u);
    const Basis1D N = bspline_basis(c.knots, u, 2);
    for (int k = 0; k < 3; ++k)  // relative to the row: close random knots make N'' large
      EXPECT_LT((R.R.row(k) - N.ders.row(k)).cwiseAbs().maxCoeff(),
                1e-14 * std::max(1.0, N.ders.row(k).cwiseAbs().maxCoeff()));
  }
}

namespace {
NurbsSurface random_surface(std::mt19937& g, int p, int q, bool rational) {
  NurbsSurface s;
  s.u = random_knots(g, p, 2);
  s.v = random_knots(g, q, 3, -1.0, 2.0);
  std::uniform_real_distribution<double> W(0.3, 2.5);
  for (int k = 0; k < s.n_u() * s.n_v(); ++k) {
    s.points.push_back(random_vector(g, 3));
    s.weights.push_back(rational ? W(g) : 1.0);
  }
  return s;
}
// All rational basis functions (row `row` of SurfaceBasis::R) as a global vector.
VecX global_surface_basis(const NurbsSurface& s, double u, double v, int row) {
  const SurfaceBasis B = surface_basis(s, u, v);
  VecX R = VecX::Zero(s.n_u() * s.n_v());
  for (int k = 0; k < B.R.cols(); ++k) R(B.global_index(s, k)) = B.R(row, k);
  return R;
}
}  // namespace

TEST(NurbsBasis, SurfaceBasisPartitionQuotientAndIndexing) {
  std::mt19937 g(6);
  std::uniform_real_distribution<double> U(0.0, 1.0), V(-1.0, 2.0);
  for (auto [p, q] : {std::pair{1, 1}, {2, 2}, {3, 2}, {2, 4}}) {
    for (bool rational : {false, true}) {
      const NurbsSurface s = random_surface(g, p, q, rational);
      for (int t = 0; t < 20; ++t) {
        const double u = U(g), v = V(g);
        const SurfaceBasis B = surface_basis(s, u, v);
        ASSERT_EQ(B.R.cols(), (p + 1) * (q + 1));
        EXPECT_NEAR(B.R.row(0).sum(), 1.0, 1e-14);
        EXPECT_GE(B.R.row(0).minCoeff(), 0.0);
        for (int r = 1; r < 6; ++r)
          EXPECT_NEAR(B.R.row(r).sum(), 0.0, 1e-12 * std::max(1.0, B.R.row(r).cwiseAbs().sum()));
        // (4.12) from the literal recursion, through the documented index convention.
        const int lu = s.u.element_spans().back(), lv = s.v.element_spans().back();
        double W = 0.0;
        for (int j = 0; j < s.n_v(); ++j)
          for (int i = 0; i < s.n_u(); ++i)
            W += s.weights[i + s.n_u() * j] * cox_de_boor(s.u.knots(), i, p, u, lu) *
                 cox_de_boor(s.v.knots(), j, q, v, lv);
        for (int k = 0; k < B.R.cols(); ++k) {
          const int a = k % (p + 1), b = k / (p + 1);
          const int i = B.span_u - p + a, j = B.span_v - q + b;
          EXPECT_EQ(B.global_index(s, k), i + s.n_u() * j);
          const double ref = s.weights[i + s.n_u() * j] * cox_de_boor(s.u.knots(), i, p, u, lu) *
                             cox_de_boor(s.v.knots(), j, q, v, lv) / W;
          EXPECT_NEAR(B.R(0, k), ref, 1e-14);
        }
      }
    }
  }
}

TEST(NurbsBasis, SurfaceBasisDerivativesMatchCentralDifferences) {
  std::mt19937 g(7);
  std::uniform_real_distribution<double> U(0.0, 1.0), V(-1.0, 2.0);
  for (auto [p, q] : {std::pair{1, 2}, {2, 2}, {3, 3}}) {
    for (bool rational : {false, true}) {
      const NurbsSurface s = random_surface(g, p, q, rational);
      for (int t = 0; t < 10; ++t) {
        const double u = U(g), v = V(g);
        if (knot_distance(s.u, u) < 1e-3 || knot_distance(s.v, v) < 1e-3) continue;
        const VecX x = (VecX(2) << u, v).finished();
        // Rows (R, R_ξ, R_η) differentiated give (R_ξ R_η), (R_ξξ R_ξη), (R_ξη R_ηη).
        const int first[3][2] = {{1, 2}, {3, 4}, {4, 5}};
        for (int r = 0; r < 3; ++r) {
          auto f = [&](const VecX& y) -> VecX { return global_surface_basis(s, y(0), y(1), r); };
          const MatX J = central_jacobian(f, x);
          EXPECT_LT(rel_diff(global_surface_basis(s, u, v, first[r][0]), J.col(0)), 1e-7);
          EXPECT_LT(rel_diff(global_surface_basis(s, u, v, first[r][1]), J.col(1)), 1e-7);
        }
      }
    }
  }
}
