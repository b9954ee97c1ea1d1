#pragma once
// Geometry for tests: random knot vectors, curves and surfaces, fixed test surfaces, and small
// helpers for error messages and reported numbers.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "isoflex/geometry/bspline_basis.hpp"
#include "isoflex/geometry/knot_vector.hpp"
#include "isoflex/geometry/nurbs_curve.hpp"
#include "isoflex/geometry/nurbs_surface.hpp"
#include "support/finite_difference.hpp"

namespace isoflex::test {

// π, for angles in the tests.
inline constexpr double kPi = std::numbers::pi;

// All n basis functions of kv at u, zero outside the p + 1 non-zero ones.
inline VecX all_basis_functions(const geometry::KnotVector& kv, double u) {
  const geometry::Basis1D b = geometry::bspline_basis(kv, u, 0);
  VecX N = VecX::Zero(kv.n_basis());
  for (int j = 0; j <= kv.degree(); ++j) N(b.span - kv.degree() + j) = b.ders(0, j);
  return N;
}

// Scientific notation for RecordProperty (std::to_string prints 0.000000 for 1e-15).
inline std::string sci(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2e", v);
  return buf;
}

// Message of the std::invalid_argument thrown by f (empty if none).
template <class F>
std::string message_of(F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

// Open knot vector on [a, b]: n_interior random knots from [lo, hi], each of multiplicity 1..p.
inline geometry::KnotVector random_knots(std::mt19937& g, int p, int n_interior, double a, double b,
                                         double lo, double hi) {
  std::uniform_real_distribution<double> U(lo, hi);
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
  return geometry::KnotVector(p, k);
}

// Open knot vector on [a, b] with n_interior random knots anywhere inside (multiplicity 1..p).
inline geometry::KnotVector random_knots(std::mt19937& g, int p, int n_interior, double a = 0.0,
                                         double b = 1.0) {
  return random_knots(g, p, n_interior, a, b, a, b);
}

// Open knot vector on [a, b] with jittered, well-separated interior knots (for finite differences).
inline geometry::KnotVector jittered_knots(std::mt19937& g, int p, int n_interior, double a,
                                           double b) {
  std::uniform_real_distribution<double> J(-0.25, 0.25);
  std::vector<double> k(p + 1, a);
  for (int i = 1; i <= n_interior; ++i) {
    const double x = a + (b - a) * (i + J(g)) / (n_interior + 1);
    const int m = 1 + static_cast<int>(g() % std::max(1, p));
    k.insert(k.end(), m, x);
  }
  k.insert(k.end(), p + 1, b);
  return geometry::KnotVector(p, k);
}

// Curve on `knots`, control points in [−1, 1]³, weights from [w_min, w_max] if rational (else 1).
inline geometry::NurbsCurve random_nurbs_curve(std::mt19937& g, geometry::KnotVector knots,
                                               bool rational, double w_min, double w_max) {
  geometry::NurbsCurve c;
  c.knots = std::move(knots);
  std::uniform_real_distribution<double> W(w_min, w_max);
  for (int i = 0; i < c.knots.n_basis(); ++i) {
    c.points.push_back(random_vector(g, 3));
    c.weights.push_back(rational ? W(g) : 1.0);
  }
  return c;
}

// Surface on u × v, control points in [−1, 1]³, weights from [w_min, w_max] if rational (else 1).
inline geometry::NurbsSurface random_nurbs_surface(std::mt19937& g, geometry::KnotVector u,
                                                   geometry::KnotVector v, bool rational,
                                                   double w_min, double w_max) {
  geometry::NurbsSurface s;
  s.u = std::move(u);
  s.v = std::move(v);
  std::uniform_real_distribution<double> W(w_min, w_max);
  for (int k = 0; k < s.n_u() * s.n_v(); ++k) {
    s.points.push_back(random_vector(g, 3));
    s.weights.push_back(rational ? W(g) : 1.0);
  }
  return s;
}

// Distance of u to the nearest knot (finite differences must not straddle a knot).
inline double knot_distance(const geometry::KnotVector& kv, double u) {
  double d = 1e300;
  for (double k : kv.knots()) d = std::min(d, std::abs(u - k));
  return d;
}

// Half cylinder (radius R about z, height H): two rational 90° arcs in ξ, quadratic in η.
inline geometry::NurbsSurface half_cylinder(double R, double H) {
  geometry::NurbsSurface s;
  s.u = geometry::KnotVector(2, {0.0, 0.0, 0.0, 0.5, 0.5, 1.0, 1.0, 1.0});
  s.v = geometry::KnotVector(2, {0.0, 0.0, 0.0, 0.35, 1.0, 1.0, 1.0});
  const double c = std::sqrt(0.5);
  const Vec3 arc[5] = {{R, 0, 0}, {R, R, 0}, {0, R, 0}, {-R, R, 0}, {-R, 0, 0}};
  const double w[5] = {1.0, c, 1.0, c, 1.0};
  const double z[4] = {0.0, 0.2 * H, 0.6 * H, H};
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 5; ++i) {
      s.points.push_back(arc[i] + Vec3(0, 0, z[j]));
      s.weights.push_back(w[i]);
    }
  return s;
}

// The curve of row j of the control net (η = const. where N_j(η) = 1): knots u, points P_{i,j}.
inline geometry::NurbsCurve surface_row(const geometry::NurbsSurface& s, int j) {
  geometry::NurbsCurve row;
  row.knots = s.u;
  for (int i = 0; i < s.n_u(); ++i) {
    row.points.push_back(s.points[s.index(i, j)]);
    row.weights.push_back(s.weights[s.index(i, j)]);
  }
  return row;
}

}  // namespace isoflex::test
