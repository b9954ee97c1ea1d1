#include "isoflex/geometry/homogeneous_lines.hpp"

#include <utility>

namespace isoflex::geometry::detail {

Hom to_hom(const Vec3& x, double w) {
  Hom h;
  h << w * x, w;
  return h;
}

HomCurve surface_line(const NurbsSurface& s, Direction d, int line) {
  HomCurve c{d == Direction::u ? s.u : s.v, {}};
  const int n = c.kv.n_basis();
  c.pw.reserve(n);
  for (int k = 0; k < n; ++k) {
    const int idx = d == Direction::u ? s.index(k, line) : s.index(line, k);
    c.pw.push_back(to_hom(s.points[idx], s.weights[idx]));
  }
  return c;
}

HomCurve to_hom(const NurbsCurve& c) {
  HomCurve h{c.knots, {}};
  h.pw.reserve(c.n());
  for (int i = 0; i < c.n(); ++i) h.pw.push_back(to_hom(c.points[i], c.weights[i]));
  return h;
}

NurbsCurve from_hom(HomCurve&& h) {
  NurbsCurve c;
  c.knots = std::move(h.kv);
  c.points.reserve(h.pw.size());
  c.weights.reserve(h.pw.size());
  for (const Hom& q : h.pw) {
    c.points.push_back(q.head<3>() / q(3));
    c.weights.push_back(q(3));
  }
  return c;
}

NurbsSurface apply_lines(const NurbsSurface& s, Direction d,
                         const std::function<HomCurve(const HomCurve&)>& f) {
  const int n_lines = d == Direction::u ? s.n_v() : s.n_u();
  NurbsSurface out;
  out.u = s.u;
  out.v = s.v;
  for (int line = 0; line < n_lines; ++line) {
    HomCurve h = f(surface_line(s, d, line));
    if (line == 0) {
      (d == Direction::u ? out.u : out.v) = h.kv;
      out.points.resize(static_cast<std::size_t>(out.n_u()) * out.n_v());
      out.weights.resize(out.points.size());
    }
    for (int k = 0; k < static_cast<int>(h.pw.size()); ++k) {
      const int idx = d == Direction::u ? out.index(k, line) : out.index(line, k);
      out.points[idx] = h.pw[k].head<3>() / h.pw[k](3);
      out.weights[idx] = h.pw[k](3);
    }
  }
  return out;
}

// For i in (k−p, k] the denominator U_{i+p} − U_i ≥ U_{k+1} − U_k > 0. At an existing knot of
// multiplicity s the last s factors α_i are 0, which reproduces the copy of P_{i−1}.
HomCurve insert_once(const HomCurve& c, double u) {
  const int p = c.kv.degree(), n = c.kv.n_basis();
  const std::vector<double>& U = c.kv.knots();
  const int k = c.kv.find_span(u);
  HomCurve out;
  out.pw.resize(n + 1);
  for (int i = 0; i <= n; ++i) {
    if (i <= k - p) {
      out.pw[i] = c.pw[i];
    } else if (i <= k) {
      const double alpha = (u - U[i]) / (U[i + p] - U[i]);
      out.pw[i] = alpha * c.pw[i] + (1.0 - alpha) * c.pw[i - 1];
    } else {
      out.pw[i] = c.pw[i - 1];
    }
  }
  std::vector<double> knots = U;
  knots.insert(knots.begin() + k + 1, u);
  out.kv = KnotVector(p, std::move(knots));
  return out;
}

}  // namespace isoflex::geometry::detail
