#include "isoflex/geometry/bspline_basis.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>

namespace isoflex::geometry {

namespace {

// Complete unrolling of the loops over the degree (GCC unrolls only tiny loops at -O2).
#define ISOFLEX_UNROLL _Pragma("GCC unroll 16")

// Two doubles in one SSE2 register (GCC/Clang vector extension).
using V2 [[gnu::vector_size(16)]] = double;

// All P+1 non-zero B-splines N_{s−P..s} on span s with first and second derivatives, by the
// Cox–de Boor recursion IGA-thesis (4.3) organised as one triangle (Piegl & Tiller, The NURBS
// Book, A2.2), degree j = 1 … P, in place in N[0..j]:
//
//   N_{i,j} = (u − ξ_i) T_i + (ξ_{i+j+1} − u) T_{i+1},   T_i = N_{i,j−1} / (ξ_{i+j} − ξ_i)   (4.3b)
//
// (T_i of the function that vanishes on the span is 0). The derivatives are differences of the
// same quotients T (differentiating (4.3b), The NURBS Book §2.3):
//
//   N'_{i,P}  = P (T_i − T_{i+1})                       with T of level j = P,
//   N''_{i,P} = P (N'_{i,P−1} / (ξ_{i+P} − ξ_i) − N'_{i+1,P−1} / (ξ_{i+P+1} − ξ_{i+1})),
//   N'_{i,P−1} = (P−1) (T_i − T_{i+1})                  with T of level j = P − 1.
//
// Only the reciprocals 1/(ξ_{i+j} − ξ_i) are divisions; they depend on the knots alone, not on u
// or on the previous level, so they do not lie on the dependency chain of the triangle. The 0/0
// := 0 convention of (4.3) never arises: on a non-empty span every difference used here,
// ξ_{s+r+1} − ξ_{s+r+1−j} with 0 ≤ r < j, contains the span. Written for a fixed degree P so that
// the compiler unrolls the loops and keeps the triangle in registers.
template <int P>
void ders2(const double* U, int s, double u, double* d0, double* d1, double* d2) {
  if constexpr (P == 0) {
    d0[0] = 1.0, d1[0] = 0.0, d2[0] = 0.0;
  } else {
    double left[P + 1], right[P + 1];  // u − ξ_{s+1−j}, ξ_{s+j} − u
    ISOFLEX_UNROLL
    for (int j = 1; j <= P; ++j) {
      left[j] = u - U[s + 1 - j];
      right[j] = U[s + j] - u;
    }
    // inv[j][r] = 1/(ξ_{s+r+1} − ξ_{s+r+1−j}), 0 ≤ r < j: two per SSE2 division.
    double inv[P + 1][P];
    ISOFLEX_UNROLL
    for (int j = 1; j <= P; ++j) {
      ISOFLEX_UNROLL
      for (int r = 0; r < j; r += 2) {
        if (r + 1 < j) {
          V2 hi, lo;
          std::memcpy(&hi, U + s + r + 1, sizeof hi);
          std::memcpy(&lo, U + s + r + 1 - j, sizeof lo);
          const V2 q = 1.0 / (hi - lo);
          inv[j][r] = q[0], inv[j][r + 1] = q[1];
        } else {
          inv[j][r] = 1.0 / (U[s + r + 1] - U[s + r + 1 - j]);
        }
      }
    }
    double N[P + 1];  // level j: N[r] = N_{s−j+r, j}
    double T[P];      // level P:   T[r] = T_{s−P+1+r}
    double Tm[P];     // level P−1: Tm[r] = T_{s−P+2+r} (P ≥ 2)
    N[0] = 1.0;       // (4.3a): N_{s,0} = 1 on the span
    ISOFLEX_UNROLL
    for (int j = 1; j <= P; ++j) {
      double saved = 0.0;  // left-hand term of N_{s−j+r, j}, from T_{s−j+r}
      ISOFLEX_UNROLL
      for (int r = 0; r < j; ++r) {
        // T_{s−j+r+1} = N_{s−j+r+1, j−1} / (ξ_{s+r+1} − ξ_{s−j+r+1}); N[r] still holds level j − 1.
        const double t = N[r] * inv[j][r];
        if (j == P) T[r] = t;
        if (j == P - 1) Tm[r] = t;
        // (4.3b): T_{s−j+r+1} contributes the right-hand term of N_{s−j+r, j} and the left-hand
        // term of N_{s−j+r+1, j} (N_{s−j, j−1} vanishes on the span: nothing to add for r = 0).
        N[r] = r == 0 ? right[1] * t : saved + right[r + 1] * t;
        saved = left[j - r] * t;
      }
      N[j] = saved;
    }
    ISOFLEX_UNROLL
    for (int a = 0; a <= P; ++a) d0[a] = N[a];
    // N'_{s−P+a} = P (T[a−1] − T[a]); the T of N_{s−P, P−1} and N_{s+1, P−1} are 0.
    d1[0] = -P * T[0];
    ISOFLEX_UNROLL
    for (int a = 1; a < P; ++a) d1[a] = P * (T[a - 1] - T[a]);
    d1[P] = P * T[P - 1];
    if constexpr (P == 1) {
      d2[0] = 0.0, d2[1] = 0.0;
    } else {
      // g[a] = N'_{s−P+1+a, P−1} / ((P−1) (ξ_{s+a+1} − ξ_{s−P+a+1})) with N'/(P−1) = Tm[a−1] −
      // Tm[a] (Tm[−1] = Tm[P−1] = 0), a = 0 … P−1; then N''_{s−P+a} = P (P−1) (g[a−1] − g[a]),
      // g[−1] = g[P] = 0.
      double g[P];
      g[0] = -Tm[0] * inv[P][0];
      ISOFLEX_UNROLL
      for (int a = 1; a < P - 1; ++a) g[a] = (Tm[a - 1] - Tm[a]) * inv[P][a];
      g[P - 1] = Tm[P - 2] * inv[P][P - 1];
      constexpr double c = P * (P - 1);
      d2[0] = -c * g[0];
      ISOFLEX_UNROLL
      for (int a = 1; a < P; ++a) d2[a] = c * (g[a - 1] - g[a]);
      d2[P] = c * g[P - 1];
    }
  }
}

using Kernel = void (*)(const double*, int, double, double*, double*, double*);

template <int... P>
constexpr std::array<Kernel, sizeof...(P)> make_kernels(std::integer_sequence<int, P...>) {
  return {&ders2<P>...};
}
constexpr auto kKernels = make_kernels(std::make_integer_sequence<int, kMaxDegree + 1>{});

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

}  // namespace isoflex::geometry
