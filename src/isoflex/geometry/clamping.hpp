#pragma once
// Clamping of NURBS curves and surfaces whose knot vector is not open: a "floating" (unclamped)
// or periodic B-spline, as CAD systems write closed and periodic shapes, or one with an end knot
// more than p+1-fold. The result describes exactly the same curve or surface, with the same
// parametrization, on the same parameter domain [U_p, U_{n}] (KnotVector::front(), back()), with an
// open knot vector — what analysis needs (IGA-thesis (4.4)): the boundary interpolates the
// boundary control points, so supports and patch coupling on control points are exact, and
// degree elevation (refinement.hpp) applies.
//
// Algorithm (knot insertion, The NURBS Book §5.2–5.3, on the homogeneous control points): insert
// each end of the domain with Boehm's formula until it is p+1-fold; the curve is then split into
// independent pieces at the ends, and the control points and knots of the pieces outside the
// domain are dropped (their basis functions vanish on it). Interior knots are kept as they are.
#include "isoflex/geometry/nurbs_curve.hpp"
#include "isoflex/geometry/nurbs_surface.hpp"
#include "isoflex/geometry/refinement.hpp"

namespace isoflex::geometry {

// An open knot vector is returned unchanged (bit for bit). Throws std::invalid_argument for an
// invalid curve or surface (NurbsCurve::validate, NurbsSurface::validate).
NurbsCurve clamped(const NurbsCurve& c);
// Clamps the knot vector of direction d only.
NurbsSurface clamped(const NurbsSurface& s, Direction d);
// Clamps both directions (each only if its knot vector is not open).
NurbsSurface clamped(const NurbsSurface& s);

}  // namespace isoflex::geometry
