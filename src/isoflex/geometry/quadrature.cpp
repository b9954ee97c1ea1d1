#include "isoflex/geometry/quadrature.hpp"

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

namespace isoflex::geometry {

namespace {

// P_n(x) and P_n'(x) by the three-term recurrence (j+1) P_{j+1} = (2j+1) x P_j − j P_{j−1};
// the derivative from (x² − 1) P_n' = n (x P_n − P_{n−1}), valid for |x| < 1 (all nodes are).
void legendre(int n, double x, double& p, double& dp) {
  double p0 = 1.0, p1 = x;
  for (int j = 1; j < n; ++j) {
    const double p2 = ((2 * j + 1) * x * p1 - j * p0) / (j + 1);
    p0 = p1;
    p1 = p2;
  }
  p = p1;
  dp = n * (x * p1 - p0) / (x * x - 1.0);
}

}  // namespace

GaussRule gauss_legendre(int n) {
  if (n < 1) throw std::invalid_argument("gauss_legendre: n = " + std::to_string(n) + " < 1");
  GaussRule r;
  r.nodes.assign(n, 0.0);
  r.weights.assign(n, 0.0);
  constexpr double eps = std::numeric_limits<double>::epsilon();
  // The rule is symmetric: compute the ⌈n/2⌉ non-negative nodes (largest first) and mirror them,
  // so x_k = −x_{n−1−k} and w_k = w_{n−1−k} hold exactly.
  for (int k = 0; k < (n + 1) / 2; ++k) {
    // Start close to the k-th largest root (Tricomi's asymptotic first term); Newton then
    // converges quadratically from the right side, never jumping to a neighbouring root.
    double x = std::cos(std::numbers::pi * (k + 0.75) / (n + 0.5));
    double p = 0.0, dp = 0.0;
    if (2 * k + 1 == n) {
      x = 0.0;  // the middle node of an odd rule
    } else {
      for (int it = 0; it < 100; ++it) {
        legendre(n, x, p, dp);
        const double dx = p / dp;
        x -= dx;
        if (std::abs(dx) <= 2.0 * eps * std::abs(x)) break;
      }
    }
    legendre(n, x, p, dp);
    const double w = 2.0 / ((1.0 - x * x) * dp * dp);
    r.nodes[n - 1 - k] = x;
    r.nodes[k] = -x;
    r.weights[n - 1 - k] = w;
    r.weights[k] = w;
  }
  return r;
}

std::vector<SpanElement> span_elements(const KnotVector& kv) {
  std::vector<SpanElement> out;
  const auto& t = kv.knots();
  for (const int s : kv.element_spans()) out.push_back({s, t[s], t[s + 1]});
  return out;
}

std::vector<SurfaceElement> surface_elements(const NurbsSurface& s) {
  const auto eu = span_elements(s.u), ev = span_elements(s.v);
  std::vector<SurfaceElement> out;
  out.reserve(eu.size() * ev.size());
  for (const auto& b : ev)
    for (const auto& a : eu) out.push_back({a.span, b.span, a.a, a.b, b.a, b.b});
  return out;
}

std::vector<QuadraturePoint> span_quadrature(const SpanElement& e, const GaussRule& rule) {
  // Affine parent map ξ(ζ) = (a + b)/2 + (b − a)/2 ζ, dξ/dζ = (b − a)/2.
  const double mid = 0.5 * (e.a + e.b), half = 0.5 * (e.b - e.a);
  std::vector<QuadraturePoint> out(rule.size());
  for (int i = 0; i < rule.size(); ++i)
    out[i] = {mid + half * rule.nodes[i], 0.0, half * rule.weights[i]};
  return out;
}

std::vector<QuadraturePoint> element_quadrature(const SurfaceElement& e, const GaussRule& rule_u,
                                                const GaussRule& rule_v) {
  const double mu = 0.5 * (e.u0 + e.u1), hu = 0.5 * (e.u1 - e.u0);
  const double mv = 0.5 * (e.v0 + e.v1), hv = 0.5 * (e.v1 - e.v0);
  std::vector<QuadraturePoint> out;
  out.reserve(static_cast<std::size_t>(rule_u.size()) * rule_v.size());
  for (int j = 0; j < rule_v.size(); ++j)
    for (int i = 0; i < rule_u.size(); ++i)
      out.push_back({mu + hu * rule_u.nodes[i], mv + hv * rule_v.nodes[j],
                     hu * hv * rule_u.weights[i] * rule_v.weights[j]});
  return out;
}

std::vector<std::vector<QuadraturePoint>> surface_quadrature(const NurbsSurface& s,
                                                             QuadratureOrder order) {
  const GaussRule ru = gauss_legendre(order.n_u > 0 ? order.n_u : s.u.degree() + 1);
  const GaussRule rv = gauss_legendre(order.n_v > 0 ? order.n_v : s.v.degree() + 1);
  std::vector<std::vector<QuadraturePoint>> out;
  for (const auto& e : surface_elements(s)) out.push_back(element_quadrature(e, ru, rv));
  return out;
}

}  // namespace isoflex::geometry
