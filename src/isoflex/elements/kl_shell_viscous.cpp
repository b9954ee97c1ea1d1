// KLShellPatch::viscous_force_into: the Kelvin–Voigt viscous force of IGA-thesis §3.5,
// (3.51)–(3.55), and its linearization in x and ẋ. Derivation and the matrix forms:
// docs/theory/kl-shell.md §11.
#include <algorithm>
#include <vector>

#include "isoflex/elements/kl_shell_patch_impl.hpp"

namespace isoflex::elements {

namespace {

struct Work {
  geometry::ElementBasis eb;
  kl::LocalPoints xl, vl, Xl;
  kl::LocalVector re;
  std::vector<kl::PackedTangent> Tg;
  MatX Rho, W, Ke;
};

// The x-derivative of the strain rates at one point, ∂Ė/∂x_l = Σ_k ∂²E/∂x_k∂x_l ẋ_k
// = Σ_j ρ_j(l) F_j: in the ρ-form of the second variations, ∂²E_c/∂x_k∂x_l = Σ_ij ρ_i(k) ρ_j(l)
// H^c_ij (add_geometric_tangent with the unit resultant of component c), row c of F_j is
// Σ_i ėᵢᵀ H^c_ij with ė = Σ_k ρ(k) ẋ_k the gathered velocity derivatives. F has the shape of a
// strain operator, so Bᵀ D ∂Ė/∂x is material_tangent(E, F) (the thesis' Ė_*,v, (3.55) ff.).
kl::StrainOperator rate_operator(const kl::CurrentPoint& cur, const kl::NormalFactors& nf,
                                 const kl::Derivatives& rate) {
  kl::StrainOperator F;
  for (int c = 0; c < 6; ++c) {
    kl::Resultants unit{Vec3::Zero(), Vec3::Zero()};
    (c < 3 ? unit.n : unit.m)(c % 3) = 1.0;
    kl::PointTangent H = kl::PointTangent::Zero();
    kl::add_geometric_tangent(cur, nf, unit, 1.0, H);
    F.row(c) = rate.transpose() * H;
  }
  return F;
}

}  // namespace

VecX KLShellPatch::viscous_force_into(const VecX& x, const VecX& xdot, KLKinematics kin, double cx,
                                      double cv, double* values) const {
  const Impl& m = *impl_;
  m.check_size(x, "viscous_force");
  m.check_size(xdot, "viscous_force");
  VecX r = VecX::Zero(x.size());
  const double eta = m.sec.eta;
  if (eta == 0.0) return r;
  const double t = m.membrane_thickness(), tb = m.bending_thickness();
  const bool linear = kin == KLKinematics::linear;
  const int nf = m.n_fun;
  const int workers = m.workers(threads_);
  std::vector<Work> work(static_cast<std::size_t>(workers));
  for (Work& w : work) {
    w.re.resize(3 * nf);
    if (!values) continue;
    w.Tg.resize(static_cast<std::size_t>(m.n_qp));
    w.Rho.resize(kl::kDerivatives * m.n_qp, nf);
    w.Ke.resize(9 * nf, nf);
  }
  m.loop.run(workers, [&](int e, int worker) {
    Work& w = work[static_cast<std::size_t>(worker)];
    geometry::element_basis(m.ref, m.elems[e], m.rule_u, m.rule_v, w.eb);
    m.gather(x, e, w.xl);
    m.gather(xdot, e, w.vl);
    w.re.setZero();
    for (int g = 0; g < m.n_qp; ++g) {
      const kl::BasisView R = Impl::view(w.eb, g);
      const kl::ReferencePoint& ref = m.points[static_cast<std::size_t>(e) * m.n_qp + g];
      const kl::CurrentPoint cur = linear ? kl::as_current(ref) : kl::current_point(R, w.xl);
      const kl::NormalFactors nfac = kl::normal_factors(cur);
      kl::StrainOperator E;
      kl::strain_operator(cur, nfac, E);
      // Ė = B(x) ẋ, (3.52)–(3.54); S_v = η C Ė (3.51), pre-integrated over the thickness and
      // times dA: D = dA diag(t C, t³/12 C).
      const kl::Derivatives rate = kl::gather_derivatives(R, w.vl);
      const Vec<6> Edot = E * rate;
      const Mat3 Dm = (eta * ref.dA * t) * ref.C, Db = (eta * ref.dA * tb) * ref.C;
      Vec<6> S;
      S << Dm * Edot.head<3>(), Db * Edot.tail<3>();
      kl::spread(R, E.transpose() * S, w.re);  // (3.55): ∫ S_v·E_*(v)
      if (!values) continue;
      // cv ∂f_v/∂ẋ = cv Bᵀ D B (the damping matrix), cx ∂f_v/∂x = cx (Σ S_v,c ∂²E_c + Bᵀ D ∂Ė/∂x).
      kl::PointTangent T;
      kl::material_tangent(E, cur.a3, cv * Dm, cv * Db, T);
      if (!linear && cx != 0.0) {
        kl::PointTangent Tx;
        kl::material_tangent(E, rate_operator(cur, nfac, rate), cx * Dm, cx * Db, Tx);
        kl::add_geometric_tangent(cur, nfac, kl::Resultants{S.head<3>(), S.tail<3>()}, cx, Tx);
        T += Tx;
      }
      kl::pack_tangent(T, w.Tg[static_cast<std::size_t>(g)]);
      for (int k = 0; k < nf; ++k)
        for (int i = 0; i < kl::kDerivatives; ++i) w.Rho(kl::kDerivatives * g + i, k) = R(1 + i, k);
    }
    const int* cn = m.conn.data() + static_cast<std::size_t>(e) * nf;
    for (int k = 0; k < nf; ++k) r.segment<3>(3 * cn[k]) += w.re.segment<3>(3 * k);
    if (!values) return;
    kl::element_tangent_full(w.Tg.data(), m.n_qp, w.Rho, w.W, w.Ke);
    m.scatter_full(e, w.Ke, values);
  });
  return r;
}

}  // namespace isoflex::elements
