#pragma once
// NURBS curves (IGA-thesis (4.9)–(4.11)): C(ξ) = Σ R_i(ξ) P_i with R_i = N_i w_i / Σ N_j w_j.
// A B-spline curve (4.6) is the special case of equal weights.
#include <vector>

#include "isoflex/geometry/bspline_basis.hpp"
#include "isoflex/geometry/knot_vector.hpp"
#include "isoflex/math/types.hpp"

namespace isoflex::geometry {

struct NurbsCurve {
  KnotVector knots;
  std::vector<Vec3> points;
  std::vector<double> weights;  // all 1 for a B-spline curve

  int n() const { return static_cast<int>(points.size()); }
  int degree() const { return knots.degree(); }
  bool is_rational() const;  // some weight differs from the others
  // Throws std::invalid_argument on inconsistent sizes, non-finite points or non-positive
  // weights.
  void validate() const;
};

struct CurvePoint {
  Vec3 x, x1, x2;  // position, first and second derivative in ξ
};

// The p+1 rational basis functions that are non-zero at ξ (IGA-thesis (4.9)) and their first and
// second derivatives: R(k, a) = d^k R_{span−p+a} / dξ^k, k = 0..2, a = 0..p.
struct CurveBasis {
  int span = 0;
  BasisTable R;
  // Global control-point index of local function a.
  int global_index(const NurbsCurve& c, int a) const { return span - c.degree() + a; }
};

CurveBasis curve_basis(const NurbsCurve& c, double xi);
CurvePoint evaluate(const NurbsCurve& c, double xi);

}  // namespace isoflex::geometry
