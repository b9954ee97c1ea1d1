#pragma once
// Gauss–Legendre quadrature and the element (knot-span) loop of isogeometric analysis
// (IGA-thesis §4.2.1, §4.3: "Cartesian products of NURBS knot spans playing the role of
// elements", integrated by Gaussian quadrature).
//
// An n-point Gauss–Legendre rule integrates polynomials of degree ≤ 2n − 1 exactly on [−1, 1].
// On a knot span the NURBS basis is a rational function, so no rule is exact there; the default
// (p+1)×(q+1) points integrate the polynomial (B-spline) mass-matrix entries N_i N_j of degree 2p
// exactly, the usual choice.
#include <vector>

#include "isoflex/geometry/knot_vector.hpp"
#include "isoflex/geometry/nurbs_surface.hpp"

namespace isoflex::geometry {

// Nodes (ascending, in (−1, 1)) and weights of a rule on the parent interval [−1, 1].
struct GaussRule {
  std::vector<double> nodes;
  std::vector<double> weights;
  int size() const { return static_cast<int>(nodes.size()); }
};

// The n-point Gauss–Legendre rule, n ≥ 1: nodes are the roots of the Legendre polynomial P_n,
// found by Newton's method on the three-term recurrence to round-off; weights
// w_k = 2 / ((1 − x_k²) P_n'(x_k)²). Computed on every call (nothing is cached, no global state);
// build the rule once outside the element loop. Throws std::invalid_argument for n < 1.
GaussRule gauss_legendre(int n);

// One non-empty knot span [a, b) of a knot vector; `span` is its index in the knot vector
// (knots[span] = a < knots[span+1] = b), as returned by KnotVector::find_span inside it.
struct SpanElement {
  int span = 0;
  double a = 0.0, b = 0.0;
};

// The non-empty spans of a knot vector, in order (zero-length spans of repeated knots skipped).
std::vector<SpanElement> span_elements(const KnotVector& kv);

// One surface element: the product of a ξ-span and an η-span.
struct SurfaceElement {
  int span_u = 0, span_v = 0;
  double u0 = 0.0, u1 = 0.0, v0 = 0.0, v1 = 0.0;
};

// All elements of a surface, ξ-span running fastest (element e = iu + n_spans_u · iv), matching
// the control-point numbering of NurbsSurface.
std::vector<SurfaceElement> surface_elements(const NurbsSurface& s);

// A quadrature point in parameter space. `weight` already contains the Jacobian of the affine
// parent → parameter map, w = w_i w_j (u1 − u0)/2 · (v1 − v0)/2; multiply by the surface
// Jacobian |S_ξ × S_η| yourself for integrals over the physical surface.
struct QuadraturePoint {
  double xi = 0.0, eta = 0.0;
  double weight = 0.0;
};

// Points of a 1D rule mapped to [a, b]: x = (a + b)/2 + (b − a)/2 · ζ, weight · (b − a)/2.
std::vector<QuadraturePoint> span_quadrature(const SpanElement& e, const GaussRule& rule);

// Tensor-product points of rule_u × rule_v on element e, ξ index running fastest.
std::vector<QuadraturePoint> element_quadrature(const SurfaceElement& e, const GaussRule& rule_u,
                                                const GaussRule& rule_v);

// How many points per direction; ≤ 0 means the default p + 1 (resp. q + 1).
struct QuadratureOrder {
  int n_u = 0, n_v = 0;
};

// The quadrature points of every element of `s`, element by element (outer index: the element
// of surface_elements(s)). Builds the two rules once.
std::vector<std::vector<QuadraturePoint>> surface_quadrature(const NurbsSurface& s,
                                                             QuadratureOrder order = {});

}  // namespace isoflex::geometry
