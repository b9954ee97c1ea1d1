#include "isoflex/geometry/nurbs_surface.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>

namespace isoflex::geometry {

namespace {
[[noreturn, gnu::cold]] void throw_size_mismatch(const NurbsSurface& s) {
  const int nb = s.n_u() * s.n_v();
  if (static_cast<int>(s.points.size()) != nb)
    throw std::invalid_argument("NURBS surface: " + std::to_string(s.points.size()) +
                                " control points but the knot vectors define " +
                                std::to_string(s.n_u()) + " x " + std::to_string(s.n_v()) + " = " +
                                std::to_string(nb));
  throw std::invalid_argument("NURBS surface: " + std::to_string(s.weights.size()) +
                              " weights but " + std::to_string(nb) + " control points");
}
// Called on every evaluation: the comparison inline, the message out of line.
inline void check_sizes(const NurbsSurface& s) {
  const int nb = s.n_u() * s.n_v();
  if (static_cast<int>(s.points.size()) != nb || static_cast<int>(s.weights.size()) != nb)
      [[unlikely]]
    throw_size_mismatch(s);
}
}  // namespace

bool NurbsSurface::is_rational() const {
  for (double w : weights)
    if (w != weights.front()) return true;
  return false;
}

void NurbsSurface::validate() const {
  check_sizes(*this);
  for (std::size_t k = 0; k < points.size(); ++k) {
    // Written so that NaN fails: (4.12) needs w_ij ∈ R⁺.
    if (!(weights[k] > 0.0) || !std::isfinite(weights[k]))
      throw std::invalid_argument("NURBS surface: weight " + std::to_string(k) + " = " +
                                  std::to_string(weights[k]) + " is not positive and finite");
    if (!points[k].allFinite())
      throw std::invalid_argument("NURBS surface: control point " + std::to_string(k) +
                                  " is not finite");
  }
}

int SurfaceBasis::global_index(const NurbsSurface& s, int k) const {
  const int p1 = s.degree_u() + 1;
  return s.index(span_u - s.degree_u() + k % p1, span_v - s.degree_v() + k / p1);
}

namespace {

// Complete unrolling of the loops over the ξ-degree P (GCC unrolls only tiny loops at -O2).
#define ISOFLEX_UNROLL _Pragma("GCC unroll 16")

// Two doubles in one SSE2 register (GCC/Clang vector extension): (R, R_ξ), (R_η, R_ξξ) and
// (R_ξη, R_ηη) of one function are computed and stored as pairs.
using V2 [[gnu::vector_size(16)]] = double;

// Bivariate rational basis (4.12), R_k = A_k / W with A_k = w_k N_a(ξ) M_b(η) (k = a + (p+1)·b,
// N_a = N_{span_u−p+a}, M_b = N_{span_v−q+b}), W = Σ_k A_k, and its derivatives. The quotient rule
//   R_ξ  = (A_ξ − R W_ξ)/W,                      R_η likewise,
//   R_ξξ = (A_ξξ − 2 R_ξ W_ξ − R W_ξξ)/W,         R_ηη likewise,
//   R_ξη = (A_ξη − R_ξ W_η − R_η W_ξ − R W_ξη)/W
// factors, because A_k is a product, into 1D functions: with ω_ξ = W_ξ/W, ω_ξξ = W_ξξ/W, …
//   Ñ'_a = N'_a − ω_ξ N_a,   Ñ''_a = N''_a − 2 ω_ξ N'_a + (2 ω_ξ² − ω_ξξ) N_a,   M̃ likewise,
//   R = w N M/W,  R_ξ = w Ñ' M/W,  R_η = w N M̃'/W,  R_ξξ = w Ñ'' M/W,  R_ηη = w N M̃''/W,
//   R_ξη = w (Ñ' M̃' + (ω_ξ ω_η − ω_ξη) N M)/W
// (substitute R, R_ξ, R_η into the second-derivative lines; docs/theory/nurbs-tools.md §5).
// W and its derivatives are sums along ξ per row b, then along η; 1/W is the only division.
template <int P>
void surface_kernel(const NurbsSurface& s, double xi, double eta, SurfaceBasis& out) {
  const int q = s.degree_v();
  BasisArray Bu, Bv;
  bspline_basis_unchecked(s.u, out.span_u, xi, Bu);
  bspline_basis_unchecked(s.v, out.span_v, eta, Bv);
  const double *N = Bu[0], *N1 = Bu[1], *N2 = Bu[2];
  const double *M = Bv[0], *M1 = Bv[1], *M2 = Bv[2];
  const int nu = s.n_u();
  const double* w0 = s.weights.data() + s.index(out.span_u - P, out.span_v - q);  // w_{a,b=0}

  // W and its derivatives (numbered like the rows of R): W01 = (W, W_ξ) and W24 = (W_η, W_ξη) as
  // pairs from (N, N'), W_ξξ and W_ηη alone.
  V2 n[P + 1];
  ISOFLEX_UNROLL
  for (int a = 0; a <= P; ++a) n[a] = V2{N[a], N1[a]};
  V2 W01 = {0.0, 0.0}, W24 = {0.0, 0.0};
  double Wuu = 0.0, Wvv = 0.0;
  for (int b = 0; b <= q; ++b) {
    const double* w = w0 + nu * b;
    V2 c01 = w[0] * n[0];      // Σ_a w (N, N')
    double c2 = w[0] * N2[0];  // Σ_a w N''
    ISOFLEX_UNROLL
    for (int a = 1; a <= P; ++a) c01 += w[a] * n[a], c2 += w[a] * N2[a];
    W01 += M[b] * c01;
    W24 += M1[b] * c01;
    Wuu += M[b] * c2;
    Wvv += M2[b] * c01[0];
  }
  const double iW = 1.0 / W01[0];
  const double ou = W01[1] * iW, ov = W24[0] * iW, ouv = W24[1] * iW;
  const double ouu = Wuu * iW, ovv = Wvv * iW;
  const double ku = 2.0 * ou, ku0 = ku * ou - ouu;  // Ñ'' = N'' − ku N' + ku0 N
  const double kv = 2.0 * ov, kv0 = kv * ov - ovv;
  const double c = ou * ov - ouv;

  // Pairs per a: (N, Ñ'), (N, Ñ''), (Ñ', N); per b: (M, M), (M̃', M), (M̃', M̃'') times 1/W. Per
  // function, with (t0, t1, t2) = w (M, M̃', M̃'')/W:
  //   R = N t0, R_ξ = Ñ' t0, R_η = N t1, R_ξξ = Ñ'' t0, R_ξη = Ñ' t1 + c R, R_ηη = N t2.
  V2 n01[P + 1], n23[P + 1], n45[P + 1];
  ISOFLEX_UNROLL
  for (int a = 0; a <= P; ++a) {
    const double Nt1 = N1[a] - ou * N[a];
    const double Nt2 = N2[a] - ku * N1[a] + ku0 * N[a];
    n01[a] = V2{N[a], Nt1};
    n23[a] = V2{N[a], Nt2};
    n45[a] = V2{Nt1, N[a]};
  }
  const V2 cR = {c, 0.0};  // adds c R to R_ξη, nothing to R_ηη
  double* col = out.R.data();
  for (int b = 0; b <= q; ++b) {
    const double* w = w0 + nu * b;
    const double m0 = iW * M[b];
    const double m1 = iW * (M1[b] - ov * M[b]);
    const double m2 = iW * (M2[b] - kv * M1[b] + kv0 * M[b]);
    const V2 b01 = {m0, m0}, b23 = {m1, m0}, b45 = {m1, m2};
    ISOFLEX_UNROLL
    for (int a = 0; a <= P; ++a, col += 6) {
      const V2 r01 = n01[a] * (w[a] * b01);             // (R, R_ξ)
      const V2 r23 = n23[a] * (w[a] * b23);             // (R_η, R_ξξ)
      const V2 r45 = n45[a] * (w[a] * b45) + cR * r01;  // (R_ξη, R_ηη)
      std::memcpy(col, &r01, sizeof r01);
      std::memcpy(col + 2, &r23, sizeof r23);
      std::memcpy(col + 4, &r45, sizeof r45);
    }
  }
}

using SurfaceKernel = void (*)(const NurbsSurface&, double, double, SurfaceBasis&);
template <int... P>
constexpr std::array<SurfaceKernel, sizeof...(P)> make_kernels(std::integer_sequence<int, P...>) {
  return {&surface_kernel<P>...};
}
constexpr auto kSurfaceKernels = make_kernels(std::make_integer_sequence<int, kMaxDegree + 1>{});

}  // namespace

SurfaceBasis surface_basis(const NurbsSurface& s, double xi, double eta) {
  check_sizes(s);
  if (std::isnan(xi) || std::isnan(eta))
    throw std::invalid_argument("surface_basis: parameter is NaN");
  // Clamped like bspline_basis: the polynomial pieces are never extrapolated.
  xi = std::clamp(xi, s.u.front(), s.u.back());
  eta = std::clamp(eta, s.v.front(), s.v.back());
  SurfaceBasis out;
  out.span_u = s.u.find_span(xi);
  out.span_v = s.v.find_span(eta);
  out.R.resize(6, (s.degree_u() + 1) * (s.degree_v() + 1));
  kSurfaceKernels[s.degree_u()](s, xi, eta, out);
  return out;
}

// The surface (4.13) in homogeneous form: A = Σ w_ij N_i N_j P_ij, W = Σ w_ij N_i N_j, S = A/W;
// differentiating A = W S (The NURBS Book ch. 4):
//   S_ξ  = (A_ξ − W_ξ S)/W,                         S_η likewise,
//   S_ξξ = (A_ξξ − 2 W_ξ S_ξ − W_ξξ S)/W,            S_ηη likewise,
//   S_ξη = (A_ξη − W_ξ S_η − W_η S_ξ − W_ξη S)/W.
// Deliberately a separate code path from surface_basis (a row-by-row sum, no rational basis),
// so the two can check each other.
SurfacePoint evaluate(const NurbsSurface& s, double xi, double eta) {
  check_sizes(s);
  const int p = s.degree_u(), q = s.degree_v();
  const Basis1D Nu = bspline_basis(s.u, xi, 2);
  const Basis1D Nv = bspline_basis(s.v, eta, 2);
  // Homogeneous sums: first along ξ for each row b, then along η.
  Eigen::Matrix<double, 4, 6> H = Eigen::Matrix<double, 4, 6>::Zero();  // (A; W) per derivative
  for (int b = 0; b <= q; ++b) {
    Eigen::Matrix<double, 4, 3> row = Eigen::Matrix<double, 4, 3>::Zero();  // (A; W), d^0..2/dξ
    for (int a = 0; a <= p; ++a) {
      const int i = s.index(Nu.span - p + a, Nv.span - q + b);
      Eigen::Vector4d hw;
      hw << s.weights[i] * s.points[i], s.weights[i];
      for (int k = 0; k < 3; ++k) row.col(k) += Nu.ders(k, a) * hw;
    }
    H.col(0) += Nv.ders(0, b) * row.col(0);  // A, W
    H.col(1) += Nv.ders(0, b) * row.col(1);  // ∂ξ
    H.col(2) += Nv.ders(1, b) * row.col(0);  // ∂η
    H.col(3) += Nv.ders(0, b) * row.col(2);  // ∂ξξ
    H.col(4) += Nv.ders(1, b) * row.col(1);  // ∂ξη
    H.col(5) += Nv.ders(2, b) * row.col(0);  // ∂ηη
  }
  const double W = H(3, 0), Wu = H(3, 1), Wv = H(3, 2), Wuu = H(3, 3), Wuv = H(3, 4), Wvv = H(3, 5);
  SurfacePoint out;
  out.x = H.block<3, 1>(0, 0) / W;
  out.xu = (H.block<3, 1>(0, 1) - Wu * out.x) / W;
  out.xv = (H.block<3, 1>(0, 2) - Wv * out.x) / W;
  out.xuu = (H.block<3, 1>(0, 3) - 2.0 * Wu * out.xu - Wuu * out.x) / W;
  out.xuv = (H.block<3, 1>(0, 4) - Wu * out.xv - Wv * out.xu - Wuv * out.x) / W;
  out.xvv = (H.block<3, 1>(0, 5) - 2.0 * Wv * out.xv - Wvv * out.x) / W;
  return out;
}

}  // namespace isoflex::geometry
