#include "isoflex/geometry/element_basis.hpp"

#include <array>
#include <cstdint>
#include <cstring>
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>

#include "isoflex/geometry/bspline_triangle.hpp"

namespace isoflex::geometry {

int ElementBasis::global_index(const NurbsSurface& s, int k) const {
  const int p1 = s.degree_u() + 1;
  return s.index(span_u - s.degree_u() + k % p1, span_v - s.degree_v() + k / p1);
}

namespace {

using bspline_detail::V2;

inline V2 load2(const double* p) {
  V2 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline void store2(double* p, V2 v) {
  std::memcpy(p, &v, sizeof v);
}
inline V2 splat(double x) {
  return V2{x, x};
}

// Degrees up to which element_kernel is instantiated for fixed (p, q), completely unrolled;
// higher degrees take the same code with the degrees at run time.
constexpr int kFixedDegrees = 5;
constexpr int kRuntime = -1;
// Per point, between the two passes of element_kernel: (ω_ξ, ω_η), (2ω_ξ, 2ω_η),
// (2ω_ξ² − ω_ξξ, 2ω_η² − ω_ηη), (1/W, ω_ξ ω_η − ω_ξη).
constexpr int kScratchPerPoint = 8;

// The algorithm of surface_basis (nurbs_surface.cpp, docs/theory/nurbs-tools.md §5) with the
// same operations in the same order, so that every value is bit for bit the same, but arranged
// over the grid (ξ_i) × (η_j) of one element:
//   per element    the reciprocals of the two triangles (4.3), the weights in local order;
//   per ξ_i, η_j   the univariate bases (N, N', N'')(ξ_i), (M, M', M'')(η_j);
//   per (ξ_i, b)   the partial sums c_b = Σ_a w_ab (N_a, N'_a, N''_a);
//   per point      W and its derivatives Σ_b M_b^(l) c_b, 1/W, ω, Ñ', Ñ'' (per a), M̃', M̃''
//                  (per b), and the six values of every function.
// In the last step the functions go in pairs (k, k+1) of the local numbering k = a + (p+1)·b,
// one per SSE2 lane, so that every store is a contiguous pair of a row of
// ElementBasis::values (16-byte aligned: the row stride is even); when p + 1 is odd a pair may
// span two rows, (a, b) = (p, b), (0, b+1): the ξ-side arrays carry a copy of entry 0 behind
// entry p for that. If (p+1)(q+1) is odd, the last function is computed in a pair with a zero
// weight, whose lane goes to the padding entry of the rows.
// P, Q: the degrees, or kRuntime for degrees known at run time only.
template <int P, int Q>
void element_kernel(const NurbsSurface& s, ElementBasis& e) {
  const int p = P >= 0 ? P : s.degree_u(), q = Q >= 0 ? Q : s.degree_v();
  const int p1 = p + 1, q1 = q + 1, nf = p1 * q1, ld = e.row_stride;
  constexpr int kP1 = (P >= 0 ? P : kMaxDegree) + 1;  // array bounds
  constexpr int kQ1 = (Q >= 0 ? Q : kMaxDegree) + 1;
  const int nu = e.n_u, nv = e.n_v;
  const int sx = p1 + 1, sy = q1 + 1;  // row strides of the univariate tables: one extra entry

  double* Nu = e.work.data();     // per ξ_i: N, N', N'' (stride sx), entry p+1 = entry 0
  double* Mv = Nu + 3 * sx * nu;  // per η_j: M, M', M'' (stride sy), entry q+1 = 0
  double* C = Mv + 3 * sy * nv;   // per (ξ_i, b): Σ_a w (N, N', N''), Σ_a w N again
  double* MM = C + 4 * q1 * nu;   // per (η_j, b): (M, M'')
  if constexpr (P >= 0) {
    bspline_detail::ders2_span<P>(s.u.knots().data(), e.span_u, e.xi.data(), nu, Nu, sx);
    bspline_detail::ders2_span<Q>(s.v.knots().data(), e.span_v, e.eta.data(), nv, Mv, sy);
  } else {
    bspline_basis_span_unchecked(s.u, e.span_u, e.xi.data(), nu, Nu, sx);
    bspline_basis_span_unchecked(s.v, e.span_v, e.eta.data(), nv, Mv, sy);
  }
  if (p1 % 2 == 1)
    for (double* r = Nu; r != Nu + 3 * sx * nu; r += sx) r[p1] = r[0];
  if (q1 % 2 == 1)
    for (double* r = Mv; r != Mv + 3 * sy * nv; r += sy) r[q1] = 0.0;

  // The weights in local order k = a + (p+1) b, and a zero behind them.
  const int ncp = s.n_u();  // stride of a row of control points
  const double* w0 = s.weights.data() + s.index(e.span_u - p, e.span_v - q);  // w_{a,b=0}
  alignas(16) double wk[kP1 * kQ1 + 1];
  for (int b = 0; b < q1; ++b)
    for (int a = 0; a < p1; ++a) wk[a + p1 * b] = w0[a + ncp * b];
  wk[nf] = 0.0;

  // Partial sums along ξ, exactly as in surface_basis: (Σ w N, Σ w N') as a pair, Σ w N''.
  for (int i = 0; i < nu; ++i) {
    const double *N = Nu + 3 * sx * i, *N2 = N + 2 * sx;
    V2 n[kP1];
    ISOFLEX_UNROLL
    for (int a = 0; a < p1; ++a) n[a] = V2{N[a], N[sx + a]};
    double* c = C + 4 * q1 * i;
    for (int b = 0; b < q1; ++b, c += 4) {
      const double* w = wk + p1 * b;
      V2 c01 = w[0] * n[0];
      double c2 = w[0] * N2[0];
      ISOFLEX_UNROLL
      for (int a = 1; a < p1; ++a) c01 += w[a] * n[a], c2 += w[a] * N2[a];
      store2(c, c01);
      store2(c + 2, V2{c2, c01[0]});
    }
  }
  for (int j = 0; j < nv; ++j) {
    const double *M = Mv + 3 * sy * j, *M2 = M + 2 * sy;
    ISOFLEX_UNROLL
    for (int b = 0; b < q1; ++b) store2(MM + 2 * (q1 * j + b), V2{M[b], M2[b]});
  }

  // Per point: (ω_ξ, ω_η), k = (2ω_ξ, 2ω_η), k0 = (2ω_ξ² − ω_ξξ, 2ω_η² − ω_ηη), (1/W, c) with
  // c = ω_ξ ω_η − ω_ξη; 16-byte aligned.
  constexpr int ns = kScratchPerPoint;
  double* S = MM + 2 * q1 * nv;
  S += reinterpret_cast<std::uintptr_t>(S) % 16 / sizeof(double);

  // First W and ω at all points: each point's chain W → 1/W → ω is long, the points are
  // independent, so the processor overlaps them here.
  double* sg = S;
  for (int j = 0; j < nv; ++j) {
    const double *M = Mv + 3 * sy * j, *M1 = M + sy;
    const double* mm = MM + 2 * q1 * j;
    for (int i = 0; i < nu; ++i, sg += ns) {
      // W and its derivatives as pairs: W01 = (W, W_ξ), W24 = (W_η, W_ξη), W35 = (W_ξξ, W_ηη).
      // (surface_basis starts these sums from 0: the same values, up to the sign of a zero.)
      const double* c = C + 4 * q1 * i;
      V2 c01 = load2(c);
      V2 W01 = M[0] * c01, W24 = M1[0] * c01, W35 = load2(mm) * load2(c + 2);
      ISOFLEX_UNROLL
      for (int b = 1; b < q1; ++b) {
        c01 = load2(c + 4 * b);
        W01 += M[b] * c01;
        W24 += M1[b] * c01;
        W35 += load2(mm + 2 * b) * load2(c + 4 * b + 2);
      }
      // ω = W_·/W: (·, ω_ξ), (ω_η, ω_ξη), (ω_ξξ, ω_ηη).
      const double iW = 1.0 / W01[0];
      const V2 iWv = splat(iW);
      const V2 o01 = W01 * iWv, o24 = W24 * iWv, o35 = W35 * iWv;
      const V2 o12 = {o01[1], o24[0]};  // (ω_ξ, ω_η)
      const V2 k = 2.0 * o12;
      store2(sg, o12);
      store2(sg + 2, k);
      store2(sg + 4, k * o12 - o35);
      store2(sg + 6, V2{iW, o12[0] * o12[1] - o24[1]});
    }
  }

  // Then per point Ñ', Ñ'' and M̃', M̃'' and the functions, two at a time: R = N t0, R_ξ = Ñ' t0,
  // R_η = N t1, R_ξξ = Ñ'' t0, R_ξη = Ñ' t1 + c R, R_ηη = N t2 with (t0, t1, t2) = w (M, M̃',
  // M̃'')/W.
  double* out = e.values.data();
  sg = S;
  for (int j = 0; j < nv; ++j) {
    const double *M = Mv + 3 * sy * j, *M1 = M + sy, *M2 = M1 + sy;
    for (int i = 0; i < nu; ++i, out += 6 * ld, sg += ns) {
      const double* N = Nu + 3 * sx * i;
      const double *N1 = N + sx, *N2 = N1 + sx;
      const double ou = sg[0], ov = sg[1], ku = sg[2], kv = sg[3], ku0 = sg[4], kv0 = sg[5];
      const double iW = sg[6];
      const V2 cc = splat(sg[7]);
      // Ñ' = N' − ω_ξ N, Ñ'' per a (pairs; for odd p+1 the last pair gives entry p and the copy
      // of entry 0), and (M, M̃', M̃'')/W per b.
      alignas(16) double n1[kP1 + 1], n2[kP1 + 1], m0[kQ1 + 1], m1[kQ1 + 1], m2[kQ1 + 1];
      ISOFLEX_UNROLL
      for (int a = 0; a < p1; a += 2) {
        const V2 x0 = load2(N + a), x1 = load2(N1 + a), x2 = load2(N2 + a);
        store2(n1 + a, x1 - ou * x0);
        store2(n2 + a, x2 - ku * x1 + ku0 * x0);
      }
      ISOFLEX_UNROLL
      for (int b = 0; b < q1; b += 2) {
        const V2 x0 = load2(M + b), x1 = load2(M1 + b), x2 = load2(M2 + b);
        store2(m0 + b, iW * x0);
        store2(m1 + b, iW * (x1 - ov * x0));
        store2(m2 + b, iW * (x2 - kv * x1 + kv0 * x0));
      }
      // Functions k and k+1.
      auto pair = [&](int k) {
        const int a = k % p1, b = k / p1;
        V2 y0, y1, y2;  // (M, M̃', M̃'')/W of the two functions
        if (a + 1 < p1) {
          y0 = splat(m0[b]), y1 = splat(m1[b]), y2 = splat(m2[b]);
        } else {  // (p, b) and (0, b+1)
          y0 = load2(m0 + b), y1 = load2(m1 + b), y2 = load2(m2 + b);
        }
        const V2 wt = load2(wk + k);
        const V2 t0 = wt * y0, t1 = wt * y1, t2 = wt * y2;
        const V2 x0 = load2(N + a), x1 = load2(n1 + a), x2 = load2(n2 + a);
        const V2 r = x0 * t0;
        // (k + 1 = nf: the padding entry of the rows gets the value of the zero weight.)
        double* o = out + k;
        store2(o, r);
        store2(o + ld, x1 * t0);
        store2(o + 2 * ld, x0 * t1);
        store2(o + 3 * ld, x2 * t0);
        store2(o + 4 * ld, x1 * t1 + cc * r);
        store2(o + 5 * ld, x0 * t2);
      };
      if constexpr (P >= 0) {
        _Pragma("GCC unroll 64") for (int k = 0; k < nf; k += 2) pair(k);
      } else {
        for (int k = 0; k < nf; k += 2) pair(k);
      }
    }
  }
}

using ElementKernel = void (*)(const NurbsSurface&, ElementBasis&);
template <int... K>
constexpr std::array<ElementKernel, sizeof...(K)> make_kernels(std::integer_sequence<int, K...>) {
  constexpr int n = kFixedDegrees + 1;
  return {&element_kernel<K % n, K / n>...};
}
// kFixedKernels[p + (kFixedDegrees + 1) q]
constexpr auto kFixedKernels =
    make_kernels(std::make_integer_sequence<int, (kFixedDegrees + 1) * (kFixedDegrees + 1)>{});

// Error paths, out of line.
[[noreturn, gnu::cold, gnu::noinline]] void fail(const std::string& what) {
  throw std::invalid_argument("element_basis: " + what);
}
[[noreturn, gnu::cold, gnu::noinline]] void fail_sizes(const NurbsSurface& s) {
  fail(std::to_string(s.points.size()) + " control points and " + std::to_string(s.weights.size()) +
       " weights, but the knot vectors define " + std::to_string(s.n_u() * s.n_v()));
}
[[noreturn, gnu::cold, gnu::noinline]] void fail_span(const char* dir, int span) {
  fail(std::string(dir) + "-span " + std::to_string(span) + " is not a non-empty knot span");
}
[[noreturn, gnu::cold, gnu::noinline]] void fail_parameter(const char* dir, double u, double lo,
                                                           double hi) {
  fail(std::string(dir) + " = " + std::to_string(u) + " outside its span [" + std::to_string(lo) +
       ", " + std::to_string(hi) + "]");
}

// The numbers of points and weights match the knot vectors, and both spans are non-empty knot
// spans.
inline void check_surface_and_spans(const NurbsSurface& s, int span_u, int span_v) {
  const std::size_t nb = static_cast<std::size_t>(s.n_u()) * s.n_v();
  if (s.points.size() != nb || s.weights.size() != nb) [[unlikely]]
    fail_sizes(s);
  const auto &U = s.u.knots(), &V = s.v.knots();
  if (span_u < s.degree_u() || span_u >= s.n_u() || !(U[span_u] < U[span_u + 1])) [[unlikely]]
    fail_span("xi", span_u);
  if (span_v < s.degree_v() || span_v >= s.n_v() || !(V[span_v] < V[span_v + 1])) [[unlikely]]
    fail_span("eta", span_v);
}

// The parameters lie in the span (NaN does not).
void check_parameters(const KnotVector& kv, int span, const std::vector<double>& x,
                      const char* dir) {
  const double lo = kv.knots()[span], hi = kv.knots()[span + 1];
  for (const double u : x)
    if (!(u >= lo && u <= hi)) [[unlikely]]
      fail_parameter(dir, u, lo, hi);
}

// Sizes the output and evaluates; everything has been checked.
void run(const NurbsSurface& s, ElementBasis& out) {
  const int p1 = s.degree_u() + 1, q1 = s.degree_v() + 1;
  out.n_u = static_cast<int>(out.xi.size());
  out.n_v = static_cast<int>(out.eta.size());
  out.n_functions = p1 * q1;
  out.row_stride = (out.n_functions + 1) & ~1;
  const std::size_t nv = 6 * static_cast<std::size_t>(out.row_stride) * out.n_u * out.n_v;
  const std::size_t nw = static_cast<std::size_t>(3 * (p1 + 1) * out.n_u + 3 * (q1 + 1) * out.n_v +
                                                  4 * q1 * out.n_u + 2 * q1 * out.n_v + 1) +
                         static_cast<std::size_t>(kScratchPerPoint) * out.n_u * out.n_v;
  if (out.values.size() != nv) out.values.resize(nv);
  if (out.work.size() < nw) out.work.resize(nw);
  if (p1 <= kFixedDegrees + 1 && q1 <= kFixedDegrees + 1)
    kFixedKernels[(p1 - 1) + (kFixedDegrees + 1) * (q1 - 1)](s, out);
  else
    element_kernel<kRuntime, kRuntime>(s, out);
}

// v = x, also if x is (a part of) v itself.
void assign(std::vector<double>& v, std::span<const double> x) {
  if (x.data() == v.data() && x.size() == v.size()) return;
  const std::less<const double*> before;
  if (!v.empty() && !before(x.data(), v.data()) && before(x.data(), v.data() + v.size())) {
    std::vector<double> copy(x.begin(), x.end());
    v.swap(copy);
  } else {
    v.assign(x.begin(), x.end());
  }
}

}  // namespace

void element_basis(const NurbsSurface& s, int span_u, int span_v, std::span<const double> xi,
                   std::span<const double> eta, ElementBasis& out) {
  check_surface_and_spans(s, span_u, span_v);
  if (xi.empty() || eta.empty()) fail("no points");
  out.span_u = span_u;
  out.span_v = span_v;
  assign(out.xi, xi);
  assign(out.eta, eta);
  check_parameters(s.u, span_u, out.xi, "xi");
  check_parameters(s.v, span_v, out.eta, "eta");
  run(s, out);
}

void element_basis(const NurbsSurface& s, const SurfaceElement& e, const GaussRule& rule_u,
                   const GaussRule& rule_v, ElementBasis& out) {
  check_surface_and_spans(s, e.span_u, e.span_v);
  // The nodes lie in (−1, 1), so the points in [u0, u1] × [v0, v1], which must be the element.
  if (e.u0 != s.u.knots()[e.span_u] || e.u1 != s.u.knots()[e.span_u + 1] ||
      e.v0 != s.v.knots()[e.span_v] || e.v1 != s.v.knots()[e.span_v + 1]) [[unlikely]]
    fail("the bounds of the element are not the knots of its spans");
  if (rule_u.size() == 0 || rule_v.size() == 0) fail("no points");
  out.span_u = e.span_u;
  out.span_v = e.span_v;
  // The affine parent map of element_quadrature, ξ = (u0 + u1)/2 + (u1 − u0)/2 · ζ.
  const double mu = 0.5 * (e.u0 + e.u1), hu = 0.5 * (e.u1 - e.u0);
  const double mv = 0.5 * (e.v0 + e.v1), hv = 0.5 * (e.v1 - e.v0);
  if (out.xi.size() != rule_u.nodes.size()) out.xi.resize(rule_u.nodes.size());
  if (out.eta.size() != rule_v.nodes.size()) out.eta.resize(rule_v.nodes.size());
  for (std::size_t i = 0; i < out.xi.size(); ++i) out.xi[i] = mu + hu * rule_u.nodes[i];
  for (std::size_t j = 0; j < out.eta.size(); ++j) out.eta[j] = mv + hv * rule_v.nodes[j];
  run(s, out);
}

}  // namespace isoflex::geometry
