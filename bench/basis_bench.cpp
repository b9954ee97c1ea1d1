// Basis-evaluation benchmark (see bench/basis.md): throughput of
// geometry::surface_basis — all (p+1)(q+1) non-zero rational basis functions R with their first
// and second derivatives at one point, IGA-thesis (4.3), (4.12) — for p = q = 2 … 5, against a
// naive recursive Cox–de Boor evaluation written here, and against the machine's scalar
// floating-point peak measured by a loop of independent multiply–adds.
//
//   basis_bench [Google Benchmark flags, e.g. --benchmark_filter=p=3]
//
// Google Benchmark prints points/s (items_per_second) and flop/pt (the count of the algorithm,
// derived in flops_per_point below) per run; a summary table at the end gives, per p, the fastest
// repetition as points/s, ns/pt, flop/pt, achieved GFlop/s, vs_peak = time per point /
// (flop/pt ÷ peak) — how many times longer than the flop count takes at the measured scalar
// peak — and the naive/kernel time ratio.
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

#include "isoflex/geometry/nurbs_surface.hpp"

namespace {

using isoflex::Vec3;
using isoflex::geometry::KnotVector;
using isoflex::geometry::NurbsSurface;

constexpr int kSpans = 8;      // spans per direction of the benchmark surface
constexpr int kPoints = 4096;  // evaluation points per benchmark iteration

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
// geometry/nurbs_surface.cpp (+, −, ×, ÷ one flop each; integer index arithmetic and
// comparisons not counted), for p ≥ 2, two derivatives:
//   1D, Piegl–Tiller A2.2 triangle:  2p (left, right) + 5 · p(p+1)/2 (add, div, mul, add, mul)
//   1D, derivatives (A2.3): k = 1: 5p; k = 2: 9(p − 1); scaling by p!/(p−k)!: 2(p + 1) + 2
//     → f₁(p) = 2.5 p² + 20.5 p − 5
//   tensor product, per local function (n = (p+1)(q+1)): 6 products w·N·M (12 ×) and the sums
//     W, W_ξ, … (6 +) = 18; quotient rule R, R_ξ, R_η, R_ξξ, R_ξη, R_ηη = 1 + 3 + 3 + 6 + 7 + 6
//     = 26 → 44 n
//   total f(p, q) = f₁(p) + f₁(q) + 44 (p+1)(q+1).
double flops_1d(int p) {
  return 2.5 * p * p + 20.5 * p - 5.0;
}
double flops_per_point(int p, int q) {
  return flops_1d(p) + flops_1d(q) + 44.0 * (p + 1) * (q + 1);
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

constexpr double kFlopsPerLoopIteration = 24.0;  // 12 × (multiply + add)

// Best of 5 timed runs of ≈ 0.1 s each, in flop/s.
double measure_peak(double (*loop)(long)) {
  const long n = 25'000'000;
  double best = 0.0;
  for (int rep = 0; rep < 5; ++rep) {
    const auto t0 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(loop(n));
    const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    best = std::max(best, kFlopsPerLoopIteration * n / dt);
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

// Check once that the naive reference and the kernel agree, so the comparison is fair.
bool naive_matches_kernel() {
  for (int p = 2; p <= 5; ++p) {
    const NurbsSurface s = bench_surface(p);
    std::vector<double> R;
    for (const auto& [xi, eta] : bench_points()) {
      naive_surface_basis(s, xi, eta, R);
      const auto b = isoflex::geometry::surface_basis(s, xi, eta);
      for (int k = 0; k < b.R.cols(); ++k)
        for (int d = 0; d < 6; ++d)
          if (std::abs(b.R(d, k) - R[6 * k + d]) > 1e-8 * (1.0 + std::abs(R[6 * k + d])))
            return false;
    }
  }
  return true;
}

// Console output plus, at the end, the summary table: per p the fastest repetition of the
// kernel and of the naive reference (seconds per point), the flop count, the achieved flop rate,
// vs_peak = t_kernel / (flop/pt ÷ peak) and naive/kernel.
class Reporter : public benchmark::ConsoleReporter {
 public:
  explicit Reporter(double peak, OutputOptions options) : ConsoleReporter(options), peak_(peak) {}
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const auto& r : runs) {
      if (r.run_type != Run::RT_Iteration || r.iterations == 0) continue;
      const double t = r.real_accumulated_time / static_cast<double>(r.iterations) / kPoints;
      auto [it, fresh] = best_.try_emplace(r.run_name.function_name, t);
      if (!fresh) it->second = std::min(it->second, t);
    }
  }
  void Finalize() override {
    ConsoleReporter::Finalize();
    std::printf(
        "\nsummary (fastest repetition; peak %.2f GFlop/s)\n"
        "  p  kernel_pts/s  kernel_ns/pt  flop/pt  GFlop/s  vs_peak  naive_ns/pt  naive/kernel\n",
        peak_ * 1e-9);
    for (int p = 2; p <= 5; ++p) {
      const auto k = best_.find("surface_basis/p=" + std::to_string(p));
      const auto n = best_.find("naive_cox_de_boor/p=" + std::to_string(p));
      if (k == best_.end()) continue;
      const double f = flops_per_point(p, p), t = k->second;
      std::printf("  %d  %12.3e  %12.1f  %7.0f  %7.2f  %7.2f", p, 1.0 / t, t * 1e9, f, f / t * 1e-9,
                  t / (f / peak_));
      if (n != best_.end()) std::printf("  %11.1f  %12.1f", n->second * 1e9, n->second / t);
      std::printf("\n");
    }
  }

 private:
  double peak_;
  std::map<std::string, double> best_;  // seconds per point
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  if (!naive_matches_kernel()) {
    std::fprintf(stderr, "naive reference and surface_basis disagree\n");
    return 1;
  }
  const double peak_muladd = measure_peak(muladd_loop);
  const bool has_fma = __builtin_cpu_supports("fma");
  const double peak_fma = has_fma ? measure_peak(fma_loop) : 0.0;
  const double peak = std::max(peak_muladd, peak_fma);
  std::printf("scalar peak: mul+add %.2f GFlop/s, fused FMA %s%.2f GFlop/s; vs_peak uses %.2f\n",
              peak_muladd * 1e-9, has_fma ? "" : "(no FMA) ", peak_fma * 1e-9, peak * 1e-9);
  for (int p = 2; p <= 5; ++p) {
    // Three repetitions each (the machine is shared); the summary takes the fastest.
    benchmark::RegisterBenchmark(("surface_basis/p=" + std::to_string(p)).c_str(), bm_kernel, p)
        ->Unit(benchmark::kMicrosecond)
        ->Repetitions(3);
    benchmark::RegisterBenchmark(("naive_cox_de_boor/p=" + std::to_string(p)).c_str(), bm_naive, p)
        ->Unit(benchmark::kMicrosecond)
        ->Repetitions(3);
  }
  // Colour only on a terminal (a custom display reporter does not see --benchmark_color).
  Reporter reporter(peak, isatty(fileno(stdout)) ? benchmark::ConsoleReporter::OO_ColorTabular
                                                 : benchmark::ConsoleReporter::OO_Tabular);
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
