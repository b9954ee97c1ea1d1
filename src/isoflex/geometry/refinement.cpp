#include "isoflex/geometry/refinement.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>

#include "isoflex/geometry/homogeneous_lines.hpp"
#include "isoflex/math/exact_text.hpp"

namespace isoflex::geometry {

namespace {

using detail::apply_lines;
using detail::from_hom;
using detail::Hom;
using detail::HomCurve;
using detail::insert_once;
using detail::to_hom;

// Knots to insert must be finite, strictly inside the domain, and may not raise a multiplicity
// above p (the spline would become discontinuous; for p = 0 multiplicity 1 is the normal case).
void check_new_knots(const KnotVector& kv, const std::vector<double>& sorted, const char* what) {
  const int max_mult = std::max(kv.degree(), 1);
  for (std::size_t k = 0; k < sorted.size(); ++k) {
    const double x = sorted[k];
    if (!std::isfinite(x) || !(x > kv.front() && x < kv.back()))
      throw std::invalid_argument(std::string(what) + ": knot " + exact_text(x) +
                                  " is not strictly inside the domain (" + exact_text(kv.front()) +
                                  ", " + exact_text(kv.back()) + ")");
    if (k > 0 && sorted[k - 1] == x) continue;
    const auto count =
        static_cast<int>(std::upper_bound(sorted.begin(), sorted.end(), x) - sorted.begin()) -
        static_cast<int>(k);
    const int mult = kv.multiplicity(x) + count;
    if (mult > max_mult)
      throw std::invalid_argument(std::string(what) + ": knot " + exact_text(x) +
                                  " would get multiplicity " + std::to_string(mult) + " > degree " +
                                  std::to_string(kv.degree()) +
                                  " (the spline would become discontinuous)");
  }
}

// Knot refinement (The NURBS Book A5.4): inserts the sorted knots X in one sweep from the right.
// Control points left of span a−p and right of span b stay; in between each new knot X_j is
// inserted into the partially built new knot vector Ū with Boehm's factors
// α = (Ū_{k+l} − X_j)/(Ū_{k+l} − U_{i−p+l}), working from the highest new knot down.
HomCurve refine(const HomCurve& c, const std::vector<double>& X) {
  if (X.empty()) return c;
  const int p = c.kv.degree();
  const std::vector<double>& U = c.kv.knots();
  const int n = c.kv.n_basis() - 1;  // last control-point index
  const int m = n + p + 1;           // last knot index
  const int r = static_cast<int>(X.size()) - 1;
  const int a = c.kv.find_span(X.front());
  const int b = c.kv.find_span(X.back()) + 1;
  std::vector<Hom> Q(n + r + 2);
  std::vector<double> Ub(m + r + 2);
  for (int j = 0; j <= a - p; ++j) Q[j] = c.pw[j];
  for (int j = b - 1; j <= n; ++j) Q[j + r + 1] = c.pw[j];
  for (int j = 0; j <= a; ++j) Ub[j] = U[j];
  for (int j = b + p; j <= m; ++j) Ub[j + r + 1] = U[j];
  int i = b + p - 1, k = b + p + r;
  for (int j = r; j >= 0; --j) {
    while (X[j] <= U[i] && i > a) {
      Q[k - p - 1] = c.pw[i - p - 1];
      Ub[k] = U[i];
      --k;
      --i;
    }
    Q[k - p - 1] = Q[k - p];
    for (int l = 1; l <= p; ++l) {
      const int ind = k - p + l;
      double alpha = Ub[k + l] - X[j];
      if (alpha == 0.0) {
        Q[ind - 1] = Q[ind];
      } else {
        alpha /= Ub[k + l] - U[i - p + l];
        Q[ind - 1] = alpha * Q[ind - 1] + (1.0 - alpha) * Q[ind];
      }
    }
    Ub[k] = X[j];
    --k;
  }
  return {KnotVector(p, std::move(Ub)), std::move(Q)};
}

// Degree elevation by t (The NURBS Book A5.9, Prautzsch's idea of §4.1.4 [Pra84] done
// segment-wise): sweep the knot vector; for each span (1) insert its right knot until the span
// is a Bézier segment, (2) elevate the Bézier segment,
//     Q_i = Σ_j C(p, j) C(t, i − j) / C(p + t, i) · P_j,   max(0, i−t) ≤ j ≤ min(p, i),
// (3) remove the knot inserted at the segment's left end again (oldr − 1 times), so that every
// original knot ends with multiplicity (its old multiplicity + t).
HomCurve elevate(const HomCurve& c, int t) {
  const int p = c.kv.degree();
  const std::vector<double>& U = c.kv.knots();
  const int n = c.kv.n_basis() - 1;
  const int m = n + p + 1;
  const int ph = p + t, ph2 = ph / 2;

  // Binomial coefficients up to ph (≤ kMaxDegree).
  std::array<std::array<double, kMaxDegree + 1>, kMaxDegree + 1> bin{};
  for (int i = 0; i <= ph; ++i) {
    bin[i][0] = bin[i][i] = 1.0;
    for (int j = 1; j < i; ++j) bin[i][j] = bin[i - 1][j - 1] + bin[i - 1][j];
  }
  // Bézier elevation coefficients bezalfs[i][j], symmetric: bezalfs[ph−i][p−j] = bezalfs[i][j].
  std::array<std::array<double, kMaxDegree + 1>, kMaxDegree + 1> bezalfs{};
  bezalfs[0][0] = bezalfs[ph][p] = 1.0;
  for (int i = 1; i <= ph2; ++i) {
    const double inv = 1.0 / bin[ph][i];
    for (int j = std::max(0, i - t); j <= std::min(p, i); ++j)
      bezalfs[i][j] = inv * bin[p][j] * bin[t][i - j];
  }
  for (int i = ph2 + 1; i <= ph - 1; ++i)
    for (int j = std::max(0, i - t); j <= std::min(p, i); ++j)
      bezalfs[i][j] = bezalfs[ph - i][p - j];

  // Sizes of the result: every distinct knot gains t copies.
  const int n_distinct = static_cast<int>(c.kv.breakpoints().size());
  const int n_new = n + 1 + t * (n_distinct - 1);
  const int n_knots_new = m + 1 + t * n_distinct;
  std::vector<Hom> Q(n_new);
  std::vector<double> Uh(n_knots_new);
  std::array<Hom, kMaxDegree + 1> bpts, ebpts, next_bpts;
  std::array<double, kMaxDegree + 1> alfs{};

  int mh = ph, kind = ph + 1;
  int r = -1, a = p, b = p + 1, cind = 1;
  double ua = U[0];
  Q[0] = c.pw[0];
  for (int i = 0; i <= ph; ++i) Uh[i] = ua;
  for (int i = 0; i <= p; ++i) bpts[i] = c.pw[i];
  while (b < m) {
    const int i0 = b;
    while (b < m && U[b] == U[b + 1]) ++b;
    const int mul = b - i0 + 1;
    mh += mul + t;
    const double ub = U[b];
    const int oldr = r;
    r = p - mul;
    const int lbz = oldr > 0 ? (oldr + 2) / 2 : 1;
    const int rbz = r > 0 ? ph - (r + 1) / 2 : ph;
    if (r > 0) {
      // (1) Insert ub r times: the current segment becomes Bézier; the points pushed out to the
      // right start the next segment.
      const double numer = ub - ua;
      for (int k = p; k > mul; --k) alfs[k - mul - 1] = numer / (U[a + k] - ua);
      for (int j = 1; j <= r; ++j) {
        const int save = r - j, s = mul + j;
        for (int k = p; k >= s; --k)
          bpts[k] = alfs[k - s] * bpts[k] + (1.0 - alfs[k - s]) * bpts[k - 1];
        next_bpts[save] = bpts[p];
      }
    }
    // (2) Elevate the Bézier segment (only points lbz..ph are needed below).
    for (int i = lbz; i <= ph; ++i) {
      ebpts[i].setZero();
      for (int j = std::max(0, i - t); j <= std::min(p, i); ++j)
        ebpts[i] += bezalfs[i][j] * bpts[j];
    }
    // (3) Remove the knot ua oldr − 1 times (it was inserted oldr times for the previous segment).
    if (oldr > 1) {
      int first = kind - 2, last = kind;
      const double den = ub - ua;
      const double bet = (ub - Uh[kind - 1]) / den;
      for (int tr = 1; tr < oldr; ++tr) {
        int i = first, j = last, kj = j - kind + 1;
        while (j - i > tr) {
          if (i < cind) {
            const double alf = (ub - Uh[i]) / (ua - Uh[i]);
            Q[i] = alf * Q[i] + (1.0 - alf) * Q[i - 1];
          }
          if (j >= lbz) {
            if (j - tr <= kind - ph + oldr) {
              const double gam = (ub - Uh[j - tr]) / den;
              ebpts[kj] = gam * ebpts[kj] + (1.0 - gam) * ebpts[kj + 1];
            } else {
              ebpts[kj] = bet * ebpts[kj] + (1.0 - bet) * ebpts[kj + 1];
            }
          }
          ++i;
          --j;
          --kj;
        }
        --first;
        ++last;
      }
    }
    if (a != p)  // load the knot ua with its new multiplicity
      for (int i = 0; i < ph - oldr; ++i) Uh[kind++] = ua;
    for (int j = lbz; j <= rbz; ++j) Q[cind++] = ebpts[j];
    if (b < m) {  // set up the next segment
      for (int j = 0; j < r; ++j) bpts[j] = next_bpts[j];
      for (int j = r; j <= p; ++j) bpts[j] = c.pw[b - p + j];
      a = b;
      ++b;
      ua = ub;
    } else {
      for (int i = 0; i <= ph; ++i) Uh[kind + i] = ub;  // end knot
    }
  }
  // Internal consistency of the sweep with the size formula above.
  if (mh - ph != n_new || mh + 1 != n_knots_new || cind != n_new)
    throw std::logic_error("elevate_degree: internal size mismatch");
  return {KnotVector(ph, std::move(Uh)), std::move(Q)};
}

void check_elevation(const KnotVector& kv, int t, const char* what) {
  if (t < 0)
    throw std::invalid_argument(std::string(what) + ": elevation t = " + std::to_string(t) +
                                " is negative");
  if (kv.degree() + t > kMaxDegree)
    throw std::invalid_argument(std::string(what) + ": degree " + std::to_string(kv.degree()) +
                                " + " + std::to_string(t) +
                                " exceeds kMaxDegree = " + std::to_string(kMaxDegree));
  if (!kv.is_open())
    throw std::invalid_argument(std::string(what) +
                                ": needs an open knot vector (IGA-thesis (4.4))");
  const std::vector<double> bp = kv.breakpoints();
  for (std::size_t k = 1; k + 1 < bp.size(); ++k)
    if (kv.multiplicity(bp[k]) > kv.degree())
      throw std::invalid_argument(std::string(what) + ": interior knot " + exact_text(bp[k]) +
                                  " has multiplicity " + std::to_string(kv.multiplicity(bp[k])) +
                                  " > degree " + std::to_string(kv.degree()));
}

const KnotVector& knots_of(const NurbsSurface& s, Direction d) {
  return d == Direction::u ? s.u : s.v;
}

void check_r(int r, const char* what) {
  if (r < 1)
    throw std::invalid_argument(std::string(what) + ": r = " + std::to_string(r) +
                                " insertions, need r >= 1");
}

void check_n_per_span(int n, const char* what) {
  if (n < 0)
    throw std::invalid_argument(std::string(what) + ": " + std::to_string(n) +
                                " new knots per span is negative");
}

}  // namespace

// --- Curves -------------------------------------------------------------------------------------

NurbsCurve insert_knot(const NurbsCurve& c, double knot, int r) {
  c.validate();
  check_r(r, "insert_knot");
  check_new_knots(c.knots, std::vector<double>(r, knot), "insert_knot");
  HomCurve h = to_hom(c);
  for (int k = 0; k < r; ++k) h = insert_once(h, knot);
  return from_hom(std::move(h));
}

NurbsCurve refine_knots(const NurbsCurve& c, const std::vector<double>& new_knots) {
  c.validate();
  std::vector<double> X = new_knots;
  std::sort(X.begin(), X.end());
  check_new_knots(c.knots, X, "refine_knots");
  return from_hom(refine(to_hom(c), X));
}

NurbsCurve elevate_degree(const NurbsCurve& c, int t) {
  c.validate();
  check_elevation(c.knots, t, "elevate_degree");
  if (t == 0) return c;
  return from_hom(elevate(to_hom(c), t));
}

std::vector<double> uniform_new_knots(const KnotVector& kv, int n_per_span) {
  check_n_per_span(n_per_span, "uniform_new_knots");
  std::vector<double> X;
  for (int s : kv.element_spans()) {
    const double a = kv.knots()[s], b = kv.knots()[s + 1];
    for (int k = 1; k <= n_per_span; ++k) X.push_back(a + (b - a) * k / (n_per_span + 1));
  }
  return X;
}

NurbsCurve refine_uniform(const NurbsCurve& c, int n_per_span) {
  return refine_knots(c, uniform_new_knots(c.knots, n_per_span));
}

NurbsCurve k_refine(const NurbsCurve& c, int t, int n_per_span) {
  check_n_per_span(n_per_span, "k_refine");
  // §4.2.2: elevation first, so the knots inserted afterwards have continuity C^{p+t−1}.
  return refine_uniform(elevate_degree(c, t), n_per_span);
}

// --- Surfaces -----------------------------------------------------------------------------------

NurbsSurface insert_knot(const NurbsSurface& s, Direction d, double knot, int r) {
  s.validate();
  check_r(r, "insert_knot");
  check_new_knots(knots_of(s, d), std::vector<double>(r, knot), "insert_knot");
  return apply_lines(s, d, [&](const HomCurve& h) {
    HomCurve g = h;
    for (int k = 0; k < r; ++k) g = insert_once(g, knot);
    return g;
  });
}

NurbsSurface refine_knots(const NurbsSurface& s, Direction d,
                          const std::vector<double>& new_knots) {
  s.validate();
  std::vector<double> X = new_knots;
  std::sort(X.begin(), X.end());
  check_new_knots(knots_of(s, d), X, "refine_knots");
  if (X.empty()) return s;
  return apply_lines(s, d, [&](const HomCurve& h) { return refine(h, X); });
}

NurbsSurface elevate_degree(const NurbsSurface& s, Direction d, int t) {
  s.validate();
  check_elevation(knots_of(s, d), t, "elevate_degree");
  if (t == 0) return s;
  return apply_lines(s, d, [&](const HomCurve& h) { return elevate(h, t); });
}

NurbsSurface refine_uniform(const NurbsSurface& s, int n_per_span_u, int n_per_span_v) {
  const NurbsSurface su = refine_knots(s, Direction::u, uniform_new_knots(s.u, n_per_span_u));
  return refine_knots(su, Direction::v, uniform_new_knots(su.v, n_per_span_v));
}

NurbsSurface k_refine(const NurbsSurface& s, int t_u, int t_v, int n_per_span_u, int n_per_span_v) {
  check_n_per_span(n_per_span_u, "k_refine");
  check_n_per_span(n_per_span_v, "k_refine");
  // §4.2.2: elevate first, then insert.
  const NurbsSurface e = elevate_degree(elevate_degree(s, Direction::u, t_u), Direction::v, t_v);
  return refine_uniform(e, n_per_span_u, n_per_span_v);
}

}  // namespace isoflex::geometry
