#pragma once
// The rational basis (4.12) with first and second derivatives at all points of a tensor-product
// grid inside one element (a knot span × a knot span, IGA-thesis §4.2.1) — typically the Gauss
// points of the element loop — evaluated together. Per point it computes what surface_basis
// computes, with the same operations in the same order (so the same values, bit for bit, inside
// the span; the tests require 1e-14), but the work that the points share is done once: no span
// search, the knot-difference reciprocals of the triangle (4.3) once per element, the univariate
// bases once per row and column of the grid, the partial sums of W along ξ once per row
// (algorithm and operation count: docs/theory/nurbs-tools.md §5; timing: bench/basis.md).
#include <span>
#include <vector>

#include "isoflex/geometry/nurbs_surface.hpp"
#include "isoflex/geometry/quadrature.hpp"

namespace isoflex::geometry {

// Output of element_basis; keep one object and pass it to every call of an element loop, so that
// its storage is reused (no allocation once it is large enough).
struct ElementBasis {
  int span_u = 0, span_v = 0;
  int n_u = 0, n_v = 0;    // grid points per direction; point g = i + n_u·j at (ξ_i, η_j)
  int n_functions = 0;     // (p+1)(q+1); local function k = a + (p+1)·b as in SurfaceBasis
  std::vector<double> xi;  // ξ_i, i < n_u, and η_j, j < n_v
  std::vector<double> eta;
  // Point g: the 6 × n_functions matrix of SurfaceBasis::R (rows R, R_ξ, R_η, R_ξξ, R_ξη, R_ηη),
  // stored row by row: values[(6g + d)·row_stride + k] = row d, function k, k < n_functions.
  // row_stride is n_functions rounded up to even (16-byte aligned rows; a padding entry, if any,
  // holds no value).
  int row_stride = 0;
  std::vector<double> values;
  std::vector<double> work;  // scratch: univariate bases, partial sums, per-point factors

  int n_points() const { return n_u * n_v; }
  using PointMatrix = Eigen::Map<const Eigen::Matrix<double, 6, Eigen::Dynamic, Eigen::RowMajor>,
                                 Eigen::Unaligned, Eigen::OuterStride<>>;
  // R(g)(d, k) = SurfaceBasis::R(d, k) at point g.
  PointMatrix R(int g) const {
    return PointMatrix(values.data() + 6 * static_cast<std::size_t>(row_stride) * g, 6, n_functions,
                       Eigen::OuterStride<>(row_stride));
  }
  // Global control-point index of local function k (as SurfaceBasis::global_index).
  int global_index(const NurbsSurface& s, int k) const;
};

// All points (xi[i], eta[j]) of the element span_u × span_v, i fastest. span_u and span_v must be
// non-empty knot spans (as in SurfaceElement) and every xi in [knots_u[span_u], knots_u[span_u+1]],
// every eta likewise: the basis is the polynomial piece of this element, so at an interior knot
// the derivatives are this element's one-sided values (surface_basis takes the span to the right
// there, except at the end of the domain). Throws std::invalid_argument for a span that is out
// of range or empty, a parameter outside its span or NaN, empty point lists, or if the numbers of
// points or weights do not match the knot vectors; weights are checked by validate() only.
void element_basis(const NurbsSurface& s, int span_u, int span_v, std::span<const double> xi,
                   std::span<const double> eta, ElementBasis& out);

// The tensor-product Gauss points of element e, rule_u × rule_v, mapped to the element exactly
// like element_quadrature does (point g = i + n_u·j is element_quadrature's point g). Throws like
// the overload above, and if e's bounds are not the knots of its spans.
void element_basis(const NurbsSurface& s, const SurfaceElement& e, const GaussRule& rule_u,
                   const GaussRule& rule_v, ElementBasis& out);

}  // namespace isoflex::geometry
