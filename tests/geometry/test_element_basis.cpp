// element_basis (all points of an element's tensor grid at once) against the point API
// surface_basis, which is tested against the literal Cox–de Boor recursion in test_basis.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "isoflex/geometry/bspline_basis.hpp"
#include "isoflex/geometry/element_basis.hpp"
#include "isoflex/geometry/nurbs_surface.hpp"
#include "isoflex/geometry/quadrature.hpp"
#include "support/geometry.hpp"

using namespace isoflex;
using namespace isoflex::geometry;
using namespace isoflex::test;

namespace {

// Rational surface of degree (p, q): random interior knots (multiplicities 1 … p, so some
// elements are bounded by C⁰ lines) and weights in [0.3, 2.5].
NurbsSurface rational_surface(std::mt19937& g, int p, int q) {
  KnotVector u = random_knots(g, p, 3);
  KnotVector v = random_knots(g, q, 2, -1.0, 2.0);
  return random_nurbs_surface(g, std::move(u), std::move(v), true, 0.3, 2.5);
}

struct Comparison {
  double worst = 0.0;  // largest |difference| relative to the row's largest entry (≥ 1)
  long values = 0, identical = 0;
};

// Every value of element_basis at every grid point against surface_basis at the same point.
void compare_with_point_api(const NurbsSurface& s, const ElementBasis& E, Comparison& c) {
  ASSERT_EQ(E.n_functions, (s.degree_u() + 1) * (s.degree_v() + 1));
  ASSERT_EQ(E.row_stride, E.n_functions + E.n_functions % 2);
  ASSERT_EQ(E.values.size(), 6u * E.row_stride * E.n_points());
  for (int j = 0; j < E.n_v; ++j)
    for (int i = 0; i < E.n_u; ++i) {
      const int g = i + E.n_u * j;
      const SurfaceBasis B = surface_basis(s, E.xi[i], E.eta[j]);
      ASSERT_EQ(B.span_u, E.span_u);
      ASSERT_EQ(B.span_v, E.span_v);
      const auto R = E.R(g);
      for (int d = 0; d < 6; ++d) {
        const double scale = std::max(1.0, B.R.row(d).cwiseAbs().maxCoeff());
        for (int k = 0; k < E.n_functions; ++k) {
          const double err = std::abs(R(d, k) - B.R(d, k)) / scale;
          c.worst = std::max(c.worst, err);
          ++c.values;
          if (R(d, k) == B.R(d, k)) ++c.identical;
          EXPECT_LE(err, 1e-14) << "p=" << s.degree_u() << " q=" << s.degree_v()
                                << " xi=" << E.xi[i] << " eta=" << E.eta[j] << " row " << d
                                << " k=" << k;
        }
      }
      for (int k = 0; k < E.n_functions; ++k) EXPECT_EQ(E.global_index(s, k), B.global_index(s, k));
    }
}

}  // namespace

// Degrees 0 … 5 in both directions (all 36 pairs), rational, every element, Gauss grids of 1 …
// p+2 points per direction (n_u ≠ n_v too), and random points of the element including its
// left/lower edges: the same values as the point API to ≤ 1e-14 relative to the row (the
// kernels perform the same operations in the same order, so they are in fact identical).
TEST(ElementBasis, EqualsPointApiForAllDegreesAndGrids) {
  std::mt19937 g(21);
  Comparison c;
  ElementBasis E;  // one object for all calls: its storage is reused and resized
  for (int p = 0; p <= 5; ++p)
    for (int q = 0; q <= 5; ++q) {
      const NurbsSurface s = rational_surface(g, p, q);
      const auto elements = surface_elements(s);
      for (std::size_t e = 0; e < elements.size(); ++e) {
        const SurfaceElement& el = elements[e];
        const int nu = 1 + static_cast<int>((e + p) % (p + 2));
        const int nv = 1 + static_cast<int>((e + 2 * q + 1) % (q + 2));
        element_basis(s, el, gauss_legendre(nu), gauss_legendre(nv), E);
        ASSERT_EQ(E.n_u, nu);
        ASSERT_EQ(E.n_v, nv);
        compare_with_point_api(s, E, c);
        // Random points, and the lower-left corner of the element (a knot in both directions).
        std::uniform_real_distribution<double> U(el.u0, el.u1), V(el.v0, el.v1);
        std::vector<double> xi = {el.u0}, eta = {el.v0};
        for (int k = 0; k < 3; ++k) xi.push_back(U(g));
        for (int k = 0; k < 2; ++k) eta.push_back(V(g));
        element_basis(s, el.span_u, el.span_v, xi, eta, E);
        compare_with_point_api(s, E, c);
      }
    }
  RecordProperty("worst_rel_difference", sci(c.worst));
  RecordProperty("identical_fraction", sci(static_cast<double>(c.identical) / c.values));
}

// Degrees above the fixed-degree kernels (p or q > 5) take the run-time-degree kernel.
TEST(ElementBasis, EqualsPointApiForHighDegrees) {
  std::mt19937 g(26);
  Comparison c;
  ElementBasis E;
  for (auto [p, q] : {std::pair{6, 2}, {1, 7}, {6, 6}, {8, 5}, {10, 10}, {10, 0}, {3, 9}}) {
    const NurbsSurface s = rational_surface(g, p, q);
    int e = 0;
    for (const SurfaceElement& el : surface_elements(s)) {
      const int nu = 1 + (e + p) % (p + 2), nv = 1 + (e + q) % (q + 2);
      element_basis(s, el, gauss_legendre(nu), gauss_legendre(nv), E);
      compare_with_point_api(s, E, c);
      ++e;
    }
  }
  RecordProperty("worst_rel_difference", sci(c.worst));
  RecordProperty("identical_fraction", sci(static_cast<double>(c.identical) / c.values));
}

// The Gauss overload evaluates at element_quadrature's points, in its order; the row sums are a
// partition of unity and its derivatives.
TEST(ElementBasis, GaussPointsAreElementQuadraturePoints) {
  std::mt19937 g(22);
  const NurbsSurface s = rational_surface(g, 3, 2);
  const GaussRule ru = gauss_legendre(4), rv = gauss_legendre(3);
  ElementBasis E;
  for (const SurfaceElement& el : surface_elements(s)) {
    element_basis(s, el, ru, rv, E);
    const auto qp = element_quadrature(el, ru, rv);
    ASSERT_EQ(static_cast<int>(qp.size()), E.n_points());
    for (int pt = 0; pt < E.n_points(); ++pt) {
      EXPECT_EQ(qp[pt].xi, E.xi[pt % E.n_u]);
      EXPECT_EQ(qp[pt].eta, E.eta[pt / E.n_u]);
      const auto R = E.R(pt);
      EXPECT_NEAR(R.row(0).sum(), 1.0, 1e-14);
      for (int d = 1; d < 6; ++d) EXPECT_NEAR(R.row(d).sum(), 0.0, 1e-11);
    }
  }
}

// The end of the domain belongs to the last element (as for surface_basis); a point on the
// upper/right edge of an inner element takes that element's polynomial piece, whose values R
// agree with the neighbour's (the surface is C⁰ there: knot multiplicities ≤ p).
TEST(ElementBasis, DomainEndAndElementEdges) {
  std::mt19937 g(23);
  const NurbsSurface s = rational_surface(g, 2, 3);
  const auto elements = surface_elements(s);
  const SurfaceElement& last = elements.back();
  ElementBasis E;
  element_basis(s, last.span_u, last.span_v, std::vector<double>{last.u1},
                std::vector<double>{last.v1}, E);
  Comparison c;
  compare_with_point_api(s, E, c);
  for (const SurfaceElement& el : elements) {
    const std::vector<double> xi = {el.u1}, eta = {el.v1};
    element_basis(s, el.span_u, el.span_v, xi, eta, E);
    const SurfaceBasis B = surface_basis(s, el.u1, el.v1);
    std::vector<double> mine(s.n_u() * s.n_v(), 0.0), theirs(mine);
    for (int k = 0; k < E.n_functions; ++k) {
      mine[E.global_index(s, k)] = E.R(0)(0, k);
      theirs[B.global_index(s, k)] = B.R(0, k);
    }
    for (std::size_t i = 0; i < mine.size(); ++i) EXPECT_NEAR(mine[i], theirs[i], 1e-14);
  }
}

TEST(ElementBasis, RejectsBadInput) {
  std::mt19937 g(24);
  NurbsSurface s(rational_surface(g, 2, 2));
  const SurfaceElement el = surface_elements(s).front();
  const std::vector<double> inside = {0.5 * (el.u0 + el.u1)}, inside_v = {0.5 * (el.v0 + el.v1)};
  ElementBasis E;
  EXPECT_NO_THROW(element_basis(s, el.span_u, el.span_v, inside, inside_v, E));
  const std::vector<double> outside = {el.u1 + 1e-3}, nan = {std::nan("")}, none;
  EXPECT_THROW(element_basis(s, el.span_u, el.span_v, outside, inside_v, E), std::invalid_argument);
  EXPECT_THROW(element_basis(s, el.span_u, el.span_v, nan, inside_v, E), std::invalid_argument);
  EXPECT_THROW(element_basis(s, el.span_u, el.span_v, inside, nan, E), std::invalid_argument);
  EXPECT_THROW(element_basis(s, el.span_u, el.span_v, none, inside_v, E), std::invalid_argument);
  EXPECT_THROW(element_basis(s, 0, el.span_v, inside, inside_v, E), std::invalid_argument);
  EXPECT_THROW(element_basis(s, s.n_u(), el.span_v, inside, inside_v, E), std::invalid_argument);
  SurfaceElement moved = el;
  moved.u1 = 0.5 * (el.u0 + el.u1);  // not the element of span_u
  EXPECT_THROW(element_basis(s, moved, gauss_legendre(2), gauss_legendre(2), E),
               std::invalid_argument);
  EXPECT_THROW(element_basis(s, el, GaussRule{}, gauss_legendre(2), E), std::invalid_argument);
  // A zero-length span of a repeated knot.
  const KnotVector kv(2, {0, 0, 0, 0.5, 0.5, 1, 1, 1});
  NurbsSurface r = random_nurbs_surface(g, kv, kv, true, 0.5, 2.0);
  const std::vector<double> half = {0.5};
  EXPECT_THROW(element_basis(r, 3, 4, half, half, E), std::invalid_argument);
  EXPECT_NO_THROW(element_basis(r, 4, 4, half, half, E));
  r.weights.pop_back();
  EXPECT_THROW(element_basis(r, 4, 4, half, half, E), std::invalid_argument);
  // The parameters may be passed from the object itself.
  element_basis(s, el.span_u, el.span_v, inside, inside_v, E);
  element_basis(s, el.span_u, el.span_v, E.xi, E.eta, E);
  EXPECT_EQ(E.xi, inside);
  EXPECT_EQ(E.eta, inside_v);
}

// bspline_basis_span_unchecked writes, point by point, exactly what bspline_basis_unchecked does.
TEST(ElementBasis, SpanKernelEqualsPointKernel) {
  std::mt19937 g(25);
  for (int p = 0; p <= kMaxDegree; ++p) {
    const KnotVector kv = random_knots(g, p, 4);
    for (const int span : kv.element_spans()) {
      std::uniform_real_distribution<double> U(kv.knots()[span], kv.knots()[span + 1]);
      std::vector<double> u = {kv.knots()[span]};
      for (int k = 0; k < 4; ++k) u.push_back(U(g));
      const int stride = p + 1 + span % 2;  // compact, and with a gap
      std::vector<double> d(3 * stride * u.size(), -7.0);
      bspline_basis_span_unchecked(kv, span, u.data(), static_cast<int>(u.size()), d.data(),
                                   stride);
      for (std::size_t i = 0; i < u.size(); ++i) {
        BasisArray ref;
        bspline_basis_unchecked(kv, span, u[i], ref);
        for (int k = 0; k < 3; ++k) {
          for (int a = 0; a <= p; ++a)
            EXPECT_EQ(d[(3 * i + k) * stride + a], ref[k][a]) << "p=" << p << " u=" << u[i];
          for (int a = p + 1; a < stride; ++a) EXPECT_EQ(d[(3 * i + k) * stride + a], -7.0);
        }
      }
    }
  }
}
