#include "isoflex/elements/beam_element.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace isoflex::elements {

namespace {

using Coeff8 = Vec<8>;

// Block index of field f (0 = φ, 1..3 = d_f) of node n (0 = a, 1 = b) among the eight 3-vector
// blocks of the element's q.
constexpr int block(int node, int field) {
  return 4 * node + field;
}

// Coefficients of the midpoint quantities as linear combinations of the blocks, from linear
// Lagrange interpolation N_a = 1 − s/L₀, N_b = s/L₀ at s = L₀/2 (DNSM-III (18)):
// φ′ = (φ_b − φ_a)/L₀, d_i = ½(d_ia + d_ib), d_i′ = (d_ib − d_ia)/L₀.
Coeff8 derivative_of(int field, double L0) {
  Coeff8 c = Coeff8::Zero();
  c(block(0, field)) = -1.0 / L0;
  c(block(1, field)) = 1.0 / L0;
  return c;
}
Coeff8 midpoint_of(int field) {
  Coeff8 c = Coeff8::Zero();
  c(block(0, field)) = 0.5;
  c(block(1, field)) = 0.5;
  return c;
}

// The bilinear form u·v with u = Σ α_b q_b, v = Σ β_b q_b equals ½ Σ h(b,c) q_b·q_c with
// h = αβᵀ + βαᵀ.
Mat<8, 8> bilinear(const Coeff8& alpha, const Coeff8& beta) {
  return alpha * beta.transpose() + beta * alpha.transpose();
}

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument("BeamElement: " + message);
}

}  // namespace

BeamElement::BeamElement(int node_a, int node_b, const frame_node::Q& q0_a,
                         const frame_node::Q& q0_b, const BeamSection& section, const Vec3& gravity,
                         const std::optional<Mat3>& triad_a, const std::optional<Mat3>& triad_b)
    : nodes_{node_a, node_b},
      section_(section),
      g_(gravity),
      L0_((frame_node::phi(q0_b) - frame_node::phi(q0_a)).norm()) {
  // Checks at the boundary, written so that NaN fails.
  require(L0_ > 0.0, "reference nodes coincide (L0 = " + std::to_string(L0_) + ")");
  const double phi_int = std::max(frame_node::constraints(q0_a).cwiseAbs().maxCoeff(),
                                  frame_node::constraints(q0_b).cwiseAbs().maxCoeff());
  require(phi_int <= 1e-8,
          "reference triads are not orthonormal (max |Phi_int| = " + std::to_string(phi_int) + ")");
  const auto positive = [](const char* name, double v) {
    require(v > 0.0, std::string(name) + " must be > 0, got " + std::to_string(v));
  };
  positive("EA", section.EA);
  positive("GA1", section.GA1);
  positive("GA2", section.GA2);
  positive("EI1", section.EI1);
  positive("EI2", section.EI2);
  positive("GJ", section.GJ);
  const auto non_negative = [](const char* name, double v) {
    require(v >= 0.0, std::string(name) + " must be >= 0, got " + std::to_string(v));
  };
  non_negative("A_rho", section.A_rho);
  non_negative("M_rho1", section.M_rho1);
  non_negative("M_rho2", section.M_rho2);
  require(gravity.allFinite(), "gravity must be finite");

  // Strain forms (theory-notes, Betsch & Steinmann 2002), i = 1, 2, 3 ↔ field i:
  //   Γ_i = d_i·φ′,   K_i = ½(d_k·d_j′ − d_j·d_k′) for (i, j, k) cyclic.
  const Coeff8 phi_prime = derivative_of(0, L0_);
  for (int i = 1; i <= 3; ++i) {
    const int j = i % 3 + 1;
    const int k = j % 3 + 1;
    h_[i - 1] = bilinear(midpoint_of(i), phi_prime);
    h_[i + 2] = 0.5 * (bilinear(midpoint_of(k), derivative_of(j, L0_)) -
                       bilinear(midpoint_of(j), derivative_of(k, L0_)));
  }
  C_ << section.GA1, section.GA2, section.EA, section.EI1, section.EI2, section.GJ;

  // The element's blocks Q̃ = Q P from the nodes' Q (3 × 8): at a node with its own triad the
  // element's directors d̃ᵢ = Σⱼ Rᵢⱼ dⱼ, R = triadᵀ D⁰, so E_k = ½⟨h_k, PᵀQᵀQP⟩ = ½⟨P h_k Pᵀ, QᵀQ⟩.
  p_ = Block8::Identity();
  for (int node = 0; node < 2; ++node) {
    const std::optional<Mat3>& triad = node == 0 ? triad_a : triad_b;
    if (!triad) continue;
    const frame_node::Q& q0n = node == 0 ? q0_a : q0_b;
    Mat3 D0;
    for (int j = 0; j < 3; ++j) D0.col(j) = q0n.segment<3>(3 + 3 * j);
    require(((*triad).transpose() * *triad - Mat3::Identity()).cwiseAbs().maxCoeff() <= 1e-8,
            "the element's triad at a node is not orthonormal");
    const Mat3 R = triad->transpose() * D0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) p_(block(node, 1 + j), block(node, 1 + i)) = R(i, j);
  }
  if (!p_.isIdentity(0.0))
    for (Block8& h : h_) h = p_ * h * p_.transpose();
  for (int k = 0; k < 6; ++k)
    for (int c = 0; c < 8; ++c)
      for (int b = 0; b < 8; ++b)
        if (h_[k](b, c) != 0.0) entries_.push_back({3 * b, kCoords * k + 3 * c, h_[k](b, c)});
  std::vector<std::vector<Entry>> by_slot(6 * 8);
  for (const Entry& e : entries_) by_slot[e.out / 3].push_back(e);
  if (std::all_of(by_slot.begin(), by_slot.end(), [](const auto& l) { return l.size() <= 2; }))
    for (int o = 0; o < 6 * 8; ++o) {
      const auto& l = by_slot[o];
      if (l.empty())
        zero_slots_.push_back(3 * o);
      else if (l.size() == 1)
        singles_.push_back({3 * o, l[0].in, l[0].in, l[0].h, 0.0});
      else
        pairs_.push_back({3 * o, l[0].in, l[1].in, l[0].h, l[1].h});
    }

  Q q0;
  q0 << q0_a, q0_b;
  e0_ = raw_strains(q0);
}

BeamElement::Q BeamElement::as_element_q(const VecX& q) {
  if (q.size() != kCoords)
    throw std::invalid_argument("BeamElement: expected 24 coordinates, got " +
                                std::to_string(q.size()));
  return q;
}

BeamElement::Strain6 BeamElement::raw_strains(const Q& q) const {
  // Gram matrix of the blocks: E_k = ½ ⟨h_k, QᵀQ⟩ with Q = [q_0 … q_7] (3 × 8).
  const Eigen::Map<const Mat<3, 8>> blocks(q.data());
  const Mat<8, 8> gram = blocks.transpose().lazyProduct(blocks);
  Strain6 e;
  for (int k = 0; k < 6; ++k) e(k) = 0.5 * h_[k].cwiseProduct(gram).sum();
  return e;
}

Mat<BeamElement::kCoords, 6> BeamElement::strain_jacobian_transpose(const Q& q) const {
  // Column k of Bᵀ is H_k q = (h_k ⊗ I₃) q, i.e. the 3 × 8 matrix Q h_k read column by column:
  // column c of Q h_k is Σ_b h_k(b, c) q_b, summed over the nonzeros of h_k only (entries_, two
  // per column without corner triads) instead of the dense 3 × 8 by 8 × 8 product.
  Mat<kCoords, 6> Bt;
  double* out = Bt.data();
  const double* in = q.data();
  if (!zero_slots_.empty() || !singles_.empty() || !pairs_.empty()) {
    // Without corner triads every 3-vector has two entries, one or none: each summed in
    // registers and stored once (the loop below loads and stores Bᵀ for every entry and zeroes
    // it first). The sums start from 0.0 as those of the loop do, so that a contracted
    // multiply-add rounds the same way (h₀a + h₁b written as such would be contracted the other
    // way round).
    for (const int o : zero_slots_) out[o] = out[o + 1] = out[o + 2] = 0.0;
    const auto add = [](double(&sum)[3], double h, const double* a) {
      sum[0] += h * a[0];
      sum[1] += h * a[1];
      sum[2] += h * a[2];
    };
    const auto store = [](double* o, const double(&sum)[3]) {
      o[0] = sum[0];
      o[1] = sum[1];
      o[2] = sum[2];
    };
    for (const SlotEntries& p : singles_) {
      double sum[3] = {0.0, 0.0, 0.0};
      add(sum, p.h0, in + p.in0);
      store(out + p.out, sum);
    }
    for (const SlotEntries& p : pairs_) {
      double sum[3] = {0.0, 0.0, 0.0};
      add(sum, p.h0, in + p.in0);
      add(sum, p.h1, in + p.in1);
      store(out + p.out, sum);
    }
    return Bt;
  }
  Bt.setZero();
  for (const Entry& e : entries_) {
    double* o = out + e.out;
    const double* i = in + e.in;
    o[0] += e.h * i[0];
    o[1] += e.h * i[1];
    o[2] += e.h * i[2];
  }
  return Bt;
}

Mat<BeamElement::kCoords, BeamElement::kCoords> BeamElement::weighted_strain_hessian(
    const Strain6& S) const {
  Block8 h = Block8::Zero();
  for (int k = 0; k < 6; ++k) h += S(k) * h_[k];
  Mat<kCoords, kCoords> H = Mat<kCoords, kCoords>::Zero();
  for (int b = 0; b < 8; ++b)
    for (int c = 0; c < 8; ++c) H.block<3, 3>(3 * b, 3 * c).diagonal().setConstant(h(b, c));
  return H;
}

Vec<BeamElement::kCoords> BeamElement::gravity_gradient() const {
  // V_g = −∫ A_ρ g·φ ds = −½ A_ρ L₀ g·(φ_a + φ_b) for linear shape functions.
  Vec<kCoords> f = Vec<kCoords>::Zero();
  f.segment<3>(0) = -0.5 * section_.A_rho * L0_ * g_;
  f.segment<3>(12) = -0.5 * section_.A_rho * L0_ * g_;
  return f;
}

double BeamElement::potential(const VecX& qx) const {
  const Q q = as_element_q(qx);
  const Strain6 e = raw_strains(q) - e0_;
  // DNSM-III (69): W = ½ (Γᵀ C_Γ Γ + Kᵀ C_K K), one-point quadrature over L₀.
  return 0.5 * L0_ * e.dot(C_.cwiseProduct(e)) + gravity_gradient().dot(q);
}

VecX BeamElement::gradient(const VecX& qx) const {
  const Q q = as_element_q(qx);
  const Strain6 S = C_.cwiseProduct(raw_strains(q) - e0_);  // (n, m), DNSM-III (69)
  const Vec<kCoords> g = L0_ * strain_jacobian_transpose(q) * S + gravity_gradient();
  return g;
}

Mat<BeamElement::kCoords, BeamElement::kCoords> BeamElement::hessian(const VecX& qx) const {
  const Q q = as_element_q(qx);
  const Strain6 S = C_.cwiseProduct(raw_strains(q) - e0_);
  const Mat<kCoords, 6> Bt = strain_jacobian_transpose(q);
  const Mat<kCoords, 6> BC = Bt * C_.asDiagonal();
  return L0_ * (BC.lazyProduct(Bt.transpose()) + weighted_strain_hessian(S));
}

VecX BeamElement::discrete_gradient(const VecX& qnx, const VecX& qn1x, MatX* dv_dqn1) const {
  Q dv;
  if (!dv_dqn1) {
    discrete_gradient(as_element_q(qnx), as_element_q(qn1x), dv, nullptr);
    return dv;
  }
  Mat<kCoords, kCoords> K;
  discrete_gradient(as_element_q(qnx), as_element_q(qn1x), dv, &K);
  *dv_dqn1 = K;
  return dv;
}

void BeamElement::discrete_gradient(const Q& qn, const Q& qn1, Q& dv,
                                    Mat<kCoords, kCoords>* dv_dqn1,
                                    const Strain6* strains_n) const {
  const Q qm = 0.5 * (qn + qn1);
  // Average strain Ē = ½(E(qₙ) + E(qₙ₊₁)), not E(q_{n+½}): with E quadratic,
  // E(qₙ₊₁) − E(qₙ) = B(q_{n+½})(qₙ₊₁ − qₙ) exactly, so DV·Δq = ΔV (theory-notes, average strain),
  // and Ē = E(qₙ) + ½ B(q_{n+½}) Δq needs no strains at qₙ₊₁.
  const Mat<kCoords, 6> Bmt = strain_jacobian_transpose(qm);
  const Strain6 e_avg =
      (strains_n ? *strains_n : raw_strains(qn)) + 0.5 * (Bmt.transpose() * (qn1 - qn)) - e0_;
  const Strain6 S = C_.cwiseProduct(e_avg);
  dv = L0_ * Bmt * S + gravity_gradient();
  if (!dv_dqn1) return;
  // ∂/∂qₙ₊₁ [B(q_{n+½})ᵀ S̄] = ½ Σ_k S̄_k H_k + B(q_{n+½})ᵀ C ½ B(qₙ₊₁) — not symmetric.
  // Bᵀ C B′ as six rank-one updates, column by column (24-vectors: unrolled and vectorized; the
  // lazy 24 × 6 by 6 × 24 product went coefficient by coefficient), then Σ_k S̄_k h_k ⊗ I₃ on
  // the diagonals of the 3 × 3 blocks.
  Mat<kCoords, 6> BmC = Bmt;
  for (int k = 0; k < 6; ++k) BmC.col(k) *= C_(k);
  const Mat<kCoords, 6> B1t = strain_jacobian_transpose(qn1);
  Mat<kCoords, kCoords>& K = *dv_dqn1;
  for (int c = 0; c < kCoords; ++c)
    K.col(c) = BmC.col(0) * B1t(c, 0) + BmC.col(1) * B1t(c, 1) + BmC.col(2) * B1t(c, 2) +
               BmC.col(3) * B1t(c, 3) + BmC.col(4) * B1t(c, 4) + BmC.col(5) * B1t(c, 5);
  Block8 h = Block8::Zero();
  for (int k = 0; k < 6; ++k) h += S(k) * h_[k];
  for (int b = 0; b < 8; ++b)
    for (int c = 0; c < 8; ++c) K.block<3, 3>(3 * b, 3 * c).diagonal().array() += h(b, c);
  K *= 0.5 * L0_;
}

VecX BeamElement::strain_dissipation_force_in_pattern(const VecX& q_prevx, const VecX& qnx,
                                                      const VecX& qn1x, double chi, double ratio,
                                                      double* values) const {
  const Q qn = as_element_q(qnx), qn1 = as_element_q(qn1x);
  const Strain6 en = raw_strains(qn);
  const Strain6 d2e = raw_strains(qn1) - en - ratio * (en - raw_strains(as_element_q(q_prevx)));
  const Strain6 S = chi * C_.cwiseProduct(d2e);
  const Mat<kCoords, 6> Bmt = strain_jacobian_transpose(0.5 * (qn + qn1));
  if (values) {
    const Mat<kCoords, 6> BmC = Bmt * (chi * C_).asDiagonal();
    Eigen::Map<Mat<kCoords, kCoords>>(values) +=
        L0_ * (BmC.lazyProduct(strain_jacobian_transpose(qn1).transpose()) +
               0.5 * weighted_strain_hessian(S));
  }
  return L0_ * Bmt * S;
}

VecX BeamElement::viscous_force_in_pattern(const VecX& qx, const VecX& qdotx, double cq, double cv,
                                           double* values) const {
  const Q q = as_element_q(qx), v = as_element_q(qdotx);
  const Mat<kCoords, 6> Bt = strain_jacobian_transpose(q);
  const Strain6 etaC = section_.eta * C_;
  const Strain6 Sv = etaC.cwiseProduct(Bt.transpose() * v);  // η C Ė, Ė = B(q) q̇
  if (values) {
    const Mat<kCoords, 6> BC = Bt * etaC.asDiagonal();
    const Mat<kCoords, kCoords> K =
        L0_ * (cv * BC.lazyProduct(Bt.transpose()) +
               cq * (weighted_strain_hessian(Sv) +
                     BC.lazyProduct(strain_jacobian_transpose(v).transpose())));
    Eigen::Map<Mat<kCoords, kCoords>>(values) += K;  // the dense pattern, column-major
  }
  return L0_ * Bt * Sv;
}

MatX BeamElement::mass() const {
  // T = ½ ∫ (A_ρ|φ̇|² + M_ρ¹|ḋ₁|² + M_ρ²|ḋ₂|²) ds with ∫ N_a N_b ds = L₀/6 [[2, 1], [1, 2]]:
  // M = (L₀/6 [[2, 1], [1, 2]]) ⊗ diag(A_ρ, M_ρ¹, M_ρ², 0) ⊗ I₃ (consistent, constant).
  // At a corner node the element's directors are Q P (constructor): m ↦ P m Pᵀ.
  const Vec<4> rho(section_.A_rho, section_.M_rho1, section_.M_rho2, 0.0);
  Block8 m = Block8::Zero();
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
      for (int f = 0; f < 4; ++f)
        m(block(a, f), block(b, f)) = L0_ / 6.0 * (a == b ? 2.0 : 1.0) * rho(f);
  if (!p_.isIdentity(0.0)) m = p_ * m * p_.transpose();
  Mat<kCoords, kCoords> M = Mat<kCoords, kCoords>::Zero();
  for (int b = 0; b < 8; ++b)
    for (int c = 0; c < 8; ++c) M.block<3, 3>(3 * b, 3 * c).diagonal().setConstant(m(b, c));
  return M;
}

BeamElement::Strains BeamElement::strains(const VecX& q) const {
  const Strain6 e = raw_strains(as_element_q(q)) - e0_;
  return {e.head<3>(), e.tail<3>()};
}

BeamElement::Resultants BeamElement::stress_resultants(const VecX& q) const {
  const Strain6 S = C_.cwiseProduct(raw_strains(as_element_q(q)) - e0_);
  return {S.head<3>(), S.tail<3>()};
}

}  // namespace isoflex::elements
