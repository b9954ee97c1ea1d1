#pragma once
// Exact NURBS descriptions of the simple shapes used by examples and tests (IGA-thesis §4.1.3:
// conics need rational functions, Lemma 4.1/Remark 4.1). Every builder returns a valid, open,
// lowest-degree patch on the parameter domain [0, 1] (or [0, 1]²); refine it with
// refinement.hpp. Circular arcs are rational quadratics: one segment per at most 90°, the middle
// control point on the intersection of the end tangents (distance R / cos(Δθ/2) from the
// centre) with weight cos(Δθ/2), segments joined by a double knot (geometry C¹/G¹ there, the
// parametrization C⁰). Surfaces are oriented so that S_ξ × S_η points outward (away from the axis
// or centre), or along +z for planar ones. All throw std::invalid_argument on non-positive or
// non-finite sizes and out-of-range angles.
#include "isoflex/geometry/nurbs_curve.hpp"
#include "isoflex/geometry/nurbs_surface.hpp"
#include "isoflex/math/types.hpp"

namespace isoflex::geometry {

// Arc of radius r about `center` in the plane z = center.z, counter-clockwise from the angle
// `start` (from +x) through `sweep` ∈ (0, 2π]; ceil(sweep / 90°) quadratic segments.
NurbsCurve circle_arc(double radius, double start, double sweep, const Vec3& center = Vec3::Zero());
// Full circle of radius r about the origin in the xy-plane (4 segments, starting on +x).
NurbsCurve circle(double radius);

// Bilinear parallelogram corner + ξ·edge_u + η·edge_v (degree 1×1, 2×2 control points).
NurbsSurface planar_rectangle(const Vec3& corner, const Vec3& edge_u, const Vec3& edge_v);
// [0, lx] × [0, ly] in the xy-plane.
NurbsSurface planar_rectangle(double lx, double ly);

// Cylinder sector of radius R about the z axis: ξ runs along the arc from +x through `angle`
// ∈ (0, π] (one rational quadratic segment up to 90°, two beyond), η along the axis from z = 0 to
// z = length (degree 1).
NurbsSurface cylinder_sector(double radius, double length, double angle);

// Sphere sector of radius R about the origin, a surface of revolution (tensor product of two
// arcs, w_ij = w_i w_j): ξ along the azimuth from +x through `azimuth_sweep` ∈ (0, 2π], η along
// the latitude from lat_from to lat_to, −π/2 ≤ lat_from < lat_to ≤ π/2. At a pole the η = const
// edge degenerates to a point (all its control points coincide).
NurbsSurface sphere_sector(double radius, double azimuth_sweep, double lat_from, double lat_to);
// The octant x, y, z ≥ 0 (one biquadratic element, degenerate at the north pole η = 1).
NurbsSurface sphere_octant(double radius);
// The upper hemisphere z ≥ 0 (4 × 1 elements, degenerate at the north pole η = 1).
NurbsSurface hemisphere(double radius);

// The disc of IGA-thesis Fig. 4.3a: radius R about the origin in the xy-plane, one biquadratic
// element, knots (0,0,0,1,1,1) in both directions, 3 × 3 control points: the corners on the
// circle at ±45°/±135°, the edge middles at distance √2 R on the axes (the 90° arc middles), the
// centre at the origin; weights 1 at corners and centre, 1/√2 at edge middles. The four
// boundary edges are exact quarter circles; the parametrization is singular at the four corners
// (the boundary is smooth there), as for every four-sided disc.
NurbsSurface disc(double radius);

}  // namespace isoflex::geometry
