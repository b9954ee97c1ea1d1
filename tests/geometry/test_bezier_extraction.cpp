// Bézier extraction: operators against hand-derived matrices and against the Cox–de Boor
// recursion (IGA-thesis (4.3)) written out here, rational Bézier cells against the NURBS surface
// (IGA-thesis (4.12)–(4.13)) and against the analytic cylinder. The Bernstein polynomials of the
// checks are the closed form (4.2), not the library's de Casteljau evaluation.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "isoflex/geometry/bezier_extraction.hpp"
#include "isoflex/geometry/nurbs_surface.hpp"
#include "support/geometry.hpp"

namespace isoflex::geometry {
namespace {

using namespace isoflex::test;

// IGA-thesis (4.2).
double bernstein_closed(int p, int k, double t) {
  double binom = 1.0;
  for (int i = 1; i <= k; ++i) binom = binom * (p - k + i) / i;
  return binom * std::pow(t, k) * std::pow(1.0 - t, p - k);
}

// IGA-thesis (4.3) with 0/0 := 0, on the half-open spans; `last` closes the final span.
double cox_de_boor(const std::vector<double>& U, int i, int p, double u) {
  if (p == 0) {
    const double hi = U.back();
    if (u == hi) return (U[i] < hi && U[i + 1] == hi) ? 1.0 : 0.0;  // u = b: last span
    return (U[i] <= u && u < U[i + 1]) ? 1.0 : 0.0;
  }
  double v = 0.0;
  const double d1 = U[i + p] - U[i], d2 = U[i + p + 1] - U[i + 1];
  if (d1 > 0.0) v += (u - U[i]) / d1 * cox_de_boor(U, i, p - 1, u);
  if (d2 > 0.0) v += (U[i + p + 1] - u) / d2 * cox_de_boor(U, i + 1, p - 1, u);
  return v;
}

TEST(BezierExtraction, Bernstein) {
  for (int p = 0; p <= 6; ++p) {
    for (const double t : {0.0, 0.13, 0.5, 0.77, 1.0}) {
      const BernsteinTable b = bernstein(p, t);
      for (int k = 0; k <= p; ++k) {
        EXPECT_NEAR(b(0, k), bernstein_closed(p, k, t), 1e-15);
        // Derivatives against central differences of the closed form.
        if (t > 0.0 && t < 1.0) {
          const double h = 1e-5;
          const double f1 =
              (bernstein_closed(p, k, t + h) - bernstein_closed(p, k, t - h)) / (2 * h);
          const double f2 = (bernstein_closed(p, k, t + h) - 2 * bernstein_closed(p, k, t) +
                             bernstein_closed(p, k, t - h)) /
                            (h * h);
          EXPECT_NEAR(b(1, k), f1, 1e-8 * (1 + p * p));
          EXPECT_NEAR(b(2, k), f2, 1e-4 * (1 + p * p * p));
        }
      }
    }
  }
}

// Derived by hand (two Boehm insertions per span) for p = 2, Ξ = (0,0,0,1,2,3,3,3).
TEST(BezierExtraction, QuadraticUniformOperatorsByHand) {
  const CurveExtraction x = extract_curve(KnotVector(2, {0, 0, 0, 1, 2, 3, 3, 3}));
  ASSERT_EQ(x.operators.size(), 3u);
  Mat<3, 3> C1, C2, C3;
  C1 << 1, 0, 0, 0, 1, 0.5, 0, 0, 0.5;
  C2 << 0.5, 0, 0, 0.5, 1, 0.5, 0, 0, 0.5;
  C3 << 0.5, 0, 0, 0.5, 1, 0, 0, 0, 1;
  EXPECT_LT((x.operators[0] - C1).norm(), 1e-15);
  EXPECT_LT((x.operators[1] - C2).norm(), 1e-15);
  EXPECT_LT((x.operators[2] - C3).norm(), 1e-15);
}

TEST(BezierExtraction, CurveOperatorsReproduceCoxDeBoor) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U01(0.0, 1.0);
  const std::vector<std::vector<double>> interior = {
      {}, {0.5}, {0.25, 0.5, 0.75}, {0.3, 0.3, 0.6}, {0.2, 0.2, 0.2, 0.7}, {0.1, 0.4, 0.4, 0.9}};
  double worst = 0.0;
  for (int p = 1; p <= 5; ++p) {
    for (const auto& in : interior) {
      // Interior multiplicity must stay ≤ p.
      bool ok = true;
      for (const double k : in)
        if (std::count(in.begin(), in.end(), k) > p) ok = false;
      if (!ok) continue;
      std::vector<double> U(p + 1, 0.0);
      U.insert(U.end(), in.begin(), in.end());
      U.insert(U.end(), p + 1, 1.0);
      const KnotVector kv(p, U);
      const CurveExtraction x = extract_curve(kv);
      // Number of elements = distinct breakpoints − 1.
      std::vector<double> bp = in;
      bp.erase(std::unique(bp.begin(), bp.end()), bp.end());
      ASSERT_EQ(x.operators.size(), bp.size() + 1);
      for (std::size_t e = 0; e < x.elements.size(); ++e) {
        const MatX& C = x.operators[e];
        ASSERT_EQ(C.rows(), p + 1);
        ASSERT_EQ(C.cols(), p + 1);
        for (int k = 0; k <= p; ++k) EXPECT_NEAR(C.col(k).sum(), 1.0, 1e-14);
        EXPECT_GE(C.minCoeff(), -1e-15);  // refinement of non-negative functions
        const auto& el = x.elements[e];
        for (int trial = 0; trial < 10; ++trial) {
          const double t = trial == 0 ? 0.0 : U01(rng);
          const double u = el.a + t * (el.b - el.a);
          for (int i = 0; i <= p; ++i) {
            double nb = 0.0;
            for (int k = 0; k <= p; ++k) nb += C(i, k) * bernstein_closed(p, k, t);
            const double err = std::abs(nb - cox_de_boor(U, el.span - p + i, p, u));
            worst = std::max(worst, err);
            EXPECT_LT(err, 1e-14) << "p=" << p << " e=" << e << " i=" << i;
          }
        }
      }
    }
  }
  RecordProperty("worst_basis_error", sci(worst));
}

// A rational bicubic × quadratic patch with scattered weights and a double knot in ξ.
NurbsSurface wavy_rational() {
  NurbsSurface s;
  s.u = KnotVector(3, {0, 0, 0, 0, 0.3, 0.3, 0.7, 1, 1, 1, 1});
  s.v = KnotVector(2, {0, 0, 0, 0.4, 0.6, 1, 1, 1});
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> w(0.5, 2.0);
  for (int j = 0; j < s.n_v(); ++j)
    for (int i = 0; i < s.n_u(); ++i) {
      s.points.push_back(Vec3(i, 0.7 * j, 0.3 * std::sin(1.3 * i) * std::cos(0.9 * j)));
      s.weights.push_back(w(rng));
    }
  return s;
}

Vec3 eval_cell_closed(const RationalBezierCell& c, double tu, double tv) {
  Vec3 num = Vec3::Zero();
  double den = 0.0;
  for (int l = 0; l <= c.q; ++l)
    for (int k = 0; k <= c.p; ++k) {
      const int a = k + (c.p + 1) * l;
      const double bw = bernstein_closed(c.p, k, tu) * bernstein_closed(c.q, l, tv) * c.weights[a];
      num += bw * c.points[a];
      den += bw;
    }
  return num / den;
}

TEST(BezierExtraction, SurfaceSizesWithRepeatedKnots) {
  const NurbsSurface s = wavy_rational();
  const SurfaceExtraction x = extract_surface(s);
  EXPECT_EQ(x.p, 3);
  EXPECT_EQ(x.q, 2);
  EXPECT_EQ(x.n_elements_u, 3);  // breakpoints 0, 0.3, 0.7, 1
  EXPECT_EQ(x.n_elements_v, 3);
  ASSERT_EQ(x.elements.size(), 9u);
  for (const auto& e : x.elements) {
    EXPECT_EQ(e.global.size(), 12u);
    EXPECT_EQ(e.C.rows(), 12);
    EXPECT_EQ(e.C.cols(), 12);
    for (const int g : e.global) {
      EXPECT_GE(g, 0);
      EXPECT_LT(g, static_cast<int>(s.points.size()));
    }
  }
  const auto cells = bezier_cells(s, x);
  ASSERT_EQ(cells.size(), 9u);
  for (const auto& c : cells) {
    EXPECT_EQ(c.points.size(), 12u);
    EXPECT_EQ(c.weights.size(), 12u);
  }
}

TEST(BezierExtraction, RationalCellsReproduceTheSurface) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U01(0.0, 1.0);
  double worst = 0.0;
  for (const NurbsSurface& s : {half_cylinder(1.7, 2.0), wavy_rational()}) {
    for (const auto& c : bezier_cells(s)) {
      for (int trial = 0; trial < 25; ++trial) {
        const double tu = U01(rng), tv = U01(rng);
        const double xi = c.element.u0 + tu * (c.element.u1 - c.element.u0);
        const double eta = c.element.v0 + tv * (c.element.v1 - c.element.v0);
        const Vec3 ref = evaluate(s, xi, eta).x;
        const double err = (eval_cell_closed(c, tu, tv) - ref).norm();
        worst = std::max(worst, err);
        EXPECT_LT(err, 1e-13);
        EXPECT_LT((evaluate(c, tu, tv) - ref).norm(), 1e-13);
      }
    }
  }
  RecordProperty("worst_cell_error", sci(worst));
}

TEST(BezierExtraction, HalfCylinderCellsLieOnTheRadius) {
  const double R = 1.7, H = 2.0;
  const NurbsSurface s = half_cylinder(R, H);
  const auto cells = bezier_cells(s);
  ASSERT_EQ(cells.size(), 4u);  // 2 arcs × 2 spans along the axis
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U01(0.0, 1.0);
  for (const auto& c : cells) {
    // The arcs' Bézier weights: ends 1, middle 1/√2 (the knot vector is already Bézier in ξ).
    for (int l = 0; l <= c.q; ++l) {
      EXPECT_NEAR(c.weights[0 + 3 * l] / c.weights[2 + 3 * l], 1.0, 1e-15);
      EXPECT_NEAR(c.weights[1 + 3 * l] / c.weights[0 + 3 * l], std::sqrt(0.5), 1e-15);
    }
    for (int trial = 0; trial < 50; ++trial) {
      const Vec3 x = eval_cell_closed(c, U01(rng), U01(rng));
      EXPECT_NEAR(std::hypot(x.x(), x.y()), R, 1e-14);
      EXPECT_GE(x.z(), -1e-15);
      EXPECT_LE(x.z(), H + 1e-15);
    }
  }
}

// The assembly view: R_i of surface_basis (column a ↔ global_index) equals the rational basis
// built from C_e and the Bernstein polynomials, R_i = w_i (C_e B)_i / Σ_j w_j (C_e B)_j.
TEST(BezierExtraction, ElementViewMatchesSurfaceBasis) {
  const NurbsSurface s = wavy_rational();
  const SurfaceExtraction x = extract_surface(s);
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> U01(0.0, 1.0);
  for (const auto& e : x.elements) {
    for (int trial = 0; trial < 5; ++trial) {
      const double tu = U01(rng), tv = U01(rng);
      const double xi = e.element.u0 + tu * (e.element.u1 - e.element.u0);
      const double eta = e.element.v0 + tv * (e.element.v1 - e.element.v0);
      VecX B(12);
      for (int l = 0; l <= 2; ++l)
        for (int k = 0; k <= 3; ++k)
          B(k + 4 * l) = bernstein_closed(3, k, tu) * bernstein_closed(2, l, tv);
      VecX N = e.C * B;
      for (int i = 0; i < 12; ++i) N(i) *= s.weights[e.global[i]];
      N /= N.sum();
      const SurfaceBasis sb = surface_basis(s, xi, eta);
      ASSERT_EQ(sb.span_u, e.element.span_u);
      ASSERT_EQ(sb.span_v, e.element.span_v);
      for (int a = 0; a < 12; ++a) {
        EXPECT_EQ(sb.global_index(s, a), e.global[a]);
        EXPECT_NEAR(sb.R(0, a), N(a), 1e-14);
      }
    }
  }
}

TEST(BezierExtraction, FieldExtraction) {
  // A field equal to the control points' coordinates is the position itself: its rational Bézier
  // form must reproduce S(ξ, η).
  const NurbsSurface s = wavy_rational();
  std::vector<double> values;
  for (const Vec3& p : s.points) values.insert(values.end(), {p.x(), p.y(), p.z()});
  const SurfaceExtraction x = extract_surface(s);
  const auto cells = bezier_cells(s, x);
  for (std::size_t e = 0; e < x.elements.size(); ++e) {
    const auto f = extract_field(s, x.elements[e], values, 3);
    ASSERT_EQ(f.size(), 36u);
    for (int k = 0; k < 12; ++k)
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(f[3 * k + c], cells[e].points[k](c), 1e-14);
  }
  EXPECT_THROW(extract_field(s, x.elements[0], {1.0, 2.0}, 3), std::invalid_argument);
}

}  // namespace
}  // namespace isoflex::geometry
