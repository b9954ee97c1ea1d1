// Basis-evaluation benchmark (see bench/basis.md): throughput of the rational basis — all
// (p+1)(q+1) non-zero functions R with their first and second derivatives at a point,
// IGA-thesis (4.3), (4.12) — for p = q = 2 … 5 on a rational surface of 8 × 8 elements:
//   element_basis/p           geometry::element_basis, all (p+1)² Gauss points of an element at
//                             once, element after element (the element loop of assembly);
//   surface_basis_gauss/p     geometry::surface_basis at the same points, one at a time;
//   naive_cox_de_boor_gauss/p the naive recursive Cox–de Boor reference (below) at those points;
//   surface_basis/p, naive_cox_de_boor/p   the same two at 4096 random points;
// against the machine's scalar floating-point peak measured by a loop of independent
// multiply–adds.
//
//   basis_bench [Google Benchmark flags, e.g. --benchmark_filter=p=3]
//
// Each benchmark runs kRepetitions short repetitions; Google Benchmark prints their mean, median,
// stddev and cv (points/s as items_per_second, flop/pt the count of the algorithm derived in
// flops_per_point and flops_per_element below); summary tables at the end give, per p, the
// fastest and the median repetition in ns per point, points/s, flop/pt, achieved GFlop/s,
// vs_peak = time per point / (flop/pt ÷ peak) — how many times longer than the flop count takes
// at the measured scalar peak — and the naive/kernel time ratio.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "isoflex/geometry/element_basis.hpp"
#include "isoflex/geometry/nurbs_surface.hpp"
#include "isoflex/geometry/quadrature.hpp"

namespace {

using isoflex::Vec3;
using isoflex::geometry::KnotVector;
using isoflex::geometry::NurbsSurface;
using isoflex::geometry::SurfaceElement;

constexpr int kSpans = 8;      // spans per direction of the benchmark surface
constexpr int kPoints = 4096;  // evaluation points per benchmark iteration
// Many short repetitions, of which the summary takes the fastest: on a shared machine a short
// repetition has a fair chance to run undisturbed, a long one hardly.
constexpr int kRepetitions = 20;
constexpr double kMinTime = 0.05;  // seconds per repetition

// A rational degree (p, p) surface with kSpans × kSpans elements, wavy control net and
// scattered weights (a realistic, not a degenerate, rational case).
NurbsSurface bench_surface(int p) {
  NurbsSurface s;
  s.u = KnotVector::open_uniform(p, kSpans);
  s.v = KnotVector::open_uniform(p, kSpans);
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> w(0.7, 1.3);
  for (int j = 0; j < s.n_v(); ++j)
    for (int i = 0; i < s.n_u(); ++i) {
      s.points.push_back(Vec3(i, j, 0.2 * std::sin(0.5 * i) * std::cos(0.4 * j)));
      s.weights.push_back(w(rng));
    }
  return s;
}

std::vector<std::pair<double, double>> bench_points() {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::vector<std::pair<double, double>> pts(kPoints);
  for (auto& x : pts) x = {U(rng), U(rng)};
  return pts;
}

// Floating-point operations per point of the algorithm in geometry/bspline_basis.cpp and
// geometry/nurbs_surface.cpp (+, −, ×, ÷ one flop each, counted as scalar operations: an SSE2
// instruction on a pair counts its useful lanes; integer index arithmetic, comparisons and sign
// flips not counted), for p ≥ 2, two derivatives (docs/theory/nurbs-tools.md §5):
//   1D: u − ξ, ξ − u: 2p; triangle (4.3): knot difference, reciprocal, T = N·(1/Δ), two products
//     and a sum per entry, less the first level's T (= 1/Δ) and the first sum of each level:
//     3p² + 2p − 1; N' = p(T − T): 2p; N'' = p(p−1)(g − g), g = (T − T)/Δ: (p − 2) + 3p
//     → f₁(p) = 3p² + 10p − 3
//   W and derivatives: per row b, Σ_a w (N, N', N'') 6p + 3, then 12 → (q+1)(6p + 15)
//   1/W, ω = W_·/W, 2ω_ξ, 2ω_ξ² − ω_ξξ (both directions), ω_ξω_η − ω_ξη: 14
//   Ñ', Ñ'' per a: 6(p+1); M̃', M̃'' and the factor 1/W per b: 9(q+1)
//   per function: t = w·(M, M̃', M̃'')/W (3), six products, + c·R (2): 11 (p+1)(q+1)
//   total f(p, q) = f₁(p) + f₁(q) + (q+1)(6p + 15) + 14 + 6(p+1) + 9(q+1) + 11(p+1)(q+1),
//   for p = q: 23p² + 78p + 49.
double flops_1d(int p) {
  return 3.0 * p * p + 10.0 * p - 3.0;
}
double flops_per_point(int p, int q) {
  return flops_1d(p) + flops_1d(q) + (q + 1) * (6.0 * p + 15.0) + 14.0 + 6.0 * (p + 1) +
         9.0 * (q + 1) + 11.0 * (p + 1) * (q + 1);
}

// Floating-point operations of geometry::element_basis (element_basis.cpp) for one element with
// an n_u × n_v grid of points, counted like flops_per_point (scalar operations, each +, −, ×, ÷
// one flop, useful SSE2 lanes only), for p, q ≥ 2 (docs/theory/nurbs-tools.md §5):
//   per element: the Gauss points ξ = m + h ζ: 8 + 2(n_u + n_v); the reciprocals of the two
//     triangles, a difference and a division each: p(p+1) + q(q+1)
//   per ξ_i (and per η_j with q): the triangle without the reciprocals, u − ξ, ξ − u, N', N'':
//     f₁(p) − p(p+1) = 2p² + 9p − 3
//   per (ξ_i, row b): Σ_a w (N, N', N''): 3(2p + 1)
//   per point: W and its 5 derivatives Σ_b M^(l)_b c_b: 12(q+1) − 6 (the first term is not an
//     addition); 1/W, ω, 2ω, 2ω² − ω_··, ω_ξω_η − ω_ξη: 14; Ñ', Ñ'' per a: 6(p+1); (M, M̃', M̃'')/W
//     per b: 9(q+1); per function 11 (as in flops_per_point)
double flops_per_element(int p, int q, int nu, int nv) {
  const double tri_u = 2.0 * p * p + 9.0 * p - 3.0, tri_v = 2.0 * q * q + 9.0 * q - 3.0;
  const double per_point =
      12.0 * (q + 1) - 6.0 + 14.0 + 6.0 * (p + 1) + 9.0 * (q + 1) + 11.0 * (p + 1) * (q + 1);
  return 8.0 + 2.0 * (nu + nv) + p * (p + 1.0) + q * (q + 1.0) + nu * tri_u + nv * tri_v +
         nu * (q + 1) * 3.0 * (2.0 * p + 1.0) + nu * nv * per_point;
}
// The benchmark grid: the default (p+1) × (q+1) Gauss points of every element.
int gauss_points(int p) {
  return p + 1;
}
double flops_per_point_element(int p) {
  const int n = gauss_points(p);
  return flops_per_element(p, p, n, n) / (n * n);
}

// ---- Naive reference: Cox–de Boor recursion (4.3) per function, derivatives by recursion ----

double N(const std::vector<double>& U, int i, int p, double u) {
  if (p == 0) return (U[i] <= u && u < U[i + 1]) ? 1.0 : 0.0;
  double v = 0.0;
  const double d1 = U[i + p] - U[i], d2 = U[i + p + 1] - U[i + 1];
  if (d1 > 0.0) v += (u - U[i]) / d1 * N(U, i, p - 1, u);
  if (d2 > 0.0) v += (U[i + p + 1] - u) / d2 * N(U, i + 1, p - 1, u);
  return v;
}

// k-th derivative: N^(k)_{i,p} = p (N^(k−1)_{i,p−1}/(u_{i+p} − u_i) − N^(k−1)_{i+1,p−1}/(u_{i+p+1}
// − u_{i+1})).
double dN(const std::vector<double>& U, int i, int p, int k, double u) {
  if (k == 0) return N(U, i, p, u);
  if (p == 0) return 0.0;
  double v = 0.0;
  const double d1 = U[i + p] - U[i], d2 = U[i + p + 1] - U[i + 1];
  if (d1 > 0.0) v += p * dN(U, i, p - 1, k - 1, u) / d1;
  if (d2 > 0.0) v -= p * dN(U, i + 1, p - 1, k - 1, u) / d2;
  return v;
}

// Same output as surface_basis (6 × (p+1)(q+1), column a + (p+1) b), computed naively.
void naive_surface_basis(const NurbsSurface& s, double xi, double eta, std::vector<double>& R) {
  const int p = s.u.degree(), q = s.v.degree();
  const int su = s.u.find_span(xi), sv = s.v.find_span(eta);
  const auto& U = s.u.knots();
  const auto& V = s.v.knots();
  double Nu[3][11], Nv[3][11];
  for (int a = 0; a <= p; ++a)
    for (int k = 0; k < 3; ++k) Nu[k][a] = dN(U, su - p + a, p, k, xi);
  for (int b = 0; b <= q; ++b)
    for (int k = 0; k < 3; ++k) Nv[k][b] = dN(V, sv - q + b, q, k, eta);
  const int n = (p + 1) * (q + 1);
  R.assign(6 * n, 0.0);
  double W[6] = {0, 0, 0, 0, 0, 0};
  for (int b = 0; b <= q; ++b)
    for (int a = 0; a <= p; ++a) {
      const int k = a + (p + 1) * b;
      const double w = s.weights[s.index(su - p + a, sv - q + b)];
      double* r = &R[6 * k];
      r[0] = w * Nu[0][a] * Nv[0][b];
      r[1] = w * Nu[1][a] * Nv[0][b];
      r[2] = w * Nu[0][a] * Nv[1][b];
      r[3] = w * Nu[2][a] * Nv[0][b];
      r[4] = w * Nu[1][a] * Nv[1][b];
      r[5] = w * Nu[0][a] * Nv[2][b];
      for (int d = 0; d < 6; ++d) W[d] += r[d];
    }
  for (int k = 0; k < n; ++k) {
    double* r = &R[6 * k];
    const double R0 = r[0] / W[0];
    const double Ru = (r[1] - R0 * W[1]) / W[0];
    const double Rv = (r[2] - R0 * W[2]) / W[0];
    const double Ruu = (r[3] - 2.0 * Ru * W[1] - R0 * W[3]) / W[0];
    const double Ruv = (r[4] - Ru * W[2] - Rv * W[1] - R0 * W[4]) / W[0];
    const double Rvv = (r[5] - 2.0 * Rv * W[2] - R0 * W[5]) / W[0];
    r[0] = R0, r[1] = Ru, r[2] = Rv, r[3] = Ruu, r[4] = Ruv, r[5] = Rvv;
  }
}

// ---- Machine peak: independent scalar multiply–adds ----
//
// 12 independent chains a_k ← a_k·m + c keep the multiply and add units busy: latency ×
// throughput ≈ 4 cycles × 2 per cycle needs ≥ 8 chains for a fused FMA, (3 + 3) × 2 = 12 for a
// separate multiply and add. 12 accumulators + m + c fit into the 16 xmm registers (more would
// spill and put store-to-load forwarding into the chains). The empty asm statements pin each
// accumulator to its own register as a scalar, so the compiler cannot pack them into SIMD
// vectors: this is the *scalar* peak.
inline void pin(double& x) {
  asm volatile("" : "+x"(x));
}

double muladd_loop(long n) {
  double a0 = 1, a1 = 1.1, a2 = 1.2, a3 = 1.3, a4 = 1.4, a5 = 1.5, a6 = 1.6, a7 = 1.7;
  double a8 = 1.8, a9 = 1.9, a10 = 2.0, a11 = 2.1;
  double m = 0.999999999, c = 1e-9;
  pin(m);
  pin(c);
  for (long i = 0; i < n; ++i) {
    a0 = a0 * m + c, a1 = a1 * m + c, a2 = a2 * m + c, a3 = a3 * m + c;
    a4 = a4 * m + c, a5 = a5 * m + c, a6 = a6 * m + c, a7 = a7 * m + c;
    a8 = a8 * m + c, a9 = a9 * m + c, a10 = a10 * m + c, a11 = a11 * m + c;
    pin(a0), pin(a1), pin(a2), pin(a3), pin(a4), pin(a5);
    pin(a6), pin(a7), pin(a8), pin(a9), pin(a10), pin(a11);
  }
  return a0 + a1 + a2 + a3 + a4 + a5 + a6 + a7 + a8 + a9 + a10 + a11;
}

// The same with the fused instruction (vfmadd…sd), where the processor has FMA; the build flags
// (-march=x86-64-v2) do not include it, so it is enabled for this function only.
__attribute__((target("fma"))) double fma_loop(long n) {
  double a0 = 1, a1 = 1.1, a2 = 1.2, a3 = 1.3, a4 = 1.4, a5 = 1.5, a6 = 1.6, a7 = 1.7;
  double a8 = 1.8, a9 = 1.9, a10 = 2.0, a11 = 2.1;
  double m = 0.999999999, c = 1e-9;
  pin(m);
  pin(c);
  for (long i = 0; i < n; ++i) {
    a0 = __builtin_fma(a0, m, c), a1 = __builtin_fma(a1, m, c), a2 = __builtin_fma(a2, m, c);
    a3 = __builtin_fma(a3, m, c), a4 = __builtin_fma(a4, m, c), a5 = __builtin_fma(a5, m, c);
    a6 = __builtin_fma(a6, m, c), a7 = __builtin_fma(a7, m, c), a8 = __builtin_fma(a8, m, c);
    a9 = __builtin_fma(a9, m, c), a10 = __builtin_fma(a10, m, c), a11 = __builtin_fma(a11, m, c);
    pin(a0), pin(a1), pin(a2), pin(a3), pin(a4), pin(a5);
    pin(a6), pin(a7), pin(a8), pin(a9), pin(a10), pin(a11);
  }
  return a0 + a1 + a2 + a3 + a4 + a5 + a6 + a7 + a8 + a9 + a10 + a11;
}

// For reference only (vs_packed in the summary): the same 12 chains on SSE2 pairs (mulpd +
// addpd, what the build flags allow), both lanes useful — twice the scalar work per instruction.
using V2 [[gnu::vector_size(16)]] = double;
inline void pin(V2& x) {
  asm volatile("" : "+x"(x));
}
double packed_loop(long n) {
  V2 a0 = {1, 1.01}, a1 = {1.1, 1.11}, a2 = {1.2, 1.21}, a3 = {1.3, 1.31}, a4 = {1.4, 1.41};
  V2 a5 = {1.5, 1.51}, a6 = {1.6, 1.61}, a7 = {1.7, 1.71}, a8 = {1.8, 1.81}, a9 = {1.9, 1.91};
  V2 a10 = {2.0, 2.01}, a11 = {2.1, 2.11};
  V2 m = {0.999999999, 0.999999999}, c = {1e-9, 1e-9};
  pin(m);
  pin(c);
  for (long i = 0; i < n; ++i) {
    a0 = a0 * m + c, a1 = a1 * m + c, a2 = a2 * m + c, a3 = a3 * m + c;
    a4 = a4 * m + c, a5 = a5 * m + c, a6 = a6 * m + c, a7 = a7 * m + c;
    a8 = a8 * m + c, a9 = a9 * m + c, a10 = a10 * m + c, a11 = a11 * m + c;
    pin(a0), pin(a1), pin(a2), pin(a3), pin(a4), pin(a5);
    pin(a6), pin(a7), pin(a8), pin(a9), pin(a10), pin(a11);
  }
  const V2 sum = a0 + a1 + a2 + a3 + a4 + a5 + a6 + a7 + a8 + a9 + a10 + a11;
  return sum[0] + sum[1];
}

constexpr double kFlopsPerLoopIteration = 24.0;  // 12 × (multiply + add)

// Best of 5 timed runs of ≈ 0.1 s each, in flop/s.
double measure_peak(double (*loop)(long), double flops_per_iteration = kFlopsPerLoopIteration) {
  const long n = 25'000'000;
  double best = 0.0;
  for (int rep = 0; rep < 5; ++rep) {
    const auto t0 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(loop(n));
    const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    best = std::max(best, flops_per_iteration * n / dt);
  }
  return best;
}

void set_counters(benchmark::State& state, int p) {
  state.SetItemsProcessed(state.iterations() * kPoints);
  state.counters["flop/pt"] = flops_per_point(p, p);
}

void bm_kernel(benchmark::State& state, int p) {
  const NurbsSurface s = bench_surface(p);
  const auto pts = bench_points();
  double sink = 0.0;
  for (auto _ : state) {
    for (const auto& [xi, eta] : pts) {
      const auto b = isoflex::geometry::surface_basis(s, xi, eta);
      sink += b.R(0, 0) + b.R(5, b.R.cols() - 1);
    }
    benchmark::DoNotOptimize(sink);
  }
  set_counters(state, p);
}

void bm_naive(benchmark::State& state, int p) {
  const NurbsSurface s = bench_surface(p);
  const auto pts = bench_points();
  std::vector<double> R;
  double sink = 0.0;
  for (auto _ : state) {
    for (const auto& [xi, eta] : pts) {
      naive_surface_basis(s, xi, eta, R);
      sink += R[0] + R.back();
    }
    benchmark::DoNotOptimize(sink);
  }
  set_counters(state, p);
}

// ---- The element loop: the (p+1) × (p+1) Gauss points of every element of the surface ----

// The Gauss points of all elements, element by element, in element_quadrature's order.
std::vector<std::pair<double, double>> gauss_grid_points(const NurbsSurface& s) {
  const auto rule = isoflex::geometry::gauss_legendre(gauss_points(s.degree_u()));
  std::vector<std::pair<double, double>> pts;
  for (const auto& e : isoflex::geometry::surface_elements(s))
    for (const auto& qp : isoflex::geometry::element_quadrature(e, rule, rule))
      pts.emplace_back(qp.xi, qp.eta);
  return pts;
}

// element_basis on every element: all functions with first and second derivatives at all Gauss
// points of the element, into one ElementBasis reused from element to element.
void bm_element(benchmark::State& state, int p) {
  const NurbsSurface s = bench_surface(p);
  const auto elements = isoflex::geometry::surface_elements(s);
  const auto rule = isoflex::geometry::gauss_legendre(gauss_points(p));
  isoflex::geometry::ElementBasis E;
  double sink = 0.0;
  for (auto _ : state) {
    for (const SurfaceElement& e : elements) {
      isoflex::geometry::element_basis(s, e, rule, rule, E);
      sink += E.values.front() + E.values.back();
    }
    benchmark::DoNotOptimize(sink);
  }
  const int n = gauss_points(p);
  state.SetItemsProcessed(state.iterations() * static_cast<long>(elements.size()) * n * n);
  state.counters["flop/pt"] = flops_per_point_element(p);
}

// The same points one at a time, with surface_basis or the naive reference.
template <bool naive>
void bm_at_gauss_points(benchmark::State& state, int p) {
  const NurbsSurface s = bench_surface(p);
  const auto pts = gauss_grid_points(s);
  std::vector<double> R;
  double sink = 0.0;
  for (auto _ : state) {
    for (const auto& [xi, eta] : pts) {
      if constexpr (naive) {
        naive_surface_basis(s, xi, eta, R);
        sink += R[0] + R.back();
      } else {
        const auto b = isoflex::geometry::surface_basis(s, xi, eta);
        sink += b.R(0, 0) + b.R(5, b.R.cols() - 1);
      }
    }
    benchmark::DoNotOptimize(sink);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<long>(pts.size()));
  state.counters["flop/pt"] = naive ? 0.0 : flops_per_point(p, p);
}

// Check once that the naive reference and the kernels agree, so the comparison is fair: the
// point kernel at the random points, and element_basis at the Gauss points against both the
// naive reference and surface_basis.
bool naive_matches_kernel() {
  const auto close = [](double x, double ref) {
    return std::abs(x - ref) <= 1e-8 * (1.0 + std::abs(ref));
  };
  for (int p = 2; p <= 5; ++p) {
    const NurbsSurface s = bench_surface(p);
    std::vector<double> R;
    for (const auto& [xi, eta] : bench_points()) {
      naive_surface_basis(s, xi, eta, R);
      const auto b = isoflex::geometry::surface_basis(s, xi, eta);
      for (int k = 0; k < b.R.cols(); ++k)
        for (int d = 0; d < 6; ++d)
          if (!close(b.R(d, k), R[6 * k + d])) return false;
    }
    const auto rule = isoflex::geometry::gauss_legendre(gauss_points(p));
    isoflex::geometry::ElementBasis E;
    for (const SurfaceElement& e : isoflex::geometry::surface_elements(s)) {
      isoflex::geometry::element_basis(s, e, rule, rule, E);
      for (int g = 0; g < E.n_points(); ++g) {
        const double xi = E.xi[g % E.n_u], eta = E.eta[g / E.n_u];
        naive_surface_basis(s, xi, eta, R);
        const auto b = isoflex::geometry::surface_basis(s, xi, eta);
        const auto Rg = E.R(g);
        for (int k = 0; k < E.n_functions; ++k)
          for (int d = 0; d < 6; ++d)
            if (!close(Rg(d, k), R[6 * k + d]) ||
                std::abs(Rg(d, k) - b.R(d, k)) > 1e-13 * (1.0 + std::abs(b.R(d, k))))
              return false;
      }
    }
  }
  return true;
}

// The scalar peak: the larger of the separate and the fused multiply–add loop.
double measure_scalar_peak(double* muladd, double* fma) {
  *muladd = measure_peak(muladd_loop);
  *fma = __builtin_cpu_supports("fma") ? measure_peak(fma_loop) : 0.0;
  return std::max(*muladd, *fma);
}

// Points per benchmark iteration, by benchmark name.
std::map<std::string, double> points_per_iteration;

// Console output plus, at the end, the summary tables: per p and benchmark the fastest and the
// median of the repetitions (seconds per point), the flop count, the achieved flop rate,
// vs_peak = t / (flop/pt ÷ peak) and the naive/kernel ratio (of the medians). The peak is
// measured again after the runs and the larger value used: on a shared machine a slice of lost
// time lowers a measured peak as it lowers a measured kernel rate, and the best of both is the
// closest to the machine.
class Reporter : public benchmark::ConsoleReporter {
 public:
  explicit Reporter(double peak, double packed, OutputOptions options)
      : ConsoleReporter(options), peak_(peak), packed_(packed) {}
  // Prints only the aggregates (mean, median, stddev, cv over the repetitions) and keeps the
  // time of every repetition.
  void ReportRuns(const std::vector<Run>& runs) override {
    std::vector<Run> aggregates;
    for (const auto& r : runs)
      if (r.run_type == Run::RT_Aggregate) aggregates.push_back(r);
    if (!aggregates.empty()) ConsoleReporter::ReportRuns(aggregates);
    for (const auto& r : runs) {
      if (r.run_type != Run::RT_Iteration || r.iterations == 0) continue;
      const std::string name = r.run_name.function_name;
      times_[name].push_back(r.real_accumulated_time / static_cast<double>(r.iterations) /
                             points_per_iteration.at(name));
    }
  }
  void Finalize() override {
    ConsoleReporter::Finalize();
    double muladd, fma;
    const double again = measure_scalar_peak(&muladd, &fma);
    packed_ = std::max(packed_, measure_peak(packed_loop, 2 * kFlopsPerLoopIteration));
    std::printf(
        "\nscalar peak after the runs: mul+add %.2f GFlop/s, fused FMA %.2f GFlop/s"
        " (SSE2 mulpd+addpd: %.2f GFlop/s)\n",
        muladd * 1e-9, fma * 1e-9, packed_ * 1e-9);
    peak_ = std::max(peak_, again);
    std::printf(
        "\nsummary (%d repetitions each: fastest / median; scalar peak %.2f GFlop/s, SSE2 pairs"
        " %.2f)\n",
        kRepetitions, peak_ * 1e-9, packed_ * 1e-9);
    std::printf(
        "\nelement_basis: all (p+1)^2 Gauss points of an element at once, %d x %d elements\n"
        "  p   ns/pt fast/median   pts/s(med)  flop/pt  GFlop/s(med)  vs_peak fast/median"
        "  vs_sse2(med)  point_api_ns  naive_ns  naive/kernel\n",
        kSpans, kSpans);
    for (int p = 2; p <= 5; ++p) {
      const std::string P = "/p=" + std::to_string(p);
      const Stats k = stats("element_basis" + P), pt = stats("surface_basis_gauss" + P),
                  n = stats("naive_cox_de_boor_gauss" + P);
      if (k.median == 0.0) continue;
      const double f = flops_per_point_element(p);
      std::printf(
          "  %d  %7.1f / %7.1f  %11.3e  %7.1f  %12.2f  %8.2f / %6.2f  %12.2f  %12.1f  %8.1f  %12.1f"
          "\n",
          p, k.fastest * 1e9, k.median * 1e9, 1.0 / k.median, f, f / k.median * 1e-9,
          k.fastest / (f / peak_), k.median / (f / peak_), k.median / (f / packed_),
          pt.median * 1e9, n.median * 1e9, n.median / k.median);
    }
    std::printf(
        "\nsurface_basis: one point at a time, %d random points\n"
        "  p   ns/pt fast/median   pts/s(med)  flop/pt  GFlop/s(med)  vs_peak fast/median"
        "  naive_ns  naive/kernel\n",
        kPoints);
    for (int p = 2; p <= 5; ++p) {
      const std::string P = "/p=" + std::to_string(p);
      const Stats k = stats("surface_basis" + P), n = stats("naive_cox_de_boor" + P);
      if (k.median == 0.0) continue;
      const double f = flops_per_point(p, p);
      std::printf("  %d  %7.1f / %7.1f  %11.3e  %7.0f  %12.2f  %8.2f / %6.2f  %8.1f  %12.1f\n", p,
                  k.fastest * 1e9, k.median * 1e9, 1.0 / k.median, f, f / k.median * 1e-9,
                  k.fastest / (f / peak_), k.median / (f / peak_), n.median * 1e9,
                  n.median / k.median);
    }
  }

 private:
  struct Stats {
    double fastest = 0.0, median = 0.0;  // seconds per point; 0 if the benchmark did not run
  };
  Stats stats(const std::string& name) const {
    const auto it = times_.find(name);
    if (it == times_.end() || it->second.empty()) return {};
    std::vector<double> t = it->second;
    std::sort(t.begin(), t.end());
    const std::size_t m = t.size() / 2;
    return {t.front(), t.size() % 2 == 1 ? t[m] : 0.5 * (t[m - 1] + t[m])};
  }
  double peak_, packed_;
  std::map<std::string, std::vector<double>> times_;  // seconds per point, per repetition
};

template <class F>
void add(const std::string& name, F f, int p, double points) {
  points_per_iteration[name] = points;
  benchmark::RegisterBenchmark(name.c_str(), f, p)
      ->Unit(benchmark::kMicrosecond)
      ->MinTime(kMinTime)
      ->Repetitions(kRepetitions);
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  if (!naive_matches_kernel()) {
    std::fprintf(stderr, "naive reference, surface_basis and element_basis disagree\n");
    return 1;
  }
  double peak_muladd, peak_fma;
  const double peak = measure_scalar_peak(&peak_muladd, &peak_fma);
  const double packed = measure_peak(packed_loop, 2 * kFlopsPerLoopIteration);
  std::printf(
      "scalar peak: mul+add %.2f GFlop/s, fused FMA %s%.2f GFlop/s; vs_peak uses the larger"
      " (and the larger of this and the peak measured after the runs); SSE2 mulpd+addpd"
      " %.2f GFlop/s\n",
      peak_muladd * 1e-9, __builtin_cpu_supports("fma") ? "" : "(no FMA) ", peak_fma * 1e-9,
      packed * 1e-9);
  std::fflush(stdout);  // before Google Benchmark's own output
  for (int p = 2; p <= 5; ++p) {
    const std::string P = "/p=" + std::to_string(p);
    const double gauss = kSpans * kSpans * gauss_points(p) * gauss_points(p);
    add("element_basis" + P, bm_element, p, gauss);
    add("surface_basis_gauss" + P, bm_at_gauss_points<false>, p, gauss);
    add("naive_cox_de_boor_gauss" + P, bm_at_gauss_points<true>, p, gauss);
    add("surface_basis" + P, bm_kernel, p, kPoints);
    add("naive_cox_de_boor" + P, bm_naive, p, kPoints);
  }
  // Colour only on a terminal (a custom display reporter does not see --benchmark_color).
  Reporter reporter(peak, packed,
                    isatty(fileno(stdout)) ? benchmark::ConsoleReporter::OO_ColorTabular
                                           : benchmark::ConsoleReporter::OO_Tabular);
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
