// KLShellPatch::stress: stress recovery at one parametric point (IGA-thesis §3.4, (3.41)–(3.50);
// conventions and the deviations from the thesis: docs/theory/kl-shell.md §7).
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "isoflex/elements/kl_shell_patch_impl.hpp"
#include "isoflex/math/exact_text.hpp"

namespace isoflex::elements {

namespace {

// Principal values σ_I ≥ σ_II of the plane stress (11, 22, 12) (IGA-thesis (3.48)).
Eigen::Vector2d principal(const Vec3& s) {
  const double mid = 0.5 * (s(0) + s(1));
  const double rad = std::hypot(0.5 * (s(0) - s(1)), s(2));
  return {mid + rad, mid - rad};
}

// IGA-thesis (3.50).
double von_mises(const Eigen::Vector2d& p) {
  return std::sqrt(p(0) * p(0) + p(1) * p(1) - p(0) * p(1));
}

// Contravariant components (11, 22, 12) in the basis a_α ⊗ a_β → components in the orthonormal
// e_k ⊗ e_l (IGA-thesis (3.45)–(3.46)): σ̂_kl = σ^{αβ} (e_k·a_α)(a_β·e_l), T(k, α) = e_k·a_α.
Vec3 to_frame(const Eigen::Matrix2d& T, const Vec3& s) {
  Eigen::Matrix2d S;
  S << s(0), s(2), s(2), s(1);
  const Eigen::Matrix2d H = T * S * T.transpose();
  return {H(0, 0), H(1, 1), H(0, 1)};
}

}  // namespace

KLShellStress KLShellPatch::stress(const VecX& x, double xi, double eta, KLKinematics kin) const {
  const Impl& m = *impl_;
  // The size only: a writer recovers the stress at many points, and a check of all of x at each
  // would make its cost quadratic; the control points used are checked below.
  if (x.size() != 3 * static_cast<Eigen::Index>(m.ref.points.size()))
    throw std::invalid_argument("KLShellPatch: stress: x has " + std::to_string(x.size()) +
                                " entries, expected " + std::to_string(3 * m.ref.points.size()) +
                                " (3 per control point)");
  const auto& s = m.ref;
  if (!(xi >= s.u.front() && xi <= s.u.back() && eta >= s.v.front() && eta <= s.v.back()))
    throw std::invalid_argument("KLShellPatch: stress: (xi, eta) = (" + exact_text(xi) + ", " +
                                exact_text(eta) + ") outside the parameter domain");
  const geometry::SurfaceBasis sb = geometry::surface_basis(s, xi, eta);
  const int n = static_cast<int>(sb.R.cols());
  const kl::BasisView R{sb.R.data(), n, 1, 6};
  kl::LocalPoints xl(3, n), Xl(3, n);
  for (int k = 0; k < n; ++k) {
    const int A = sb.global_index(s, k);
    xl.col(k) = x.segment<3>(3 * A);
    Xl.col(k) = s.points[A];
  }
  if (!xl.allFinite()) throw std::invalid_argument("KLShellPatch: stress: x is not finite");
  const kl::ReferencePoint ref = kl::reference_point(R, Xl, 0.0, m.sec.young, m.sec.poisson);
  if (!(ref.J0 > 0.0))
    throw std::invalid_argument("KLShellPatch: stress: degenerate reference geometry at (" +
                                exact_text(xi) + ", " + exact_text(eta) + ")");

  KLShellStress out;
  out.point.setZero();
  for (int k = 0; k < n; ++k) out.point += R(0, k) * xl.col(k);  // (4.20)–(4.21)

  Vec3 Em, Ef;
  kl::CurrentPoint cur;
  double area_ratio = 1.0;
  if (kin == KLKinematics::linear) {
    // Linearized strains; the frame is the reference one (small displacements).
    cur = kl::as_current(ref);
    kl::BBlocks B;
    kl::b_matrix(R, cur, kl::normal_factors(cur), B);
    Vec<6> E = Vec<6>::Zero();
    for (int k = 0; k < n; ++k) E.noalias() += B[k] * (xl.col(k) - Xl.col(k));
    Em = E.head<3>();
    Ef = E.tail<3>();
  } else {
    cur = kl::current_point(R, xl);
    if (!(cur.j > 0.0))
      throw std::invalid_argument("KLShellPatch: stress: degenerate current geometry at (" +
                                  exact_text(xi) + ", " + exact_text(eta) + ")");
    kl::strains(ref, cur, Em, Ef);
    area_ratio = ref.J0 / cur.j;  // IGA-thesis (3.44)
  }
  // Resultants (contravariant, per unit reference length): n = t C E^m, m = t³/12 C E^f
  // (IGA-thesis (3.43) for the standard C, kl-shell.md §7), then Cauchy-type (3.44).
  const double t = m.sec.thickness;
  const Vec3 nc = area_ratio * t * (ref.C * Em);
  const Vec3 mc = area_ratio * (t * t * t / 12.0) * (ref.C * Ef);
  // Local frame: e1 = a1/|a1|, e2 = a^2/|a^2|, e3 = a3 (after (3.46)).
  const Vec3 e1 = cur.a1.normalized();
  const Vec3 e2 = cur.a3.cross(cur.a1).normalized();  // a^2 ∥ a₃ × a₁
  out.frame.col(0) = e1;
  out.frame.col(1) = e2;
  out.frame.col(2) = cur.a3;
  Eigen::Matrix2d T;
  T << e1.dot(cur.a1), e1.dot(cur.a2), e2.dot(cur.a1), e2.dot(cur.a2);
  out.n = to_frame(T, nc);
  out.m = to_frame(T, mc);
  // Linear distribution through the thickness: σ(ϑ₃) = n/t + 12 m ϑ₃ / t³ at ϑ₃ = ±t/2
  // (IGA-thesis (3.49) for the total stress tensor, kl-shell.md §7).
  out.sigma_top = out.n / t + 6.0 * out.m / (t * t);
  out.sigma_bottom = out.n / t - 6.0 * out.m / (t * t);
  out.principal_top = principal(out.sigma_top);
  out.principal_bottom = principal(out.sigma_bottom);
  out.von_mises_top = von_mises(out.principal_top);
  out.von_mises_bottom = von_mises(out.principal_bottom);
  return out;
}

}  // namespace isoflex::elements
