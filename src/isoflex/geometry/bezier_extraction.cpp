#include "isoflex/geometry/bezier_extraction.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace isoflex::geometry {

namespace {

// Boehm's single knot insertion of u into the knot vector T of a B-spline function whose control
// coefficients are the columns of P (any dimension). `k` is the last index with T[k] ≤ u and
// `m` the multiplicity of u in T. New coefficients (one more column):
//   Q_j = P_j                              j ≤ k − p
//   Q_j = α_j P_j + (1 − α_j) P_{j−1}      k − p + 1 ≤ j ≤ k − m,  α_j = (u − T_j)/(T_{j+p} − T_j)
//   Q_j = P_{j−1}                          j ≥ k − m + 1
// (for k − m < j ≤ k the general formula has α_j = 0, so it is the last case).
void insert_knot(int p, std::vector<double>& T, MatX& P, double u) {
  const int k = static_cast<int>(std::upper_bound(T.begin(), T.end(), u) - T.begin()) - 1;
  const int m = static_cast<int>(std::count(T.begin(), T.end(), u));
  const int n = static_cast<int>(P.cols());
  MatX Q(P.rows(), n + 1);
  for (int j = 0; j <= k - p; ++j) Q.col(j) = P.col(j);
  // The caller's window guarantees k − p + 1 ≥ 1 and T_{j+p} > u for the blended j.
  for (int j = k - p + 1; j <= k - m; ++j) {
    const double alpha = (u - T[j]) / (T[j + p] - T[j]);
    Q.col(j) = alpha * P.col(j) + (1.0 - alpha) * P.col(j - 1);
  }
  for (int j = k - m + 1; j <= n; ++j) Q.col(j) = P.col(j - 1);
  T.insert(T.begin() + k + 1, u);
  P = std::move(Q);
}

// Extraction operator of span s = [T_s, T_{s+1}) of a degree-p knot vector: on the local window
// T_{s−p} … T_{s+p+1}, which carries exactly the p + 1 functions N_{s−p} … N_s, the identity
// coefficients are refined until both span ends have multiplicity p; then the p + 1 functions
// non-zero on the span are the Bernstein polynomials of the span, and their coefficients are
// the columns of C_e (row i = N_{s−p+i}).
MatX span_operator(const std::vector<double>& knots, int p, int s) {
  std::vector<double> T(knots.begin() + (s - p), knots.begin() + (s + p + 2));
  MatX P = MatX::Identity(p + 1, p + 1);
  const double a = knots[s], b = knots[s + 1];
  while (std::count(T.begin(), T.end(), a) < p) insert_knot(p, T, P, a);
  while (std::count(T.begin(), T.end(), b) < p) insert_knot(p, T, P, b);
  const int last_a = static_cast<int>(std::upper_bound(T.begin(), T.end(), a) - T.begin()) - 1;
  return P.middleCols(last_a - p, p + 1);
}

// (w_i P_i, w_i) of the element's functions mapped through C_e: the homogeneous Bézier points.
void homogeneous(const NurbsSurface& s, const BezierElement& e, std::vector<Vec3>& points,
                 std::vector<double>& weights) {
  const int n = static_cast<int>(e.global.size());
  points.assign(n, Vec3::Zero());
  weights.assign(n, 0.0);
  for (int k = 0; k < n; ++k) {
    Vec3 wp = Vec3::Zero();
    double w = 0.0;
    for (int i = 0; i < n; ++i) {
      const double c = e.C(i, k);
      if (c == 0.0) continue;
      const int g = e.global[i];
      wp += c * s.weights[g] * s.points[g];
      w += c * s.weights[g];
    }
    weights[k] = w;
    points[k] = wp / w;
  }
}

}  // namespace

BernsteinTable bernstein(int p, double t) {
  if (p < 0 || p > kMaxDegree)
    throw std::invalid_argument("bernstein: degree " + std::to_string(p) + " out of range");
  // Triangle B_{k,j} = (1 − t) B_{k,j−1} + t B_{k−1,j−1}; keep the rows of degree p − 2, p − 1
  // and p for the derivatives
  //   B'_{k,p}  = p (B_{k−1,p−1} − B_{k,p−1}),
  //   B''_{k,p} = p (p − 1) (B_{k−2,p−2} − 2 B_{k−1,p−2} + B_{k,p−2}).
  Eigen::Matrix<double, kMaxDegree + 1, 1> b, b1, b2;  // degree j, j − 1, j − 2
  b.setZero();
  b1.setZero();
  b2.setZero();
  b(0) = 1.0;
  const double s = 1.0 - t;
  for (int j = 1; j <= p; ++j) {
    b2 = b1;
    b1 = b;
    b(j) = t * b1(j - 1);
    for (int k = j - 1; k >= 1; --k) b(k) = s * b1(k) + t * b1(k - 1);
    b(0) = s * b1(0);
  }
  BernsteinTable out(3, p + 1);
  for (int k = 0; k <= p; ++k) {
    out(0, k) = b(k);
    if (p >= 1)
      out(1, k) = p * ((k >= 1 ? b1(k - 1) : 0.0) - (k <= p - 1 ? b1(k) : 0.0));
    else
      out(1, k) = 0.0;
    if (p >= 2) {
      const double a0 = (k >= 2) ? b2(k - 2) : 0.0;
      const double a1 = (k >= 1 && k - 1 <= p - 2) ? b2(k - 1) : 0.0;
      const double a2 = (k <= p - 2) ? b2(k) : 0.0;
      out(2, k) = p * (p - 1) * (a0 - 2.0 * a1 + a2);
    } else {
      out(2, k) = 0.0;
    }
  }
  return out;
}

CurveExtraction extract_curve(const KnotVector& kv) {
  CurveExtraction x;
  x.degree = kv.degree();
  x.elements = span_elements(kv);
  x.operators.reserve(x.elements.size());
  for (const auto& e : x.elements)
    x.operators.push_back(span_operator(kv.knots(), kv.degree(), e.span));
  return x;
}

SurfaceExtraction extract_surface(const NurbsSurface& s) {
  const CurveExtraction xu = extract_curve(s.u), xv = extract_curve(s.v);
  SurfaceExtraction x;
  x.p = xu.degree;
  x.q = xv.degree;
  x.n_elements_u = static_cast<int>(xu.elements.size());
  x.n_elements_v = static_cast<int>(xv.elements.size());
  const int nu = x.p + 1, nv = x.q + 1, n = nu * nv;
  x.elements.reserve(static_cast<std::size_t>(x.n_elements_u) * x.n_elements_v);
  for (int ev = 0; ev < x.n_elements_v; ++ev) {
    for (int eu = 0; eu < x.n_elements_u; ++eu) {
      const SpanElement& a = xu.elements[eu];
      const SpanElement& b = xv.elements[ev];
      BezierElement be;
      be.element = {a.span, b.span, a.a, a.b, b.a, b.b};
      be.global.resize(n);
      for (int j = 0; j < nv; ++j)
        for (int i = 0; i < nu; ++i)
          be.global[i + nu * j] = s.index(a.span - x.p + i, b.span - x.q + j);
      // Kronecker product C_v ⊗ C_u: row i + nu·j, column k + nu·l = C_u(i,k) C_v(j,l).
      const MatX& Cu = xu.operators[eu];
      const MatX& Cv = xv.operators[ev];
      be.C.resize(n, n);
      for (int j = 0; j < nv; ++j)
        for (int l = 0; l < nv; ++l) be.C.block(nu * j, nu * l, nu, nu) = Cv(j, l) * Cu;
      x.elements.push_back(std::move(be));
    }
  }
  return x;
}

std::vector<RationalBezierCell> bezier_cells(const NurbsSurface& s) {
  return bezier_cells(s, extract_surface(s));
}

std::vector<RationalBezierCell> bezier_cells(const NurbsSurface& s, const SurfaceExtraction& x) {
  std::vector<RationalBezierCell> cells;
  cells.reserve(x.elements.size());
  for (const auto& e : x.elements) {
    RationalBezierCell c;
    c.element = e.element;
    c.p = x.p;
    c.q = x.q;
    homogeneous(s, e, c.points, c.weights);
    cells.push_back(std::move(c));
  }
  return cells;
}

std::vector<double> extract_field(const NurbsSurface& s, const BezierElement& e,
                                  const std::vector<double>& values, int n_components) {
  const int n = static_cast<int>(e.global.size());
  if (n_components < 1 || values.size() != static_cast<std::size_t>(n_components) * s.points.size())
    throw std::invalid_argument("extract_field: expected " + std::to_string(s.points.size()) +
                                " × " + std::to_string(n_components) + " values, got " +
                                std::to_string(values.size()));
  std::vector<double> out(static_cast<std::size_t>(n) * n_components, 0.0);
  for (int k = 0; k < n; ++k) {
    double W = 0.0;
    for (int i = 0; i < n; ++i) {
      const double cw = e.C(i, k) * s.weights[e.global[i]];
      if (cw == 0.0) continue;
      W += cw;
      for (int c = 0; c < n_components; ++c)
        out[k * n_components + c] += cw * values[e.global[i] * n_components + c];
    }
    for (int c = 0; c < n_components; ++c) out[k * n_components + c] /= W;
  }
  return out;
}

Vec3 evaluate(const RationalBezierCell& c, double tu, double tv) {
  const BernsteinTable bu = bernstein(c.p, tu), bv = bernstein(c.q, tv);
  Vec3 num = Vec3::Zero();
  double den = 0.0;
  for (int l = 0; l <= c.q; ++l) {
    for (int k = 0; k <= c.p; ++k) {
      const int idx = k + (c.p + 1) * l;
      const double bw = bu(0, k) * bv(0, l) * c.weights[idx];
      num += bw * c.points[idx];
      den += bw;
    }
  }
  return num / den;
}

}  // namespace isoflex::geometry
