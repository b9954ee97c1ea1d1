#pragma once
// B-spline and NURBS basis functions with derivatives (IGA-thesis (4.3)–(4.5)): all p+1
// functions that are non-zero on a span, at once, without heap allocation.
#include <Eigen/Core>

#include "isoflex/geometry/knot_vector.hpp"

namespace isoflex::geometry {

// ders(k, j) = d^k N_{span−p+j} / du^k, k = 0..n_derivatives, j = 0..p.
using BasisTable =
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor, 3, kMaxDegree + 1>;

struct Basis1D {
  int span = 0;
  BasisTable ders;
};

// n_derivatives ≤ 2.
Basis1D bspline_basis(const KnotVector& kv, double u, int n_derivatives = 2);

}  // namespace isoflex::geometry
