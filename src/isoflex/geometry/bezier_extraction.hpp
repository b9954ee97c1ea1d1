#pragma once
// Bézier extraction (the knot-span view of a B-spline/NURBS patch): on each non-empty knot span
// e = [a, b) the p + 1 B-splines that are non-zero there are polynomials of degree p, hence
// combinations of the Bernstein polynomials (IGA-thesis (4.2)) of the span's local coordinate
// t = (ξ − a)/(b − a) ∈ [0, 1]:
//
//     N_{s−p+i}(ξ) = Σ_k C_e(i, k) B_{k,p}(t),     i, k = 0 … p,   s = the span index,
//
// i.e. N_e = C_e · B. C_e is the extraction operator of the span. Surfaces use the tensor product
// C_e = C_v ⊗ C_u, with local index a + (p+1)·b (ξ fastest) on both sides — the column order of
// SurfaceBasis. A NURBS patch becomes one *rational Bézier* cell per element by extracting the
// homogeneous control points (w_i P_i, w_i) (IGA-thesis (4.12)–(4.13)):
//
//     W_k = Σ_i C_e(i, k) w_i,     Q_k = Σ_i C_e(i, k) w_i P_i / W_k,
//     S = Σ_k B_k W_k Q_k / Σ_k B_k W_k     on the element.
//
// C_e is computed per span by Boehm knot insertion on the span's local knot window until both
// ends of the span have multiplicity p (after which the local B-splines *are* the Bernstein
// polynomials of the span); see docs/theory/nurbs-tools.md.
#include <vector>

#include "isoflex/geometry/knot_vector.hpp"
#include "isoflex/geometry/nurbs_surface.hpp"
#include "isoflex/geometry/quadrature.hpp"
#include "isoflex/math/types.hpp"

namespace isoflex::geometry {

// Bernstein polynomials B_{k,p}(t) = C(p,k) t^k (1 − t)^{p−k} (IGA-thesis (4.2)) and their first
// and second derivatives in t, rows 0..2, columns k = 0..p. Evaluated by de Casteljau's
// triangle (stable on [0, 1]). p ≤ kMaxDegree.
using BernsteinTable = Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::ColMajor, 3, kMaxDegree + 1>;
BernsteinTable bernstein(int p, double t);

// Extraction operators of every non-empty span of a knot vector, in the order of
// span_elements(kv): operators[e] is (p+1)×(p+1), rows = local B-splines N_{s−p+i}, columns =
// Bernstein polynomials. Every column sums to 1 (both bases are partitions of unity).
struct CurveExtraction {
  int degree = 0;
  std::vector<SpanElement> elements;
  std::vector<MatX> operators;
};
CurveExtraction extract_curve(const KnotVector& kv);

// The Bézier-element view of a surface for assembly: per element its span data, the global
// control-point indices of its (p+1)(q+1) local functions (local a + (p+1)·b →
// index(span_u − p + a, span_v − q + b)) and C_e = C_v ⊗ C_u (rows: local B-splines, columns:
// Bernstein products B_k(t_u) B_l(t_v) with local index k + (p+1)·l).
struct BezierElement {
  SurfaceElement element;
  std::vector<int> global;  // size (p+1)(q+1)
  MatX C;                   // (p+1)(q+1) × (p+1)(q+1)
};
struct SurfaceExtraction {
  int p = 0, q = 0;
  int n_elements_u = 0, n_elements_v = 0;
  std::vector<BezierElement> elements;  // ξ-element fastest, as surface_elements()
};
SurfaceExtraction extract_surface(const NurbsSurface& s);

// One rational Bézier cell: (p+1)(q+1) control points and weights, local index k + (p+1)·l
// (k along ξ), mapping the element [u0,u1]×[v0,v1] via t_u = (ξ − u0)/(u1 − u0), t_v likewise.
struct RationalBezierCell {
  SurfaceElement element;
  int p = 0, q = 0;
  std::vector<Vec3> points;
  std::vector<double> weights;
};

// The rational Bézier cells of a NURBS surface, one per element (order of surface_elements()).
std::vector<RationalBezierCell> bezier_cells(const NurbsSurface& s);
// The same from a precomputed extraction (avoids recomputing C_e for several fields).
std::vector<RationalBezierCell> bezier_cells(const NurbsSurface& s, const SurfaceExtraction& x);

// Extracts a field given per NURBS control point (n_components values per point, point-major)
// to the Bézier control points of element `e` with the same rational weights, so that
// f = Σ_k B_k W_k f_k / Σ_k B_k W_k reproduces f = Σ_i R_i f_i (IGA-thesis (4.12)):
// f_k = Σ_i C(i,k) w_i f_i / W_k. Returns (p+1)(q+1) × n_components values, point-major.
std::vector<double> extract_field(const NurbsSurface& s, const BezierElement& e,
                                  const std::vector<double>& values, int n_components);

// Evaluates a rational Bézier cell at local (t_u, t_v) ∈ [0, 1]² (for tests and tessellation).
Vec3 evaluate(const RationalBezierCell& c, double tu, double tv);

}  // namespace isoflex::geometry
