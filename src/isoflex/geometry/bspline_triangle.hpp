#pragma once
// Internal to the geometry room (bspline_basis.cpp, element_basis.cpp): the Cox–de Boor triangle
// (IGA-thesis (4.3)) for a degree fixed at compile time, so that callers with a fixed degree can
// inline it.
#include <cstring>

namespace isoflex::geometry::bspline_detail {

// Complete unrolling of the loops over the degree (GCC unrolls only tiny loops at -O2).
#ifndef ISOFLEX_UNROLL
#define ISOFLEX_UNROLL _Pragma("GCC unroll 16")
#endif

// Two doubles in one SSE2 register (GCC/Clang vector extension).
using V2 [[gnu::vector_size(16)]] = double;

// Number of reciprocals 1/(ξ_{s+r+1} − ξ_{s+r+1−j}), 0 ≤ r < j ≤ P, that the triangle of degree
// P uses (at least one, so that the array type stays valid for P = 0).
constexpr int n_reciprocals(int P) {
  return P == 0 ? 1 : P * (P + 1) / 2;
}

// inv[j(j−1)/2 + r] = 1/(ξ_{s+r+1} − ξ_{s+r+1−j}), 0 ≤ r < j ≤ P, two per SSE2 division. They
// depend on the knots of span s only (not on u), so every point of the span can share them.
template <int P>
inline void reciprocals(const double* U, int s, double* inv) {
  ISOFLEX_UNROLL
  for (int j = 1; j <= P; ++j) {
    ISOFLEX_UNROLL
    for (int r = 0; r < j; r += 2) {
      double* q = inv + j * (j - 1) / 2 + r;
      if (r + 1 < j) {
        V2 hi, lo;
        std::memcpy(&hi, U + s + r + 1, sizeof hi);
        std::memcpy(&lo, U + s + r + 1 - j, sizeof lo);
        const V2 qq = 1.0 / (hi - lo);
        q[0] = qq[0], q[1] = qq[1];
      } else {
        q[0] = 1.0 / (U[s + r + 1] - U[s + r + 1 - j]);
      }
    }
  }
}

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
// Only the reciprocals 1/(ξ_{i+j} − ξ_i) (`inv`, from reciprocals<P>) are divisions; they depend
// on the knots alone, not on u or on the previous level, so they do not lie on the dependency
// chain of the triangle. The 0/0 := 0 convention of (4.3) never arises: on a non-empty span every
// difference used here, ξ_{s+r+1} − ξ_{s+r+1−j} with 0 ≤ r < j, contains the span. Written for a
// fixed degree P so that the compiler unrolls the loops and keeps the triangle in registers.
//
// T is double, or V2 for two parameters at once (one per lane, the same operations).
template <int P, class T>
[[gnu::always_inline]] inline void triangle(const double* U, int s, T u, const double* inv, T* d0,
                                            T* d1, T* d2) {
  const T zero{};
  if constexpr (P == 0) {
    d0[0] = zero + 1.0, d1[0] = zero, d2[0] = zero;
  } else {
    T left[P + 1], right[P + 1];  // u − ξ_{s+1−j}, ξ_{s+j} − u
    ISOFLEX_UNROLL
    for (int j = 1; j <= P; ++j) {
      left[j] = u - U[s + 1 - j];
      right[j] = U[s + j] - u;
    }
    T N[P + 1];         // level j: N[r] = N_{s−j+r, j}
    T Tq[P];            // level P:   Tq[r] = T_{s−P+1+r}
    T Tm[P];            // level P−1: Tm[r] = T_{s−P+2+r} (P ≥ 2)
    N[0] = zero + 1.0;  // (4.3a): N_{s,0} = 1 on the span
    ISOFLEX_UNROLL
    for (int j = 1; j <= P; ++j) {
      T saved = zero;  // left-hand term of N_{s−j+r, j}, from T_{s−j+r}
      ISOFLEX_UNROLL
      for (int r = 0; r < j; ++r) {
        // T_{s−j+r+1} = N_{s−j+r+1, j−1} / (ξ_{s+r+1} − ξ_{s−j+r+1}); N[r] still holds level j − 1.
        const T t = N[r] * inv[j * (j - 1) / 2 + r];
        if (j == P) Tq[r] = t;
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
    constexpr double dp = P;
    d1[0] = -dp * Tq[0];
    ISOFLEX_UNROLL
    for (int a = 1; a < P; ++a) d1[a] = dp * (Tq[a - 1] - Tq[a]);
    d1[P] = dp * Tq[P - 1];
    if constexpr (P == 1) {
      d2[0] = zero, d2[1] = zero;
    } else {
      // g[a] = N'_{s−P+1+a, P−1} / ((P−1) (ξ_{s+a+1} − ξ_{s−P+a+1})) with N'/(P−1) = Tm[a−1] −
      // Tm[a] (Tm[−1] = Tm[P−1] = 0), a = 0 … P−1; then N''_{s−P+a} = P (P−1) (g[a−1] − g[a]),
      // g[−1] = g[P] = 0.
      const double* invP = inv + P * (P - 1) / 2;  // level j = P
      T g[P];
      g[0] = -Tm[0] * invP[0];
      ISOFLEX_UNROLL
      for (int a = 1; a < P - 1; ++a) g[a] = (Tm[a - 1] - Tm[a]) * invP[a];
      g[P - 1] = Tm[P - 2] * invP[P - 1];
      constexpr double c = P * (P - 1);
      d2[0] = -c * g[0];
      ISOFLEX_UNROLL
      for (int a = 1; a < P; ++a) d2[a] = c * (g[a - 1] - g[a]);
      d2[P] = c * g[P - 1];
    }
  }
}

// n points of one span: the reciprocals once, then the triangles, two points at a time.
template <int P>
[[gnu::always_inline]] inline void ders2_span(const double* U, int s, const double* u, int n,
                                              double* d, int stride) {
  double inv[n_reciprocals(P)];
  reciprocals<P>(U, s, inv);
  int i = 0;
  for (; i + 1 < n; i += 2, d += 6 * stride) {
    V2 v[3][P + 1];
    triangle<P>(U, s, V2{u[i], u[i + 1]}, inv, v[0], v[1], v[2]);
    ISOFLEX_UNROLL
    for (int k = 0; k < 3; ++k) {
      ISOFLEX_UNROLL
      for (int a = 0; a <= P; ++a) {
        d[k * stride + a] = v[k][a][0];
        d[(3 + k) * stride + a] = v[k][a][1];
      }
    }
  }
  if (i < n) triangle<P>(U, s, u[i], inv, d, d + stride, d + 2 * stride);
}

}  // namespace isoflex::geometry::bspline_detail
