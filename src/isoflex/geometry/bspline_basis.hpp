#pragma once
// B-spline basis functions with derivatives (Cox–de Boor, IGA-thesis (4.3); open knot vectors
// (4.4)): all p+1 functions that are non-zero on a span, at once, without heap allocation. The
// rational (NURBS) bases built on them are in nurbs_curve.hpp (4.9) and nurbs_surface.hpp (4.12).
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

// N_{span−p..span} and their derivatives up to order n_derivatives ∈ {0, 1, 2} (rows of ders;
// derivatives of order > p are zero). span = kv.find_span(u); u outside [front, back] is clamped
// to the domain like find_span does (no polynomial extrapolation). Throws std::invalid_argument
// for n_derivatives outside [0, 2] or a NaN u.
Basis1D bspline_basis(const KnotVector& kv, double u, int n_derivatives = 2);

// The kernel of bspline_basis, for loops over many points (surface_basis, curve_basis):
// d[k][j] = d^k N_{span−p+j} / du^k, k = 0, 1, 2, j = 0 … p, into a fixed-size array. No checks:
// u must lie in [front, back] and span must be kv.find_span(u).
using BasisArray = double[3][kMaxDegree + 1];
void bspline_basis_unchecked(const KnotVector& kv, int span, double u, BasisArray& d);

// The same for n parameters u[0..n) of one span (element_basis): the knot-difference reciprocals
// are computed once for all of them. d[(3i + k)·stride + j] = d^k N_{span−p+j}/du^k at u[i]
// (stride ≥ p + 1; entries j > p are not written), bit for bit what bspline_basis_unchecked
// writes for u[i]. No checks: span must be a non-empty span (knots[span] < knots[span+1],
// p ≤ span < n_basis) and every u[i] must lie in [knots[span], knots[span+1]] (at its ends: the
// one-sided values of this span's polynomials).
void bspline_basis_span_unchecked(const KnotVector& kv, int span, const double* u, int n, double* d,
                                  int stride);

}  // namespace isoflex::geometry
