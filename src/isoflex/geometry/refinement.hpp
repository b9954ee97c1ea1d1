#pragma once
// Refinement of NURBS curves and surfaces without changing the geometry (IGA-thesis §4.1.4,
// §4.2.2): knot insertion (Boehm), knot refinement (many knots at once), degree elevation, uniform
// h-refinement and k-refinement (elevate first, then insert — §4.2.2). All algorithms act on the
// homogeneous control points (w P, w) ∈ R⁴, in which a NURBS curve (4.10) is a polynomial
// B-spline curve (4.6); the rational geometry is then unchanged exactly (up to round-off).
// A surface is refined in one direction by applying the curve algorithm to every row (Direction::u,
// fixed j) or column (Direction::v, fixed i) of its control net (tensor product (4.12)).
//
// Every function validates its input surface/curve and throws std::invalid_argument with the
// offending value for anything that would not give a valid spline of the same shape. Knot vectors
// that are not open (unclamped, periodic) become open ones with clamping.hpp; the algorithms in
// homogeneous coordinates are shared through homogeneous_lines.hpp.
#include <vector>

#include "isoflex/geometry/knot_vector.hpp"
#include "isoflex/geometry/nurbs_curve.hpp"
#include "isoflex/geometry/nurbs_surface.hpp"

namespace isoflex::geometry {

enum class Direction { u, v };  // ξ (index i) or η (index j)

// --- Curves -------------------------------------------------------------------------------------

// Inserts the knot `knot` r ≥ 1 times (Boehm's single-knot insertion, repeated). The knot must lie
// strictly inside the domain (front, back) and its multiplicity after insertion must not exceed
// the degree p (the curve stays at least C⁰). n grows by r.
NurbsCurve insert_knot(const NurbsCurve& c, double knot, int r = 1);

// Inserts all knots of `new_knots` at once (knot refinement, The NURBS Book A5.4); the list need
// not be sorted and may repeat values. Same conditions as insert_knot for every knot. n grows by
// new_knots.size(); an empty list returns the curve unchanged.
NurbsCurve refine_knots(const NurbsCurve& c, const std::vector<double>& new_knots);

// Raises the degree by t ≥ 0 (The NURBS Book A5.9: Bézier decomposition, elevation of each
// segment, removal of the knots the decomposition inserted). Every distinct knot's multiplicity
// grows by t, so the continuity at each knot is kept: n grows by t·(number of distinct interior
// knots + 1). Needs an open knot vector, interior multiplicities ≤ p and p + t ≤ kMaxDegree.
NurbsCurve elevate_degree(const NurbsCurve& c, int t);

// The knots that split every non-empty span [a, b] into n_per_span + 1 equal parts:
// a + (b − a)·k/(n_per_span + 1), k = 1..n_per_span (none for n_per_span = 0).
std::vector<double> uniform_new_knots(const KnotVector& kv, int n_per_span);

// Uniform h-refinement: refine_knots with uniform_new_knots(knots, n_per_span).
NurbsCurve refine_uniform(const NurbsCurve& c, int n_per_span);

// k-refinement (§4.2.2): elevate by t first, then insert n_per_span knots per span, so that the
// new knots get continuity C^{p+t−1} (the reverse order would give only C^{p−1} there).
NurbsCurve k_refine(const NurbsCurve& c, int t, int n_per_span);

// --- Surfaces -----------------------------------------------------------------------------------

NurbsSurface insert_knot(const NurbsSurface& s, Direction d, double knot, int r = 1);
NurbsSurface refine_knots(const NurbsSurface& s, Direction d, const std::vector<double>& new_knots);
NurbsSurface elevate_degree(const NurbsSurface& s, Direction d, int t);
// n_u / n_v new knots per non-empty span in ξ / η.
NurbsSurface refine_uniform(const NurbsSurface& s, int n_per_span_u, int n_per_span_v);
// Elevation by (t_u, t_v) first, then uniform insertion — in both directions.
NurbsSurface k_refine(const NurbsSurface& s, int t_u, int t_v, int n_per_span_u, int n_per_span_v);

}  // namespace isoflex::geometry
