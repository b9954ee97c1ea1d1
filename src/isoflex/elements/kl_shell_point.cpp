#include "isoflex/elements/kl_shell_point.hpp"

#include "isoflex/math/skew.hpp"

namespace isoflex::elements::kl {

namespace {

// Σ_k R(d, k) x_k: the d-th derivative row of the basis applied to the local points (4.16), (4.21).
Vec3 derivative(const BasisView& R, const LocalPoints& x, int d) {
  Vec3 s = Vec3::Zero();
  for (int k = 0; k < R.n; ++k) s += R(d, k) * x.col(k);
  return s;
}

}  // namespace

ReferencePoint reference_point(const BasisView& R, const LocalPoints& X, double w, double young,
                               double poisson) {
  ReferencePoint r;
  r.A1 = derivative(R, X, 1);
  r.A2 = derivative(R, X, 2);
  r.X11 = derivative(R, X, 3);
  r.X12 = derivative(R, X, 4);
  r.X22 = derivative(R, X, 5);
  const Vec3 a3 = r.A1.cross(r.A2);
  r.J0 = a3.norm();  // ν₀ = det F₀ (3.22)
  r.A3 = a3 / r.J0;  // n₀ (3.5)
  r.A_cov = Vec3(r.A1.dot(r.A1), r.A2.dot(r.A2), r.A1.dot(r.A2));
  const double det = r.A_cov(0) * r.A_cov(1) - r.A_cov(2) * r.A_cov(2);
  r.A_con = Vec3(r.A_cov(1), r.A_cov(0), -r.A_cov(2)) / det;      // a₀^{αβ} = (A_αβ)⁻¹
  r.B = Vec3(r.X11.dot(r.A3), r.X22.dot(r.A3), r.X12.dot(r.A3));  // ∂_αβ c₀ · n₀ (3.12)
  // IGA-thesis (3.15)–(3.17): C^{αβγδ} = λ̄ A^{αβ}A^{γδ} + μ(A^{αγ}A^{βδ} + A^{αδ}A^{βγ}) with the
  // plane-stress λ̄ = 2λμ/(λ + 2μ) = Eν/(1 − ν²) and μ = E/(2(1 + ν)). The thesis writes twice this
  // tensor and compensates with the ¼ of (3.22); kl-shell.md §2.
  const double lambda = young * poisson / (1.0 - poisson * poisson);
  const double mu = young / (2.0 * (1.0 + poisson));
  Eigen::Matrix2d G;
  G << r.A_con(0), r.A_con(2), r.A_con(2), r.A_con(1);
  constexpr int ia[3] = {0, 1, 0}, ib[3] = {0, 1, 1};  // Voigt (11, 22, 12)
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k)
      r.C(i, k) = lambda * G(ia[i], ib[i]) * G(ia[k], ib[k]) +
                  mu * (G(ia[i], ia[k]) * G(ib[i], ib[k]) + G(ia[i], ib[k]) * G(ib[i], ia[k]));
  r.dA = r.J0 * w;
  return r;
}

CurrentPoint current_point(const BasisView& R, const LocalPoints& x) {
  CurrentPoint c;
  c.a1 = derivative(R, x, 1);
  c.a2 = derivative(R, x, 2);
  c.a11 = derivative(R, x, 3);
  c.a12 = derivative(R, x, 4);
  c.a22 = derivative(R, x, 5);
  const Vec3 t = c.a1.cross(c.a2);  // ã₃ (4.20)
  c.j = t.norm();
  c.a3 = t / c.j;
  return c;
}

CurrentPoint as_current(const ReferencePoint& ref) {
  CurrentPoint c;
  c.a1 = ref.A1;
  c.a2 = ref.A2;
  c.a11 = ref.X11;
  c.a12 = ref.X12;
  c.a22 = ref.X22;
  c.a3 = ref.A3;
  c.j = ref.J0;
  return c;
}

void strains(const ReferencePoint& ref, const CurrentPoint& cur, Vec3& Em, Vec3& Ef) {
  // IGA-thesis (3.11), Voigt (3.16): (E₁₁, E₂₂, 2E₁₂).
  Em = Vec3(0.5 * (cur.a1.dot(cur.a1) - ref.A_cov(0)), 0.5 * (cur.a2.dot(cur.a2) - ref.A_cov(1)),
            cur.a1.dot(cur.a2) - ref.A_cov(2));
  // IGA-thesis (3.12): E^f_αβ = ∂_αβ c₀·n₀ − ∂_αβ c·n.
  Ef = Vec3(ref.B(0) - cur.a11.dot(cur.a3), ref.B(1) - cur.a22.dot(cur.a3),
            2.0 * (ref.B(2) - cur.a12.dot(cur.a3)));
}

NormalFactors normal_factors(const CurrentPoint& cur) {
  // n^*(v) = m_v − (n·m_v) n, m_v = (∂₁v × a₂ + a₁ × ∂₂v)/j (after IGA-thesis (3.33)), i.e.
  // da₃/dx_k = P(−R_k,ξ [a₂]ₓ + R_k,η [a₁]ₓ)/j (kl-shell.md §4).
  const Mat3 P = Mat3::Identity() - cur.a3 * cur.a3.transpose();
  NormalFactors nf;
  nf.M1 = -P * skew(cur.a2) / cur.j;
  nf.M2 = P * skew(cur.a1) / cur.j;
  return nf;
}

void b_matrix(const BasisView& R, const CurrentPoint& cur, const NormalFactors& nf, BBlocks& B) {
  // a_αβᵀ M_γ, so that a_αβ · n^*(v) = R_k,ξ (a_αβᵀ M₁) + R_k,η (a_αβᵀ M₂).
  const Eigen::RowVector3d c11_1 = cur.a11.transpose() * nf.M1, c11_2 = cur.a11.transpose() * nf.M2;
  const Eigen::RowVector3d c22_1 = cur.a22.transpose() * nf.M1, c22_2 = cur.a22.transpose() * nf.M2;
  const Eigen::RowVector3d c12_1 = cur.a12.transpose() * nf.M1, c12_2 = cur.a12.transpose() * nf.M2;
  const Eigen::RowVector3d a1 = cur.a1.transpose(), a2 = cur.a2.transpose(),
                           a3 = cur.a3.transpose();
  for (int k = 0; k < R.n; ++k) {
    const double r1 = R(1, k), r2 = R(2, k), r11 = R(3, k), r12 = R(4, k), r22 = R(5, k);
    Mat<6, 3>& b = B[k];
    // E^m_* (after IGA-thesis (3.33)): (∂₁v·a₁, ∂₂v·a₂, ∂₁v·a₂ + ∂₂v·a₁).
    b.row(0) = r1 * a1;
    b.row(1) = r2 * a2;
    b.row(2) = r1 * a2 + r2 * a1;
    // E^f_* of the strain (3.12), which has the opposite sign of the thesis's printed E^f_*
    // (that is the variation of ∂_αβc·n): −(∂_αβv·n + ∂_αβc·n^*(v)), ×2 for the 12 entry.
    b.row(3) = -(r11 * a3 + r1 * c11_1 + r2 * c11_2);
    b.row(4) = -(r22 * a3 + r1 * c22_1 + r2 * c22_2);
    b.row(5) = -2.0 * (r12 * a3 + r1 * c12_1 + r2 * c12_2);
  }
}

double energy_density(const Vec3& Em, const Vec3& Ef, const Resultants& s) {
  // IGA-thesis (3.22) with 2ε = t: ½ t E^m·C E^m + ½ t³/12 E^f·C E^f (kl-shell.md §2).
  return 0.5 * (s.n.dot(Em) + s.m.dot(Ef));
}

namespace {

// K_kl += Zt_k Y_l for k ≤ l, with fixed N-row factors (N = 6: material part only).
template <int N>
void add_blocks(const std::array<Mat<3, N>, kMaxFunctions>& Zt,
                const std::array<Mat<N, 3>, kMaxFunctions>& Y, int n, MatX& K) {
  for (int l = 0; l < n; ++l)
    for (int k = 0; k <= l; ++k) K.block<3, 3>(3 * k, 3 * l).noalias() += Zt[k].lazyProduct(Y[l]);
}

}  // namespace

void add_material_stiffness(const BBlocks& B, int n, const Mat3& Cm, const Mat3& Cb, MatX& K) {
  // IGA-thesis (3.36), the terms S_*(w)·E_*(v) with S_* = C E_*: Σ B_kᵀ D B_l.
  std::array<Mat<3, 6>, kMaxFunctions> Zt;
  std::array<Mat<6, 3>, kMaxFunctions> Y;
  for (int k = 0; k < n; ++k) {
    Zt[k] = B[k].transpose();
    Y[k].topRows<3>().noalias() = Cm * B[k].topRows<3>();
    Y[k].bottomRows<3>().noalias() = Cb * B[k].bottomRows<3>();
  }
  add_blocks<6>(Zt, Y, n, K);
}

void add_stiffness(const BasisView& R, const CurrentPoint& cur, const NormalFactors& nf,
                   const BBlocks& B, const Resultants& s, double w, const Mat3& Cm, const Mat3& Cb,
                   MatX& K) {
  // IGA-thesis (3.36): material part B_kᵀ D B_l plus the geometric part n·E^m_**(v, w) +
  // m·E^f_**(v, w) with the second variation n^** of the normal (after (3.36)), in the factored
  // form of kl-shell.md §5:  K_kl = Z_kᵀ Y_l + (R_k,ξ R_l,η − R_k,η R_l,ξ)[c']ₓ + g_kl I with
  //   Z_k = [B_k; P_k; Q_k],  Y_l = [D B_l; Q_l; P_l],
  //   P_k = [da₃/dx_k; h_kᵀ],  Q_k = [−s_k I + ½(c·a₃) da₃/dx_k; (D_kᵀc')ᵀ].
  const Vec3 n = w * s.n, m = w * s.m;
  // c = Σ m^{αβ} a_αβ (Voigt weights 1, 1, 2), c' = P c / j.
  const Vec3 c = m(0) * cur.a11 + m(1) * cur.a22 + 2.0 * m(2) * cur.a12;
  const double ca3 = c.dot(cur.a3);
  const Vec3 cp = (c - ca3 * cur.a3) / cur.j;
  // Contravariant current base vectors a^1 = a₂ × a₃ / j, a^2 = a₃ × a₁ / j.
  const Vec3 g1 = cur.a2.cross(cur.a3) / cur.j, g2 = cur.a3.cross(cur.a1) / cur.j;
  const Vec3 a2c = cur.a2.cross(cp), a1c = cur.a1.cross(cp);
  std::array<Mat<3, 14>, kMaxFunctions> Zt;
  std::array<Mat<14, 3>, kMaxFunctions> Y;
  for (int k = 0; k < R.n; ++k) {
    const double r1 = R(1, k), r2 = R(2, k);
    const double sk = m(0) * R(3, k) + m(1) * R(5, k) + 2.0 * m(2) * R(4, k);  // Σ m^{αβ} R_k,αβ
    const Mat3 da3 = r1 * nf.M1 + r2 * nf.M2;
    const Vec3 h = r1 * g1 + r2 * g2;    // D_kᵀ a₃ / j
    const Vec3 q = r1 * a2c - r2 * a1c;  // D_kᵀ c'
    Mat3 Q = (0.5 * ca3) * da3;
    Q.diagonal().array() -= sk;
    Mat<3, 14>& z = Zt[k];
    z.leftCols<6>() = B[k].transpose();
    z.middleCols<3>(6) = da3.transpose();
    z.col(9) = h;
    z.middleCols<3>(10) = Q.transpose();
    z.col(13) = q;
    Mat<14, 3>& y = Y[k];
    y.topRows<3>().noalias() = Cm * B[k].topRows<3>();
    y.middleRows<3>(3).noalias() = Cb * B[k].bottomRows<3>();
    y.middleRows<3>(6) = Q;
    y.row(9) = q.transpose();
    y.middleRows<3>(10) = da3;
    y.row(13) = h.transpose();
  }
  add_blocks<14>(Zt, Y, R.n, K);
  for (int l = 0; l < R.n; ++l) {
    const double r1l = R(1, l), r2l = R(2, l);
    for (int k = 0; k <= l; ++k) {
      const double r1k = R(1, k), r2k = R(2, k);
      const double a = r1k * r2l - r2k * r1l;
      // Membrane: n·E^m_**(v, w) = δ_ik (n¹¹ R_k,ξ R_l,ξ + n²² R_k,η R_l,η + n¹²(…)).
      const double gm = n(0) * r1k * r1l + n(1) * r2k * r2l + n(2) * (r1k * r2l + r2k * r1l);
      auto blk = K.block<3, 3>(3 * k, 3 * l);
      blk(0, 0) += gm;
      blk(1, 1) += gm;
      blk(2, 2) += gm;
      blk(1, 0) += a * cp(2);  // a [c']ₓ
      blk(0, 1) -= a * cp(2);
      blk(0, 2) += a * cp(1);
      blk(2, 0) -= a * cp(1);
      blk(2, 1) += a * cp(0);
      blk(1, 2) -= a * cp(0);
    }
  }
}

}  // namespace isoflex::elements::kl
