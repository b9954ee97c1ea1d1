#include "isoflex/elements/kl_shell_point.hpp"

#include <algorithm>

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
  // The five derivative rows in one pass over the functions (independent sums, (4.21)).
  c.a1.setZero();
  c.a2.setZero();
  c.a11.setZero();
  c.a12.setZero();
  c.a22.setZero();
  for (int k = 0; k < R.n; ++k) {
    const Vec3 xk = x.col(k);
    c.a1 += R(1, k) * xk;
    c.a2 += R(2, k) * xk;
    c.a11 += R(3, k) * xk;
    c.a12 += R(4, k) * xk;
    c.a22 += R(5, k) * xk;
  }
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

void strain_operator(const CurrentPoint& cur, const NormalFactors& nf, StrainOperator& E) {
  // The E_i read off b_matrix (after IGA-thesis (3.33), kl-shell.md §4–§5): B_k = Σ_i ρ_i(k) E_i.
  const Eigen::RowVector3d a1 = cur.a1.transpose(), a2 = cur.a2.transpose(),
                           a3 = cur.a3.transpose();
  E.setZero();
  const Mat3* M[2] = {&nf.M1, &nf.M2};
  for (int i = 0; i < 2; ++i) {  // R_k,ξ and R_k,η: membrane rows and a_αβᵀ da₃/dx_k
    auto Ei = E.middleCols<3>(3 * i);
    Ei.row(i) = i == 0 ? a1 : a2;
    Ei.row(2) = i == 0 ? a2 : a1;
    Ei.row(3).noalias() = -cur.a11.transpose() * *M[i];
    Ei.row(4).noalias() = -cur.a22.transpose() * *M[i];
    Ei.row(5).noalias() = -2.0 * cur.a12.transpose() * *M[i];
  }
  E.block<1, 3>(3, 6) = -a3;        // R_k,ξξ: E^f₁₁
  E.block<1, 3>(5, 9) = -2.0 * a3;  // R_k,ξη: 2E^f₁₂
  E.block<1, 3>(4, 12) = -a3;       // R_k,ηη: E^f₂₂
}

void material_tangent(const StrainOperator& E, const Vec3& a3, const Mat3& Cm, const Mat3& Cb,
                      PointTangent& T) {
  // IGA-thesis (3.36), the terms S_*(w)·E_*(v) with S_* = C E_*: B_kᵀ D B_l = Σ_ij ρ_i(k) ρ_j(l)
  // E_iᵀ D E_j. The columns of E_ξξ, E_ξη, E_ηη have one non-zero row each (σ a₃ᵀ in the bending
  // row r, σ = −1, −2, −1): their rows of T are −σ a₃ ⊗ (D E)_r.
  Mat<6, 15> DE;
  DE.topRows<3>() = Cm.lazyProduct(E.topRows<3>());
  DE.bottomRows<3>() = Cb.lazyProduct(E.bottomRows<3>());
  T.topRows<6>() = E.leftCols<6>().transpose().lazyProduct(DE);
  T.middleRows<3>(6) = -a3 * DE.row(3);          // R_k,ξξ
  T.middleRows<3>(9) = (-2.0 * a3) * DE.row(5);  // R_k,ξη
  T.middleRows<3>(12) = -a3 * DE.row(4);         // R_k,ηη
}

void material_tangent(const StrainOperator& EL, const StrainOperator& ER, const Mat3& Cm,
                      const Mat3& Cb, PointTangent& T) {
  // IGA-thesis (3.36), S_*(w)·E_*(v) with the variations of two configurations: dense, since the
  // sparsity of the E_ξξ, E_ξη, E_ηη columns that material_tangent uses holds for each operator
  // but with different normals a₃.
  Mat<6, 15> DE;
  DE.topRows<3>() = Cm.lazyProduct(ER.topRows<3>());
  DE.bottomRows<3>() = Cb.lazyProduct(ER.bottomRows<3>());
  T = EL.transpose().lazyProduct(DE);
}

void add_geometric_tangent(const CurrentPoint& cur, const NormalFactors& nf, const Resultants& s,
                           double w, PointTangent& T) {
  // IGA-thesis (3.36), S·E_**: the geometric part G_kl of kl-shell.md §5, written as
  // Σ_ij ρ_i(k) ρ_j(l) G_ij. Membrane: g_kl I. Bending, with c = Σ m^{αβ} a_αβ (Voigt weights
  // 1, 1, 2), c' = P c / j, s_k = Σ m^{αβ} R_k,αβ, da₃/dx_k = R_k,ξ M₁ + R_k,η M₂,
  // h_k = R_k,ξ a^1 + R_k,η a^2, q_k = R_k,ξ (a₂ × c') − R_k,η (a₁ × c'):
  //   −s_k da₃/dx_l − s_l (da₃/dx_k)ᵀ + (R_k,ξ R_l,η − R_k,η R_l,ξ)[c']ₓ + h_k q_lᵀ + q_k h_lᵀ
  //   + (c·a₃)(da₃/dx_k)ᵀ da₃/dx_l.
  const Vec3 n = w * s.n, m = w * s.m;
  const Vec3 c = m(0) * cur.a11 + m(1) * cur.a22 + 2.0 * m(2) * cur.a12;
  const double ca3 = c.dot(cur.a3);
  const Vec3 cp = (c - ca3 * cur.a3) / cur.j;
  // Contravariant current base vectors a^1 = a₂ × a₃ / j, a^2 = a₃ × a₁ / j.
  const Vec3 h[2] = {cur.a2.cross(cur.a3) / cur.j, cur.a3.cross(cur.a1) / cur.j};
  const Vec3 q[2] = {cur.a2.cross(cp), -cur.a1.cross(cp)};
  const Mat3* M[2] = {&nf.M1, &nf.M2};
  // Membrane n·E^m_**: n¹¹ R_k,ξ R_l,ξ + n²² R_k,η R_l,η + n¹² (R_k,ξ R_l,η + R_k,η R_l,ξ), × I.
  const double nm[2][2] = {{n(0), n(2)}, {n(2), n(1)}};
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) {
      auto Tij = T.block<3, 3>(3 * i, 3 * j);
      Tij.noalias() += ca3 * (M[i]->transpose() * *M[j]);
      Tij.noalias() += h[i] * q[j].transpose() + q[i] * h[j].transpose();
      Tij.diagonal().array() += nm[i][j];
    }
  const Mat3 cx = skew(cp);
  T.block<3, 3>(0, 3) += cx;  // (R_k,ξ R_l,η − R_k,η R_l,ξ)[c']ₓ
  T.block<3, 3>(3, 0) -= cx;
  // −s_k da₃/dx_l − s_l (da₃/dx_k)ᵀ: s_k = m¹¹ R_k,ξξ + 2m¹² R_k,ξη + m²² R_k,ηη.
  const double mv[3] = {m(0), 2.0 * m(2), m(1)};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 2; ++j) {
      T.block<3, 3>(3 * (i + 2), 3 * j) -= mv[i] * *M[j];
      T.block<3, 3>(3 * j, 3 * (i + 2)) -= mv[i] * M[j]->transpose();
    }
}

Derivatives gather_derivatives(const BasisView& R, const LocalPoints& d) {
  Derivatives du = Derivatives::Zero();
  for (int k = 0; k < R.n; ++k)
    for (int i = 0; i < kDerivatives; ++i) du.segment<3>(3 * i) += R(1 + i, k) * d.col(k);
  return du;
}

void spread(const BasisView& R, const Derivatives& f, LocalVector& v) {
  for (int k = 0; k < R.n; ++k)
    v.segment<3>(3 * k) += R(1, k) * f.segment<3>(0) + R(2, k) * f.segment<3>(3) +
                           R(3, k) * f.segment<3>(6) + R(4, k) * f.segment<3>(9) +
                           R(5, k) * f.segment<3>(12);
}

void pack_tangent(const PointTangent& T, PackedTangent& P) {
  for (int j = 0; j < kDerivatives; ++j)
    for (int i = 0; i < kDerivatives; ++i)
      for (int b = 0; b < 3; ++b)
        P.col(j).segment<3>(9 * i + 3 * b) = T.block<3, 1>(3 * i, 3 * j + b);
}

namespace {

// W (9n × 5G) of kl-shell.md §5, eq. (K): row 9l + e, column 5g + i holds entry e of W_i^g(l)
// (column-major 3 × 3).
void point_products(const PackedTangent* T, int G, const MatX& Rho, MatX& W) {
  const int n = static_cast<int>(Rho.cols());
  W.resize(9 * n, kDerivatives * G);
  for (int g = 0; g < G; ++g) {
    const PackedTangent& Tg = T[g];
    for (int l = 0; l < n; ++l) {
      const double* rl = &Rho(kDerivatives * g, l);
      const double r0 = rl[0], r1 = rl[1], r2 = rl[2], r3 = rl[3], r4 = rl[4];
      for (int i = 0; i < kDerivatives; ++i)  // W_i^g(l) = Σ_j T_ij^g ρ_j^g(l)
        Eigen::Map<Vec<9>>(&W(9 * l, kDerivatives * g + i)) =
            Tg.col(0).segment<9>(9 * i) * r0 + Tg.col(1).segment<9>(9 * i) * r1 +
            Tg.col(2).segment<9>(9 * i) * r2 + Tg.col(3).segment<9>(9 * i) * r3 +
            Tg.col(4).segment<9>(9 * i) * r4;
    }
  }
}

}  // namespace

void element_tangent(const PackedTangent* T, int G, const MatX& Rho, MatX& W, MatX& K) {
  // kl-shell.md §5, eq. (K). W as in point_products; then K (9n × n), row 9l + e, column k,
  // = W · Rho, the sum over all points and all i as one matrix product (Eigen's blocked GEMM, the
  // element matrix written once).
  const int n = static_cast<int>(Rho.cols());
  point_products(T, G, Rho, W);
  // Only k ≤ l is needed: row chunks of kChunk functions l against the columns k < l1 (chunks of
  // 2 measured slower, 8 waste more). Chunks of rows and of points keep Eigen's packed blocks
  // (≤ 36 × 180 doubles, 52 KB) below its limit for stack allocation: no heap allocation here.
  constexpr int kChunk = 4, kPointChunk = 36;
  K.setZero();
  for (int l0 = 0; l0 < n; l0 += kChunk) {
    const int l1 = std::min(n, l0 + kChunk);
    for (int g0 = 0; g0 < G; g0 += kPointChunk) {
      const int ng = std::min(G, g0 + kPointChunk) - g0;
      K.block(9 * l0, 0, 9 * (l1 - l0), l1).noalias() +=
          W.block(9 * l0, kDerivatives * g0, 9 * (l1 - l0), kDerivatives * ng) *
          Rho.block(kDerivatives * g0, 0, kDerivatives * ng, l1);
    }
  }
}

void element_tangent_full(const PackedTangent* T, int G, const MatX& Rho, MatX& W, MatX& K) {
  // As element_tangent, but all columns k for every chunk of rows l (no symmetry to use); the same
  // chunks keep Eigen's packed blocks on the stack.
  const int n = static_cast<int>(Rho.cols());
  point_products(T, G, Rho, W);
  constexpr int kChunk = 4, kPointChunk = 36;
  K.setZero();
  for (int l0 = 0; l0 < n; l0 += kChunk) {
    const int nl = std::min(n, l0 + kChunk) - l0;
    for (int g0 = 0; g0 < G; g0 += kPointChunk) {
      const int ng = std::min(G, g0 + kPointChunk) - g0;
      K.middleRows(9 * l0, 9 * nl).noalias() +=
          W.block(9 * l0, kDerivatives * g0, 9 * nl, kDerivatives * ng) *
          Rho.middleRows(kDerivatives * g0, kDerivatives * ng);
    }
  }
}

}  // namespace isoflex::elements::kl
