// KLShellPatch::discrete_gradient: a discrete gradient of the internal energy (3.22) in the sense
// of O. Gonzalez, J. Nonlinear Sci. 6 (1996) 449–467 (DV·Δx = ΔΠ, DV consistent to second order
// at the midpoint, rigid-motion invariant), built in strain space per quadrature point as in
// O. Gonzalez, CMAME 190 (2000) 1763–1783, and its tangent ∂DV/∂x_{n+1}. Formulas, the rigid
// projection and the threshold: docs/theory/kl-shell.md §10.
#include <algorithm>
#include <cstddef>
#include <vector>

#include "isoflex/elements/kl_shell_patch_impl.hpp"
#include "isoflex/geometry/element_basis.hpp"
#include "isoflex/math/skew.hpp"

namespace isoflex::elements {

namespace {

using kl::LocalVector;
using Ops = kl::Derivatives;
using kl::gather_derivatives;
using kl::spread;

// The correction is dropped (c = 0) when w·w ≤ kSize² p·p + kMotion² Δx·Δx (p: the midpoint
// control points about their centroid): the increment is rigid to 10⁻⁸ of the element's size, or
// w is at the round-off floor of the projection (~10⁻¹⁵ |Δx|). There c = N / (w·w) would mostly
// be the round-off of N divided by a tiny w·w, while dropping it costs an energy error ∝ |w|
// (kl-shell.md §10: the measured balance).
constexpr double kSize2 = 1e-16, kMotion2 = 1e-24;

// The midpoint-rule defect of the bending strains, N = E^f(x₁) − E^f(x₀) − ∇E^f(x_{n+½})Δx
// = O(|Δx|³), from the midpoint point cm and the increments du = (Δa_ξ, Δa_η, Δa_ξξ, Δa_ξη,
// Δa_ηη), x₀,₁ = x_{n+½} ∓ Δx/2. Differencing E^f(x₁) − E^f(x₀) directly would cancel two O(κ)
// numbers (κ ~ |a_αβ|) to an O(|Δx|³) result with round-off ε κ, which c = N / (w·w) amplifies;
// written with the exact differences below every term carries round-off relative to its own
// size, ε κ min(1, |Δx|/h) (kl-shell.md §10). With E^f_αβ = B_αβ − a_αβ·a₃ (3.12):
//   ΔE^f_αβ = −(Δa_αβ·ā₃ + a_αβ·Δa₃),  ∇E^f_αβ Δx = −(Δa_αβ·a₃ + a_αβ·P Δã₃ / j),
// a_αβ, a₃, P, j at the midpoint, ā₃ = (a₃(x₀) + a₃(x₁))/2, and ã₃ = a₁ × a₂ bilinear:
// ã₃(x₁,₀) = ã₃ ± ½Δã₃ + ¼ Δa₁ × Δa₂ with Δã₃ = Δa₁ × a₂ + a₁ × Δa₂ exactly.
Vec3 bending_defect(const kl::CurrentPoint& cm, const Ops& du) {
  const Vec3 da1 = du.segment<3>(0), da2 = du.segment<3>(3);
  const Vec3 t = cm.a1.cross(cm.a2), dt = da1.cross(cm.a2) + cm.a1.cross(da2),
             tt = 0.25 * da1.cross(da2);
  const Vec3 t1 = t + 0.5 * dt + tt, t0 = t - 0.5 * dt + tt;
  const double j1 = t1.norm(), j0 = t0.norm();
  // Δa₃ = ã₃(x₁)/j₁ − ã₃(x₀)/j₀ = Δã₃/j₁ − ã₃(x₀)(j₁ − j₀)/(j₀j₁), j₁ − j₀ = (ã₃(x₁) +
  // ã₃(x₀))·Δã₃/(j₁ + j₀).
  const double dj = (t1 + t0).dot(dt) / (j1 + j0);
  const Vec3 da3 = dt / j1 - t0 * (dj / (j0 * j1));
  const Vec3 ab3 = 0.5 * (t1 / j1 + t0 / j0);
  const Vec3 lin = (dt - cm.a3.dot(dt) * cm.a3) / cm.j;  // P Δã₃ / j
  const Vec3 ea = ab3 - cm.a3, eb = da3 - lin;           // both O(|Δx|²)
  const Vec3 a[3] = {cm.a11, cm.a22, cm.a12},
             d[3] = {du.segment<3>(6), du.segment<3>(12), du.segment<3>(9)};
  Vec3 N;
  for (int i = 0; i < 3; ++i) N(i) = -(d[i].dot(ea) + a[i].dot(eb));
  N(2) *= 2.0;  // Voigt 2E₁₂
  return N;
}

// Removes from d its Euclidean projection on the rigid modes of the centred points p (Σ p = 0):
// d_a −= v + ω × p_a, v = mean d, ω = J⁻¹ Σ p_a × d_a, J = Σ (|p_a|² I − p_a p_aᵀ); the centring
// decouples translations and rotations, so (RᵀR)⁻¹ is diag(I/n, J⁻¹). Returns ω.
Vec3 remove_rigid(const kl::LocalPoints& p, const Mat3& Jinv, kl::LocalPoints& d) {
  const Vec3 v = d.rowwise().mean();
  Vec3 L = Vec3::Zero();
  for (int a = 0; a < p.cols(); ++a) L += p.col(a).cross(d.col(a));
  const Vec3 om = Jinv * L;
  for (int a = 0; a < p.cols(); ++a) d.col(a) -= v + om.cross(p.col(a));
  return om;
}

// What one thread works in.
struct Work {
  geometry::ElementBasis eb;
  kl::LocalPoints y0, y1, z0, z1, zm, dx, p, w;
  LocalVector re, grow;
  std::vector<kl::PackedTangent> Tg;
  MatX Rho, W, Ke, dW;
};

}  // namespace

VecX KLShellPatch::discrete_gradient(const VecX& xn, const VecX& xn1, KLKinematics kin,
                                     SpMat* K) const {
  if (!K) return discrete_gradient_into(xn, xn1, kin, nullptr);
  impl_->adopt_pattern(*K);
  return discrete_gradient_into(xn, xn1, kin, K->valuePtr());
}

VecX KLShellPatch::discrete_gradient_into(const VecX& xn, const VecX& xn1, KLKinematics kin,
                                          double* values) const {
  const Impl& m = *impl_;
  m.check_size(xn, "discrete_gradient");
  m.check_size(xn1, "discrete_gradient");
  if (kin == KLKinematics::linear) {
    // Π_lin = ½ uᵀ K_lin u is quadratic: Π(x₁) − Π(x₀) = r(x_{n+½})·Δx exactly, ∂/∂x₁ = ½ K_lin.
    VecX r = internal_force_into(0.5 * (xn + xn1), kin, values);
    if (values) std::for_each(values, values + m.pattern.nonZeros(), [](double& v) { v *= 0.5; });
    return r;
  }
  const double t = m.membrane_thickness(), tb = m.bending_thickness();
  const int nf = m.n_fun;
  VecX r = VecX::Zero(xn.size());
  if (values) std::fill_n(values, m.pattern.nonZeros(), 0.0);
  const int workers = m.workers(threads_);
  std::vector<Work> work(static_cast<std::size_t>(workers));
  for (Work& w : work) {
    w.re.resize(3 * nf);
    if (!values) continue;
    w.grow.resize(3 * nf);
    w.Tg.resize(static_cast<std::size_t>(m.n_qp));
    w.Rho.resize(kl::kDerivatives * m.n_qp, nf);
    w.Ke.resize(9 * nf, nf);
    w.dW.resize(3 * nf, 3 * nf);
  }
  m.loop.run(workers, [&](int e, int worker) {
    Work& wk = work[static_cast<std::size_t>(worker)];
    geometry::element_basis(m.ref, m.elems[e], m.rule_u, m.rule_v, wk.eb);
    m.gather(xn, e, wk.y0);
    m.gather(xn1, e, wk.y1);
    // Element-local coordinates about one of its control points: the strains are invariant, and
    // the subtraction rounds relative to the element's size, so a_α, a_αβ and p carry round-off
    // of the element's size instead of |x| (this sets the noise floor of N and w below).
    const Vec3 o = wk.y0.col(0);
    wk.z0 = wk.y0.colwise() - o;
    wk.z1 = wk.y1.colwise() - o;
    wk.dx = wk.y1 - wk.y0;
    wk.zm = 0.5 * (wk.z0 + wk.z1);
    // w = the increment without its projection on the rigid modes at the midpoint (translations,
    // rotations ω × x_{n+½}); projected twice ("twice is enough"), so that Σ w_a and
    // Σ p_a × w_a vanish to round-off of |w|, not of |Δx|, and c w conserves momenta even when
    // c = N / (w·w) is large.
    wk.p = wk.zm.colwise() - wk.zm.rowwise().mean();
    Mat3 J = Mat3::Zero();
    for (int a = 0; a < nf; ++a)
      J += wk.p.col(a).squaredNorm() * Mat3::Identity() - wk.p.col(a) * wk.p.col(a).transpose();
    const Mat3 Jinv = J.inverse();
    wk.w = wk.dx;
    Vec3 om = remove_rigid(wk.p, Jinv, wk.w);
    om += remove_rigid(wk.p, Jinv, wk.w);
    const double d = wk.w.squaredNorm();
    const bool correct = d > kSize2 * wk.p.squaredNorm() + kMotion2 * wk.dx.squaredNorm();
    double Gamma = 0.0;  // Σ_g dA Σ_i c_i m̄_i: the correction is Γ w
    wk.re.setZero();
    if (values) wk.grow.setZero();
    for (int g = 0; g < m.n_qp; ++g) {
      const kl::BasisView R = Impl::view(wk.eb, g);
      const kl::ReferencePoint& ref = m.points[static_cast<std::size_t>(e) * m.n_qp + g];
      const kl::CurrentPoint c0 = kl::current_point(R, wk.z0), c1 = kl::current_point(R, wk.z1),
                             cm = kl::current_point(R, wk.zm);
      Vec3 Em0, Ef0, Em1, Ef1;
      kl::strains(ref, c0, Em0, Ef0);
      kl::strains(ref, c1, Em1, Ef1);
      // The averaged resultants n̄ = t C Ē^m, m̄ = t³/12 C Ē^f: with ΔE = ∇E(x_{n+½})Δx (exact for
      // the quadratic E^m, made exact for E^f by the correction) n̄·ΔE^m + m̄·ΔE^f = ΔΠ density.
      const kl::Resultants sb{(0.5 * t) * (ref.C * (Em0 + Em1)),
                              (0.5 * tb) * (ref.C * (Ef0 + Ef1))};
      const kl::NormalFactors nfm = kl::normal_factors(cm);
      kl::StrainOperator Em;
      kl::strain_operator(cm, nfm, Em);
      Vec<6> S;
      S << sb.n, sb.m;
      spread(R, Em.transpose() * (ref.dA * S), wk.re);
      // Gonzalez's correction of each bending strain: c_i = N_i / (w·w) with the midpoint-rule
      // defect N = ΔE^f − ∇E^f(x_{n+½})Δx = O(|Δx|³), so D E^f_i = ∇E^f_i + c_i w satisfies
      // D E^f_i·Δx = ΔE^f_i (w·Δx = w·w) and is orthogonal to the rigid modes.
      Ops du = Ops::Zero();
      Vec3 c = Vec3::Zero();
      if (correct) {
        du = gather_derivatives(R, wk.dx);
        c = bending_defect(cm, du) / d;
        Gamma += ref.dA * c.dot(sb.m);
      }
      if (!values) continue;
      // ∂/∂x₁ of ∇E(x_{n+½})ᵀ S̄: ½ (Σ S̄_i ∇²E_i)(x_{n+½}) + ∇E(x_{n+½})ᵀ D ½ ∇E(x₁).
      const kl::NormalFactors nf1 = kl::normal_factors(c1);
      kl::StrainOperator E1;
      kl::strain_operator(c1, nf1, E1);
      kl::PointTangent T;
      kl::material_tangent(Em, E1, (0.5 * ref.dA * t) * ref.C, (0.5 * ref.dA * tb) * ref.C, T);
      kl::add_geometric_tangent(cm, nfm, sb, 0.5 * ref.dA, T);
      kl::pack_tangent(T, wk.Tg[static_cast<std::size_t>(g)]);
      for (int k = 0; k < nf; ++k)
        for (int i = 0; i < kl::kDerivatives; ++i)
          wk.Rho(kl::kDerivatives * g + i, k) = R(1 + i, k);
      if (correct) {
        // ∂Γ/∂x₁ at this point, except the −c ∂(w·w)/∂x₁ / (w·w) part (added per element):
        // Σ_i c_i ∂m̄_i = ∇E^f(x₁)ᵀ ½ t³/12 C c and Σ_i m̄_i ∂N_i / (w·w) with
        // ∂N_i/∂x₁ = ∇E^f_i(x₁) − ∇E^f_i(x_{n+½}) − ½ ∇²E^f_i(x_{n+½}) Δx.
        kl::PointTangent Tf = kl::PointTangent::Zero();
        kl::add_geometric_tangent(cm, nfm, kl::Resultants{Vec3::Zero(), sb.m}, 1.0, Tf);
        Vec<6> Sc, Sm;
        Sc << Vec3::Zero(), (0.5 * tb) * (ref.C * c);
        Sm << Vec3::Zero(), sb.m / d;
        const Ops gv = E1.transpose() * (Sc + Sm) - Em.transpose() * Sm - (0.5 / d) * (Tf * du);
        spread(R, ref.dA * gv, wk.grow);
      }
    }
    const int* cn = m.conn.data() + static_cast<std::size_t>(e) * nf;
    if (correct) {
      for (int k = 0; k < nf; ++k) wk.re.segment<3>(3 * k) += Gamma * wk.w.col(k);
    }
    for (int k = 0; k < nf; ++k) r.segment<3>(3 * cn[k]) += wk.re.segment<3>(3 * k);
    if (!values) return;
    kl::element_tangent_full(wk.Tg.data(), m.n_qp, wk.Rho, wk.W, wk.Ke);
    MatX& Ke = wk.Ke;  // block (k, l) = ∂DV_k/∂x₁_l, column-major in rows 9l … 9l + 8 of column k
    if (correct) {
      // ∂w_a/∂x₁_b = (δ_ab − 1/n)(I − ½[ω]ₓ) + [p_a]ₓ Ω_b, Ω_b = ∂ω/∂x₁_b =
      // J⁻¹(−½[u_b]ₓ + [p_b]ₓ − ω p_bᵀ + ½(p_b·ω) I + ½ p_b ωᵀ), u_b = Δx_b − mean Δx
      // (x_{n+½} moves by ½ δx₁; kl-shell.md §10).
      MatX& dW = wk.dW;
      const Vec3 v = wk.dx.rowwise().mean();
      const Mat3 A = Mat3::Identity() - 0.5 * skew(om);
      for (int b = 0; b < nf; ++b) {
        const Vec3 pb = wk.p.col(b);
        const Mat3 Om = Jinv * (skew(pb) - 0.5 * skew(wk.dx.col(b) - v) - om * pb.transpose() +
                                0.5 * pb.dot(om) * Mat3::Identity() + 0.5 * pb * om.transpose());
        for (int a = 0; a < nf; ++a)
          dW.block<3, 3>(3 * a, 3 * b) = skew(wk.p.col(a)) * Om - (1.0 / nf) * A;
        dW.block<3, 3>(3 * b, 3 * b) += A;
      }
      // ∂Γ/∂x₁ = Σ_g (…) − (Γ / (w·w)) 2 wᵀ ∂w/∂x₁; then ∂(Γ w)/∂x₁ = w (∂Γ/∂x₁) + Γ ∂w/∂x₁.
      const Eigen::Map<const VecX> wv(wk.w.data(), 3 * nf);
      wk.grow.noalias() -= (2.0 * Gamma / d) * (dW.transpose() * wv);
      for (int k = 0; k < nf; ++k)
        for (int l = 0; l < nf; ++l)
          for (int cc = 0; cc < 3; ++cc)
            for (int i = 0; i < 3; ++i)
              Ke(9 * l + i + 3 * cc, k) +=
                  Gamma * dW(3 * k + i, 3 * l + cc) + wv(3 * k + i) * wk.grow(3 * l + cc);
    }
    m.scatter_full(e, Ke, values);
  });
  return r;
}

}  // namespace isoflex::elements
