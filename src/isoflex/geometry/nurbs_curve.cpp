#include "isoflex/geometry/nurbs_curve.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace isoflex::geometry {

namespace {
void check_sizes(const NurbsCurve& c) {
  const int nb = c.knots.n_basis();
  if (c.n() != nb)
    throw std::invalid_argument("NURBS curve: " + std::to_string(c.n()) +
                                " control points but the knot vector defines " +
                                std::to_string(nb) + " basis functions");
  if (static_cast<int>(c.weights.size()) != nb)
    throw std::invalid_argument("NURBS curve: " + std::to_string(c.weights.size()) +
                                " weights but " + std::to_string(nb) + " control points");
}
}  // namespace

bool NurbsCurve::is_rational() const {
  for (double w : weights)
    if (w != weights.front()) return true;
  return false;
}

void NurbsCurve::validate() const {
  check_sizes(*this);
  for (int i = 0; i < n(); ++i) {
    // Written so that NaN fails: (4.9) needs w_i ∈ R⁺.
    if (!(weights[i] > 0.0) || !std::isfinite(weights[i]))
      throw std::invalid_argument("NURBS curve: weight " + std::to_string(i) + " = " +
                                  std::to_string(weights[i]) + " is not positive and finite");
    if (!points[i].allFinite())
      throw std::invalid_argument("NURBS curve: control point " + std::to_string(i) +
                                  " is not finite");
  }
}

// Rational basis (4.9) and its derivatives by the quotient rule, with A_a = w_a N_a and
// W = Σ_a A_a (the homogeneous weight):
//   R = A/W,  R' = (A' − R W')/W,  R'' = (A'' − 2 R' W' − R W'')/W,
// i.e. with ω' = W'/W, ω'' = W''/W (substitute R into R', then R and R' into R''):
//   R = w N/W,  R' = w (N' − ω' N)/W,  R'' = w (N'' − 2 ω' N' + (2 ω'² − ω'') N)/W,
// one division per point (as in surface_basis, nurbs_surface.cpp).
CurveBasis curve_basis(const NurbsCurve& c, double xi) {
  check_sizes(c);
  if (std::isnan(xi)) throw std::invalid_argument("curve_basis: parameter is NaN");
  xi = std::clamp(xi, c.knots.front(), c.knots.back());  // no extrapolation, as bspline_basis
  const int p = c.degree();
  CurveBasis out;
  out.span = c.knots.find_span(xi);
  BasisArray N;
  bspline_basis_unchecked(c.knots, out.span, xi, N);
  const double* w = c.weights.data() + (out.span - p);
  double W = 0.0, W1 = 0.0, W2 = 0.0;
  for (int a = 0; a <= p; ++a) {
    W += w[a] * N[0][a];
    W1 += w[a] * N[1][a];
    W2 += w[a] * N[2][a];
  }
  const double iW = 1.0 / W, o1 = W1 * iW, o2 = W2 * iW;
  const double k1 = 2.0 * o1, k0 = k1 * o1 - o2;
  out.R.resize(3, p + 1);
  double* R = out.R.data();  // row major: row k starts at k·(p+1)
  for (int a = 0; a <= p; ++a) {
    const double r = w[a] * iW;
    R[a] = r * N[0][a];
    R[p + 1 + a] = r * (N[1][a] - o1 * N[0][a]);
    R[2 * (p + 1) + a] = r * (N[2][a] - k1 * N[1][a] + k0 * N[0][a]);
  }
  return out;
}

// The curve (4.10) in homogeneous form: with A(ξ) = Σ N_i w_i P_i and W(ξ) = Σ N_i w_i the
// point is C = A/W, and differentiating A = W C twice gives
//   C' = (A' − W' C)/W,  C'' = (A'' − 2 W' C' − W'' C)/W   (The NURBS Book ch. 4).
CurvePoint evaluate(const NurbsCurve& c, double xi) {
  check_sizes(c);
  const int p = c.degree();
  const Basis1D N = bspline_basis(c.knots, xi, 2);
  Vec3 A = Vec3::Zero(), A1 = Vec3::Zero(), A2 = Vec3::Zero();
  double W = 0.0, W1 = 0.0, W2 = 0.0;
  for (int a = 0; a <= p; ++a) {
    const int i = N.span - p + a;
    const double w = c.weights[i];
    W += w * N.ders(0, a);
    W1 += w * N.ders(1, a);
    W2 += w * N.ders(2, a);
    A += (w * N.ders(0, a)) * c.points[i];
    A1 += (w * N.ders(1, a)) * c.points[i];
    A2 += (w * N.ders(2, a)) * c.points[i];
  }
  CurvePoint out;
  out.x = A / W;
  out.x1 = (A1 - W1 * out.x) / W;
  out.x2 = (A2 - 2.0 * W1 * out.x1 - W2 * out.x) / W;
  return out;
}

}  // namespace isoflex::geometry
