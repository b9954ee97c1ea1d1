#pragma once
// Tensor-product NURBS surfaces (IGA-thesis (4.12)–(4.13); the B-spline surface (4.8) is the case
// of equal weights).
// Control point (i, j), i along ξ (u), j along η (v), is stored at index i + n_u·j.
#include <vector>

#include "isoflex/geometry/bspline_basis.hpp"
#include "isoflex/math/types.hpp"

namespace isoflex::geometry {

struct NurbsSurface {
  KnotVector u, v;
  std::vector<Vec3> points;
  std::vector<double> weights;  // all 1 for a B-spline surface

  int n_u() const { return u.n_basis(); }
  int n_v() const { return v.n_basis(); }
  int index(int i, int j) const { return i + n_u() * j; }
  int degree_u() const { return u.degree(); }
  int degree_v() const { return v.degree(); }
  bool is_rational() const;  // some weight differs from the others
  // Throws std::invalid_argument on inconsistent sizes, non-finite points or non-positive
  // weights.
  void validate() const;
};

struct SurfacePoint {
  Vec3 x, xu, xv, xuu, xuv, xvv;  // position and derivatives in (ξ, η)
};

// The (p+1)(q+1) rational basis functions that are non-zero at (ξ, η) and their derivatives.
// Column a + (p+1)·b belongs to control point index(span_u − p + a, span_v − q + b);
// rows: R, R_ξ, R_η, R_ξξ, R_ξη, R_ηη.
struct SurfaceBasis {
  int span_u = 0, span_v = 0;
  Eigen::Matrix<double, 6, Eigen::Dynamic, Eigen::ColMajor, 6, (kMaxDegree + 1) * (kMaxDegree + 1)>
      R;
  // Global control-point index of local function k.
  int global_index(const NurbsSurface& s, int k) const;
};

// Parameters outside the domain are clamped (see bspline_basis). Both throw
// std::invalid_argument for a NaN parameter or if the numbers of points or weights do not match
// the knot vectors; weights are checked by validate() only (call it once where a surface enters).
SurfaceBasis surface_basis(const NurbsSurface& s, double xi, double eta);
SurfacePoint evaluate(const NurbsSurface& s, double xi, double eta);

}  // namespace isoflex::geometry
