// B-spline and NURBS bases: compared with an independent, literal implementation of the
// Cox–de Boor recursion IGA-thesis (4.3), with the Bernstein polynomials (4.2) for the knot
// vector (4.5), with central finite differences, and checked for partition of unity and
// non-negativity.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "isoflex/geometry/bspline_basis.hpp"
#include "isoflex/geometry/nurbs_curve.hpp"
#include "isoflex/geometry/nurbs_surface.hpp"
#include "support/finite_difference.hpp"
#include "support/geometry.hpp"

using namespace isoflex;
using namespace isoflex::geometry;
using namespace isoflex::test;

namespace {

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

// All n_basis functions (zeros outside the support) as one global vector.
VecX global_basis(const KnotVector& kv, double u, int order) {
  const Basis1D B = bspline_basis(kv, u, 2);
  VecX N = VecX::Zero(kv.n_basis());
  for (int j = 0; j <= kv.degree(); ++j) N(B.span - kv.degree() + j) = B.ders(order, j);
  return N;
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
// This file's random curves: knots on [0, 1], weights in [0.3, 2.5].
NurbsCurve random_curve(std::mt19937& g, int p, bool rational) {
  return random_nurbs_curve(g, random_knots(g, p, 3), rational, 0.3, 2.5);
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
// This file's random surfaces: ξ ∈ [0, 1], η ∈ [−1, 2], weights in [0.3, 2.5].
NurbsSurface random_surface(std::mt19937& g, int p, int q, bool rational) {
  KnotVector u = random_knots(g, p, 2);
  KnotVector v = random_knots(g, q, 3, -1.0, 2.0);
  return random_nurbs_surface(g, std::move(u), std::move(v), rational, 0.3, 2.5);
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

namespace {
// d^k N_a, k = 0..2, for all functions of a knot vector at u, by the literal recursion.
std::vector<std::array<long double, 3>> literal_ders(const KnotVector& kv, double u) {
  const int last = kv.element_spans().back();
  std::vector<std::array<long double, 3>> d(kv.n_basis());
  for (int i = 0; i < kv.n_basis(); ++i)
    for (int k = 0; k < 3; ++k) d[i][k] = cox_de_boor_der(kv.knots(), i, kv.degree(), u, k, last);
  return d;
}

// Parameters for the exactness tests: the ends, every distinct knot and random points of the
// domain.
std::vector<double> test_parameters(std::mt19937& g, const KnotVector& kv, int n_random) {
  std::vector<double> us = {kv.front(), kv.back()};
  for (double k : kv.breakpoints()) us.push_back(k);
  std::uniform_real_distribution<double> U(kv.front(), kv.back());
  for (int s = 0; s < n_random; ++s) us.push_back(U(g));
  return us;
}
}  // namespace

// surface_basis factors the quotient rule into 1D functions and vectorizes it
// (nurbs_surface.cpp); here the rational derivatives are computed the plain way over the whole
// patch, the quotient rule of IGA-thesis (4.12) in long double on the literal recursion (4.3):
//   R = A/W, R_ξ = (A_ξ − R W_ξ)/W, R_ξξ = (A_ξξ − 2 R_ξ W_ξ − R W_ξξ)/W,
//   R_ξη = (A_ξη − R_ξ W_η − R_η W_ξ − R W_ξη)/W.
// Degrees 0 … 5 (also p ≠ q), repeated knots, points exactly at the knots and at the ends.
TEST(NurbsBasis, SurfaceBasisMatchesPlainQuotientRuleOnLiteralRecursion) {
  std::mt19937 g(8);
  double worst = 0.0;
  for (auto [p, q] :
       {std::pair{0, 0}, {0, 2}, {1, 1}, {2, 1}, {2, 2}, {3, 3}, {2, 4}, {4, 4}, {5, 5}, {5, 3}}) {
    for (bool rational : {false, true}) {
      const NurbsSurface s = random_surface(g, p, q, rational);
      const auto us = test_parameters(g, s.u, 6), vs = test_parameters(g, s.v, 6);
      for (double u : us)
        for (double v : vs) {
          const auto Nu = literal_ders(s.u, u), Nv = literal_ders(s.v, v);
          // A_ij and its derivatives (order: value, ξ, η, ξξ, ξη, ηη), and the sums W.
          const int pairs[6][2] = {{0, 0}, {1, 0}, {0, 1}, {2, 0}, {1, 1}, {0, 2}};
          std::vector<std::array<long double, 6>> A(s.n_u() * s.n_v());
          std::array<long double, 6> W{};
          for (int j = 0; j < s.n_v(); ++j)
            for (int i = 0; i < s.n_u(); ++i)
              for (int d = 0; d < 6; ++d) {
                const int idx = s.index(i, j);
                A[idx][d] = s.weights[idx] * Nu[i][pairs[d][0]] * Nv[j][pairs[d][1]];
                W[d] += A[idx][d];
              }
          const SurfaceBasis B = surface_basis(s, u, v);
          ASSERT_EQ(B.R.cols(), (p + 1) * (q + 1));
          std::array<double, 6> scale{};  // size of each row, for a relative comparison
          for (int d = 0; d < 6; ++d) scale[d] = std::max(1.0, B.R.row(d).cwiseAbs().maxCoeff());
          for (int k = 0; k < B.R.cols(); ++k) {
            const auto& a = A[B.global_index(s, k)];
            const long double R = a[0] / W[0];
            const long double Ru = (a[1] - R * W[1]) / W[0];
            const long double Rv = (a[2] - R * W[2]) / W[0];
            const long double Ruu = (a[3] - 2 * Ru * W[1] - R * W[3]) / W[0];
            const long double Ruv = (a[4] - Ru * W[2] - Rv * W[1] - R * W[4]) / W[0];
            const long double Rvv = (a[5] - 2 * Rv * W[2] - R * W[5]) / W[0];
            const long double ref[6] = {R, Ru, Rv, Ruu, Ruv, Rvv};
            for (int d = 0; d < 6; ++d) {
              const double err = std::abs(static_cast<double>(B.R(d, k) - ref[d])) / scale[d];
              worst = std::max(worst, err);
              EXPECT_LT(err, 1e-12) << "p=" << p << " q=" << q << " u=" << u << " v=" << v
                                    << " k=" << k << " row " << d;
            }
          }
        }
    }
  }
  RecordProperty("worst_rel_error", sci(worst));
}

TEST(NurbsBasis, CurveBasisMatchesPlainQuotientRuleOnLiteralRecursion) {
  std::mt19937 g(9);
  double worst = 0.0;
  for (int p = 0; p <= 6; ++p) {
    const NurbsCurve c = random_curve(g, p, true);
    for (double u : test_parameters(g, c.knots, 20)) {
      const auto N = literal_ders(c.knots, u);
      long double W[3] = {0, 0, 0};
      for (int i = 0; i < c.n(); ++i)
        for (int k = 0; k < 3; ++k) W[k] += c.weights[i] * N[i][k];
      const CurveBasis B = curve_basis(c, u);
      for (int a = 0; a <= p; ++a) {
        const int i = B.global_index(c, a);
        const long double R = c.weights[i] * N[i][0] / W[0];
        const long double R1 = (c.weights[i] * N[i][1] - R * W[1]) / W[0];
        const long double R2 = (c.weights[i] * N[i][2] - 2 * R1 * W[1] - R * W[2]) / W[0];
        const long double ref[3] = {R, R1, R2};
        for (int k = 0; k < 3; ++k) {
          const double scale = std::max(1.0, B.R.row(k).cwiseAbs().maxCoeff());
          const double err = std::abs(static_cast<double>(B.R(k, a) - ref[k])) / scale;
          worst = std::max(worst, err);
          EXPECT_LT(err, 1e-12) << "p=" << p << " u=" << u << " a=" << a << " k=" << k;
        }
      }
    }
  }
  RecordProperty("worst_rel_error", sci(worst));
}

// The fast path writes exactly what bspline_basis returns; outside the domain both bases clamp,
// and a NaN parameter throws.
TEST(NurbsBasis, FastPathsClampAndRejectNaN) {
  std::mt19937 g(10);
  for (int p = 0; p <= kMaxDegree; ++p) {
    const KnotVector kv = random_knots(g, p, 4);
    for (double u : test_parameters(g, kv, 10)) {
      const Basis1D B = bspline_basis(kv, u, 2);
      BasisArray d;
      bspline_basis_unchecked(kv, kv.find_span(u), u, d);
      for (int k = 0; k < 3; ++k)
        for (int j = 0; j <= p; ++j) EXPECT_EQ(d[k][j], B.ders(k, j)) << "p=" << p << " u=" << u;
    }
  }
  const NurbsSurface s = random_surface(g, 3, 2, true);  // ξ ∈ [0, 1], η ∈ [−1, 2]
  EXPECT_EQ(surface_basis(s, -0.5, 7.0).R, surface_basis(s, 0.0, 2.0).R);
  EXPECT_EQ(surface_basis(s, 1.5, -3.0).R, surface_basis(s, 1.0, -1.0).R);
  EXPECT_THROW(surface_basis(s, std::nan(""), 0.5), std::invalid_argument);
  EXPECT_THROW(surface_basis(s, 0.5, std::nan("")), std::invalid_argument);
  const NurbsCurve c = random_curve(g, 3, true);
  EXPECT_EQ(curve_basis(c, -1.0).R, curve_basis(c, 0.0).R);
  EXPECT_EQ(curve_basis(c, 2.0).R, curve_basis(c, 1.0).R);
  EXPECT_THROW(curve_basis(c, std::nan("")), std::invalid_argument);
}
