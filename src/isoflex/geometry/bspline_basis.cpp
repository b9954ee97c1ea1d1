#include "isoflex/geometry/bspline_basis.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "isoflex/geometry/bspline_triangle.hpp"

namespace isoflex::geometry {

namespace {

using namespace bspline_detail;

// One point: its own reciprocals, then the triangle.
template <int P>
void ders2(const double* U, int s, double u, double* d0, double* d1, double* d2) {
  double inv[n_reciprocals(P)];
  reciprocals<P>(U, s, inv);
  triangle<P>(U, s, u, inv, d0, d1, d2);
}

using Kernel = void (*)(const double*, int, double, double*, double*, double*);

template <int... P>
constexpr std::array<Kernel, sizeof...(P)> make_kernels(std::integer_sequence<int, P...>) {
  return {&ders2<P>...};
}
constexpr auto kKernels = make_kernels(std::make_integer_sequence<int, kMaxDegree + 1>{});

using SpanKernel = void (*)(const double*, int, const double*, int, double*, int);
template <int... P>
constexpr std::array<SpanKernel, sizeof...(P)> make_span_kernels(std::integer_sequence<int, P...>) {
  return {&ders2_span<P>...};
}
constexpr auto kSpanKernels = make_span_kernels(std::make_integer_sequence<int, kMaxDegree + 1>{});

}  // namespace

Basis1D bspline_basis(const KnotVector& kv, double u, int n_derivatives) {
  if (n_derivatives < 0 || n_derivatives > 2)
    throw std::invalid_argument("bspline_basis: n_derivatives = " + std::to_string(n_derivatives) +
                                " outside [0, 2]");
  if (std::isnan(u)) throw std::invalid_argument("bspline_basis: parameter is NaN");
  const int p = kv.degree();
  // Clamp like find_span does, so that the polynomial piece is never extrapolated.
  u = std::clamp(u, kv.front(), kv.back());
  Basis1D out;
  out.span = kv.find_span(u);
  out.ders.resize(n_derivatives + 1, p + 1);
  double* d = out.ders.data();  // row major: row k starts at k·(p+1)
  if (n_derivatives == 2) {
    kKernels[p](kv.knots().data(), out.span, u, d, d + (p + 1), d + 2 * (p + 1));
  } else {  // the kernel always computes both derivatives
    double tmp[2][kMaxDegree + 1];
    kKernels[p](kv.knots().data(), out.span, u, d, tmp[0], tmp[1]);
    if (n_derivatives == 1) std::copy(tmp[0], tmp[0] + p + 1, d + (p + 1));
  }
  return out;
}

void bspline_basis_unchecked(const KnotVector& kv, int span, double u, BasisArray& d) {
  kKernels[kv.degree()](kv.knots().data(), span, u, d[0], d[1], d[2]);
}

void bspline_basis_span_unchecked(const KnotVector& kv, int span, const double* u, int n, double* d,
                                  int stride) {
  kSpanKernels[kv.degree()](kv.knots().data(), span, u, n, d, stride);
}

}  // namespace isoflex::geometry
