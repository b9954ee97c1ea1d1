#pragma once
// Internal to the geometry room (refinement.cpp, clamping.cpp), not part of its interface: NURBS
// curves in homogeneous coordinates, a surface as the curves of its rows or columns, and Boehm's
// insertion of one knot. In the homogeneous control points (w P, w) ∈ R⁴ a NURBS curve (4.10) is
// the polynomial B-spline curve (4.6) C^w = Σ N_i P_i^w, so every knot-vector algorithm that
// keeps a B-spline curve keeps the rational one too, and is linear in these points.
#include <functional>
#include <vector>

#include "isoflex/geometry/knot_vector.hpp"
#include "isoflex/geometry/nurbs_curve.hpp"
#include "isoflex/geometry/nurbs_surface.hpp"
#include "isoflex/geometry/refinement.hpp"

namespace isoflex::geometry::detail {

using Hom = Eigen::Vector4d;

struct HomCurve {
  KnotVector kv;
  std::vector<Hom> pw;
};

Hom to_hom(const Vec3& x, double w);
HomCurve to_hom(const NurbsCurve& c);
NurbsCurve from_hom(HomCurve&& h);

// One row (fixed j, Direction::u) or column (fixed i, Direction::v) of a surface's control net.
HomCurve surface_line(const NurbsSurface& s, Direction d, int line);

// Applies a curve algorithm in homogeneous coordinates to every row or column of a surface (the
// tensor product (4.12): a knot-vector operation in ξ acts on each row alike). `f` must give the
// same knot vector for every line.
NurbsSurface apply_lines(const NurbsSurface& s, Direction d,
                         const std::function<HomCurve(const HomCurve&)>& f);

// Boehm's insertion of one knot ū with U_k ≤ ū ≤ U_{k+1}, k = kv.find_span(ū) (The NURBS Book
// §5.2):
//   Q_i = P_i                                  i ≤ k − p,
//   Q_i = α_i P_i + (1 − α_i) P_{i−1},          α_i = (ū − U_i)/(U_{i+p} − U_i),  k−p < i ≤ k,
//   Q_i = P_{i−1}                              i > k.
// No checks: the caller keeps ū in the domain [front, back]. The relation is an identity of the
// basis functions on the whole line, so it also holds at ū = U_{k+1} (the end of the domain,
// where find_span gives the last non-empty span) and up to multiplicity p + 1 (the curve is then
// split into independent pieces at ū) — what clamping uses.
HomCurve insert_once(const HomCurve& c, double u);

}  // namespace isoflex::geometry::detail
