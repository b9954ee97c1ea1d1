#pragma once
// NURBS curves (IGA-thesis (4.6)–(4.8)): C(ξ) = Σ R_i(ξ) P_i with R_i = N_i w_i / Σ N_j w_j.
#include <vector>

#include "isoflex/geometry/knot_vector.hpp"
#include "isoflex/math/types.hpp"

namespace isoflex::geometry {

struct NurbsCurve {
  KnotVector knots;
  std::vector<Vec3> points;
  std::vector<double> weights;  // all 1 for a B-spline curve

  int n() const { return static_cast<int>(points.size()); }
  // Throws std::invalid_argument on inconsistent sizes or non-positive weights.
  void validate() const;
};

struct CurvePoint {
  Vec3 x, x1, x2;  // position, first and second derivative in ξ
};

CurvePoint evaluate(const NurbsCurve& c, double xi);

}  // namespace isoflex::geometry
