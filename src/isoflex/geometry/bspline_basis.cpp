#include "isoflex/geometry/bspline_basis.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

namespace isoflex::geometry {

namespace {
constexpr int kCap = kMaxDegree + 1;
}  // namespace

// All p+1 non-zero B-splines N_{s−p..s} on span s and their derivatives, by the Cox–de Boor
// recursion IGA-thesis (4.3) organised as one triangular table (Piegl & Tiller, The NURBS Book,
// A2.2/A2.3): ndu[r][j], r ≤ j, holds N_{s−j+r, j} (degree j in column j); the knot
// differences right + left sit below the diagonal, ndu[j][r] for j > r, because the derivative
// recursion divides by them again. The 0/0 := 0 convention of (4.3) never arises: on a non-empty
// span every denominator right(r+1) + left(j−r) = ξ_{s+r+1} − ξ_{s−j+r+1} > 0 — the span itself
// lies inside it.
Basis1D bspline_basis(const KnotVector& kv, double u, int n_derivatives) {
  if (n_derivatives < 0 || n_derivatives > 2)
    throw std::invalid_argument("bspline_basis: n_derivatives = " + std::to_string(n_derivatives) +
                                " outside [0, 2]");
  if (std::isnan(u)) throw std::invalid_argument("bspline_basis: parameter is NaN");
  const int p = kv.degree();
  const std::vector<double>& U = kv.knots();
  // Clamp like find_span does, so that the polynomial piece is never extrapolated.
  u = std::clamp(u, kv.front(), kv.back());

  Basis1D out;
  out.span = kv.find_span(u);
  const int s = out.span;
  out.ders.setZero(n_derivatives + 1, p + 1);

  std::array<std::array<double, kCap>, kCap> ndu{};
  std::array<double, kCap> left{}, right{};
  ndu[0][0] = 1.0;  // (4.3a): N_{s,0} = 1 on the span
  for (int j = 1; j <= p; ++j) {
    left[j] = u - U[s + 1 - j];
    right[j] = U[s + j] - u;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      // (4.3b) for the pair N_{s−j+r, j} (gets the right-hand term of the left neighbour)
      // and N_{s−j+r+1, j} (gets the left-hand term of its own).
      ndu[j][r] = right[r + 1] + left[j - r];  // knot difference, kept for the derivatives
      const double temp = ndu[r][j - 1] / ndu[j][r];
      ndu[r][j] = saved + right[r + 1] * temp;
      saved = left[j - r] * temp;
    }
    ndu[j][j] = saved;
  }
  for (int j = 0; j <= p; ++j) out.ders(0, j) = ndu[j][p];

  // Derivatives: d^k N_{i,p} = p!/(p−k)! Σ_l a_{k,l} N_{i+l, p−k} with the a-coefficients built
  // by differencing (the derivative of (4.3b), The NURBS Book ch. 2); two alternating rows.
  const int nd = std::min(n_derivatives, p);  // derivatives above p vanish (set to zero above)
  std::array<std::array<double, kCap>, 2> a{};
  for (int r = 0; r <= p; ++r) {
    int s1 = 0, s2 = 1;
    a[0][0] = 1.0;
    for (int k = 1; k <= nd; ++k) {
      double d = 0.0;
      const int rk = r - k, pk = p - k;
      if (r >= k) {
        a[s2][0] = a[s1][0] / ndu[pk + 1][rk];
        d = a[s2][0] * ndu[rk][pk];
      }
      const int j1 = (rk >= -1) ? 1 : -rk;
      const int j2 = (r - 1 <= pk) ? k - 1 : p - r;
      for (int j = j1; j <= j2; ++j) {
        a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][rk + j];
        d += a[s2][j] * ndu[rk + j][pk];
      }
      if (r <= pk) {
        a[s2][k] = -a[s1][k - 1] / ndu[pk + 1][r];
        d += a[s2][k] * ndu[r][pk];
      }
      out.ders(k, r) = d;
      std::swap(s1, s2);
    }
  }
  // Multiply by p!/(p−k)!.
  double factor = p;
  for (int k = 1; k <= nd; ++k) {
    out.ders.row(k) *= factor;
    factor *= (p - k);
  }
  return out;
}

}  // namespace isoflex::geometry
