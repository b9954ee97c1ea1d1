#include "isoflex/geometry/nurbs_surface.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace isoflex::geometry {

namespace {
void check_sizes(const NurbsSurface& s) {
  const int nb = s.n_u() * s.n_v();
  if (static_cast<int>(s.points.size()) != nb)
    throw std::invalid_argument("NURBS surface: " + std::to_string(s.points.size()) +
                                " control points but the knot vectors define " +
                                std::to_string(s.n_u()) + " x " + std::to_string(s.n_v()) + " = " +
                                std::to_string(nb));
  if (static_cast<int>(s.weights.size()) != nb)
    throw std::invalid_argument("NURBS surface: " + std::to_string(s.weights.size()) +
                                " weights but " + std::to_string(nb) + " control points");
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

// Bivariate rational basis (4.12) and its derivatives by the quotient rule on
// A_k = w_k N_a(ξ) N_b(η), W = Σ_k A_k (k = a + (p+1)·b):
//   R     = A/W
//   R_ξ   = (A_ξ − R W_ξ)/W,                      R_η likewise,
//   R_ξξ  = (A_ξξ − 2 R_ξ W_ξ − R W_ξξ)/W,         R_ηη likewise,
//   R_ξη  = (A_ξη − R_ξ W_η − R_η W_ξ − R W_ξη)/W.
SurfaceBasis surface_basis(const NurbsSurface& s, double xi, double eta) {
  check_sizes(s);
  const int p = s.degree_u(), q = s.degree_v();
  const Basis1D Nu = bspline_basis(s.u, xi, 2);
  const Basis1D Nv = bspline_basis(s.v, eta, 2);
  SurfaceBasis out;
  out.span_u = Nu.span;
  out.span_v = Nv.span;
  const int nk = (p + 1) * (q + 1);
  out.R.resize(6, nk);
  Eigen::Matrix<double, 6, 1> W = Eigen::Matrix<double, 6, 1>::Zero();
  for (int b = 0; b <= q; ++b) {
    for (int a = 0; a <= p; ++a) {
      const int k = a + (p + 1) * b;
      const double w = s.weights[s.index(Nu.span - p + a, Nv.span - q + b)];
      out.R(0, k) = w * Nu.ders(0, a) * Nv.ders(0, b);
      out.R(1, k) = w * Nu.ders(1, a) * Nv.ders(0, b);
      out.R(2, k) = w * Nu.ders(0, a) * Nv.ders(1, b);
      out.R(3, k) = w * Nu.ders(2, a) * Nv.ders(0, b);
      out.R(4, k) = w * Nu.ders(1, a) * Nv.ders(1, b);
      out.R(5, k) = w * Nu.ders(0, a) * Nv.ders(2, b);
      W += out.R.col(k);
    }
  }
  for (int k = 0; k < nk; ++k) {
    const double R = out.R(0, k) / W(0);
    const double Ru = (out.R(1, k) - R * W(1)) / W(0);
    const double Rv = (out.R(2, k) - R * W(2)) / W(0);
    const double Ruu = (out.R(3, k) - 2.0 * Ru * W(1) - R * W(3)) / W(0);
    const double Ruv = (out.R(4, k) - Ru * W(2) - Rv * W(1) - R * W(4)) / W(0);
    const double Rvv = (out.R(5, k) - 2.0 * Rv * W(2) - R * W(5)) / W(0);
    out.R.col(k) << R, Ru, Rv, Ruu, Ruv, Rvv;
  }
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
