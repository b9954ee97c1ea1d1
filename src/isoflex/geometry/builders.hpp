#pragma once
// Exact NURBS descriptions of the simple shapes used by examples and tests (IGA-thesis §4.1.3:
// conics need rational functions, Lemma 4.1/Remark 4.1). Every builder returns a valid, open,
// lowest-degree patch on the parameter domain [0, 1] (or [0, 1]²); refine it with
// refinement.hpp. Circular arcs are rational quadratics: one segment per at most 90°, the middle
// control point on the intersection of the end tangents (distance R / cos(Δθ/2) from the
// centre) with weight cos(Δθ/2), segments joined by a double knot (geometry C¹/G¹ there, the
// parametrization C⁰). Degree elevation keeps that knot p-fold, so a Kirchhoff–Love patch on an
// arc beyond 90° has a C⁰ line of its basis there: alone a hinge (no bending coupling across
// it, elements/kl_shell_patch.hpp); a model joins it like an interface between two patches
// (system/kl_interfaces.hpp, docs/theory/multipatch.md §7). Surfaces are
// oriented so that S_ξ × S_η points outward (away from the axis or centre), or along +z for
// planar ones. All throw std::invalid_argument on non-positive or non-finite sizes and
// out-of-range angles.
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
// ∈ (0, 2π] (one rational quadratic segment per started 90°, joined by double knots), η along
// the axis from z = 0 to z = length (degree 1). For angle = 2π the patch is closed: its edges
// ξ = 0 and ξ = 1 coincide (distinct control points at the same positions, bit for bit). The
// surface itself is not joined there; a model joins such a seam (C⁰ plus the bending coupling of
// kl_interfaces) unless its kl_shells entry says `seam: open` (system/kl_interfaces.hpp).
NurbsSurface cylinder_sector(double radius, double length, double angle);
// The full cylinder, cylinder_sector(radius, length, 2π): 4 segments, a seam at +x.
NurbsSurface cylinder(double radius, double length);

// Annular sector in the xy-plane about the origin, inner radius r_i < outer radius r_o: ξ along
// the arc from +x counter-clockwise through `angle` ∈ (0, 2π] (segments as for cylinder_sector),
// η radially from the outer circle (η = 0) to the inner one (η = 1), degree 1 — inwards, so that
// S_ξ × S_η points along +z. For angle = 2π the radial edges ξ = 0 and ξ = 1 coincide: a model
// joins them unless told `seam: open`, which keeps the slit annulus (Sze et al. 2004).
NurbsSurface annulus(double inner_radius, double outer_radius, double angle);

// Sphere sector of radius R about the origin, a surface of revolution (tensor product of two
// arcs, w_ij = w_i w_j): ξ along the azimuth from +x through `azimuth_sweep` ∈ (0, 2π], η along
// the latitude from lat_from to lat_to, −π/2 ≤ lat_from < lat_to ≤ π/2. At a pole the η = const
// edge degenerates to a point (all its control points coincide).
NurbsSurface sphere_sector(double radius, double azimuth_sweep, double lat_from, double lat_to);
// The octant x, y, z ≥ 0 (one biquadratic element, degenerate at the north pole η = 1).
NurbsSurface sphere_octant(double radius);
// The upper hemisphere z ≥ 0 (4 × 1 elements, degenerate at the north pole η = 1).
NurbsSurface hemisphere(double radius);
// The cap of the sphere about +z from the pole down to the polar angle `polar_angle` ∈ (0, π),
// full in azimuth: sphere_sector(R, 2π, π/2 − polar_angle, π/2). ξ along the azimuth from +x, η
// along the meridian from the rim (η = 0) up to the pole (η = 1, a collapsed edge); one segment
// per started 90° in each direction. polar_angle = π/2 is the hemisphere.
NurbsSurface spherical_cap(double radius, double polar_angle);

// The disc of IGA-thesis Fig. 4.3a: radius R about the origin in the xy-plane, one biquadratic
// element, knots (0,0,0,1,1,1) in both directions, 3 × 3 control points: the corners on the
// circle at ±45°/±135°, the edge middles at distance √2 R on the axes (the 90° arc middles), the
// centre at the origin; weights 1 at corners and centre, 1/√2 at edge middles. The four
// boundary edges are exact quarter circles; the parametrization is singular at the four corners
// (the boundary is smooth there), as for every four-sided disc.
NurbsSurface disc(double radius);

}  // namespace isoflex::geometry
