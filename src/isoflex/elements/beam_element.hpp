#pragma once
// Two-node geometrically exact (Simo–Reissner) beam in director form (DNSM-III §3, (17)–(19);
// Betsch & Steinmann 2002; docs/theory/beam.md). Each node is a frame node
// q_α = (φ, d₁, d₂, d₃) ∈ R¹²; the element's q = (q_a, q_b) ∈ R²⁴. φ and d_i are interpolated
// linearly (DNSM-III (18)); the interpolated directors are not orthonormal between the nodes.
//
// Strains in director components at the element midpoint only (one-point integration against
// shear locking), with ′ = d/ds, s the reference arc length of the chord, L₀ = |φ_b⁰ − φ_a⁰|:
//   Γ_i = d_i·φ′ − Γ_i⁰,   K_i = ½ ε_ijk d_k·d_j′ − K_i⁰
// (K₁ = ½(d₃·d₂′ − d₂·d₃′) etc.; with d_j′ = κ × d_j, κ = K_i d_i this K is the curvature vector
// in director components). Γ⁰, K⁰ are the same expressions at the reference q₀, so an initially
// curved (or twisted, or sheared) reference is stress free. Every strain is a quadratic form in q:
// E_k(q) = ½ qᵀ H_k q − E_k⁰ with H_k = h_k ⊗ I₃ and h_k a constant 8 × 8 matrix over the eight
// 3-vector blocks of q. That is what makes the average-strain discrete gradient exact.
//
// Stored energy (St. Venant–Kirchhoff, DNSM-III (69)): V = ½ L₀ (Γᵀ C_Γ Γ + Kᵀ C_K K),
// C_Γ = diag(GA₁, GA₂, EA), C_K = diag(EI₁, EI₂, GJ) — d₃ is the beam axis in the reference, so
// Γ₃ is the axial strain and K₃ the twist. Gravity V_g = −∫ A_ρ g·φ ds.
// Kinetic energy T = ½ ∫ (A_ρ |φ̇|² + M_ρ¹ |ḋ₁|² + M_ρ² |ḋ₂|²) ds: d₃ carries no inertia.
#include <array>
#include <optional>
#include <vector>

#include "isoflex/elements/element.hpp"
#include "isoflex/math/frame_node.hpp"

namespace isoflex::elements {

// Cross-section data (per unit reference length). EI₁ pairs with K₁ (bending about d₁), EI₂ with
// K₂ (bending about d₂). M_ρ^κ = ∫ ρ (ζ^κ)² dA is the inertia weight of d_κ (DNSM-III (17)), so a
// spin ω about the axis has kinetic energy ½ (M_ρ¹ + M_ρ²) ω² per length.
struct BeamSection {
  double EA = 0.0;      // axial stiffness, pairs with Γ₃
  double GA1 = 0.0;     // shear stiffness along d₁, pairs with Γ₁
  double GA2 = 0.0;     // shear stiffness along d₂, pairs with Γ₂
  double EI1 = 0.0;     // bending stiffness about d₁, pairs with K₁
  double EI2 = 0.0;     // bending stiffness about d₂, pairs with K₂
  double GJ = 0.0;      // torsional stiffness, pairs with K₃
  double A_rho = 0.0;   // mass per reference length A_ρ
  double M_rho1 = 0.0;  // ∫ ρ (ζ¹)² dA, inertia of d₁
  double M_rho2 = 0.0;  // ∫ ρ (ζ²)² dA, inertia of d₂
  double eta = 0.0;     // Kelvin–Voigt damping factor η: viscous resultants η C (Γ̇, K̇)
};

class BeamElement final : public Element {
 public:
  static constexpr int kCoords = 2 * frame_node::kCoords;  // 24
  using Q = Vec<kCoords>;

  // Strains Γ, K in director components (reference values already subtracted).
  struct Strains {
    Vec3 Gamma;
    Vec3 K;
  };
  // Stress resultants n = C_Γ Γ (shear and axial force), m = C_K K (bending and torsional
  // moment), in director components (DNSM-III (69)).
  struct Resultants {
    Vec3 n;
    Vec3 m;
  };

  // node_a, node_b: system indices; q0_a, q0_b: reference frame nodes (orthonormal triads,
  // distinct positions). Throws std::invalid_argument for a zero length, non-orthonormal
  // reference triads, non-positive stiffnesses or negative inertia data.
  //
  // triad_a, triad_b (default: the node's own): the element's reference triad at the node,
  // [d̃₁ d̃₂ d̃₃] as columns (orthonormal). The element's directors there are the constant
  // combinations d̃ᵢ = Σⱼ Rᵢⱼ dⱼ of the node's, R = triadᵀ D⁰ (D⁰ the node's reference triad): a
  // node shared with an element of another direction — the corner of a polyline — is a rigid
  // corner, the two elements' triads keep their angle (docs/theory/beam.md §7). The strains stay
  // quadratic in the node coordinates (h_k ↦ P h_k Pᵀ), so every property of the element holds
  // as before.
  BeamElement(int node_a, int node_b, const frame_node::Q& q0_a, const frame_node::Q& q0_b,
              const BeamSection& section, const Vec3& gravity = Vec3::Zero(),
              const std::optional<Mat3>& triad_a = std::nullopt,
              const std::optional<Mat3>& triad_b = std::nullopt);

  const std::vector<int>& nodes() const override { return nodes_; }
  double potential(const VecX& q) const override;
  VecX gradient(const VecX& q) const override;
  // Average-strain discrete gradient (docs/theory/beam.md §4):
  // DV = L₀ B(q_{n+½})ᵀ C ½(E(qₙ) + E(qₙ₊₁)) + ∇V_g, exact in the sense of Gonzalez.
  VecX discrete_gradient(const VecX& qn, const VecX& qn1, MatX* dv_dqn1) const override;
  using Strain6 = Vec<6>;  // (Γ₁, Γ₂, Γ₃, K₁, K₂, K₃)
  // The strains of (69) before the reference strains Γ⁰, K⁰ are subtracted.
  Strain6 raw_strains(const Q& q) const;
  // The same in fixed sizes, without heap allocation (the reparametrized block assembly,
  // integrate/reduced_newton_matrix.hpp, calls it once per element and Newton iteration).
  // strains_n: raw_strains(qn), if the caller keeps it (qn is the same for a whole step).
  void discrete_gradient(const Q& qn, const Q& qn1, Q& dv, Mat<kCoords, kCoords>* dv_dqn1,
                         const Strain6* strains_n = nullptr) const;
  MatX mass() const override;
  // Kelvin–Voigt viscous force f_v = L₀ B(q)ᵀ η C B(q) q̇ (the strain rates Ė = B(q) q̇ with the
  // stiffnesses times η; docs/theory/beam.md §9). B is linear in q, so ∂(B(q) q̇)/∂q = B(q̇):
  // ∂f_v/∂q = L₀ (Σ_k S_v,k H_k + Bᵀ η C B(q̇)), ∂f_v/∂q̇ = L₀ Bᵀ η C B.
  bool viscous() const override { return section_.eta > 0.0; }
  // Numerical dissipation (docs/theory/schemes.md §10): χ C (ΔEₙ₊₁ − r ΔEₙ) on Γ and K at the
  // midpoint, f_d = L₀ B(q_{n+½})ᵀ S_d, ∂f_d/∂qₙ₊₁ = L₀ (½ Σ_k S_d,k H_k + B(q_{n+½})ᵀ χ C
  // B(qₙ₊₁)).
  bool strain_dissipation() const override { return true; }
  VecX strain_dissipation_force_in_pattern(const VecX& q_prev, const VecX& qn, const VecX& qn1,
                                           double chi, double ratio, double* values) const override;
  VecX viscous_force_in_pattern(const VecX& q, const VecX& qdot, double cq, double cv,
                                double* values) const override;

  // Exact Hessian of V (for static solvers and tests).
  Mat<kCoords, kCoords> hessian(const VecX& q) const;

  Strains strains(const VecX& q) const;
  Resultants stress_resultants(const VecX& q) const;

  double reference_length() const { return L0_; }
  const BeamSection& section() const { return section_; }
  // Γ⁰, K⁰: the strain expressions evaluated at the reference configuration.
  Strains reference_strains() const { return {e0_.head<3>(), e0_.tail<3>()}; }

 private:
  using Block8 = Mat<8, 8>;
  // A nonzero h_k(b, c) of a strain form: Bᵀ(3c + i, k) += h q(3b + i), i = 0, 1, 2, with
  // in = 3b and out = 24k + 3c the offsets in q and in Bᵀ's storage.
  struct Entry {
    int in, out;
    double h;
  };
  // A 3-vector of Bᵀ (block c of column k) with one or two entries: h0 q(in0) [+ h1 q(in1)].
  struct SlotEntries {
    int out, in0, in1;
    double h0, h1;
  };

  // B(q)ᵀ, B(q) = ∂E/∂q the strain Jacobian (row k = (H_k q)ᵀ, linear in q), stored as its
  // transpose: column k is H_k q, built from contiguous 3-vectors.
  Mat<kCoords, 6> strain_jacobian_transpose(const Q& q) const;
  // Σ_k S_k H_k = (Σ_k S_k h_k) ⊗ I₃.
  Mat<kCoords, kCoords> weighted_strain_hessian(const Strain6& S) const;
  Vec<kCoords> gravity_gradient() const;
  static Q as_element_q(const VecX& q);

  std::vector<int> nodes_;
  BeamSection section_;
  Vec3 g_;
  double L0_;
  std::array<Block8, 6> h_;  // DNSM-III (18) with one-point quadrature: E_k = ½ Σ h_k(b,c) q_b·q_c
  Strain6 C_;                // diag(GA₁, GA₂, EA, EI₁, EI₂, GJ), DNSM-III (69)
  Strain6 e0_;               // Γ⁰, K⁰
  Block8 p_;                 // the element's blocks from the nodes' (identity but at a corner)
  // The nonzeros of h_0 … h_5, in order. h_k couples four of the eight blocks (eight to sixteen
  // of its 64 entries are nonzero), so B(q) from them costs a fifth of the dense 3 × 8 by 8 × 8
  // products.
  std::vector<Entry> entries_;
  // entries_ by their 3-vector of Bᵀ, where none has more than two (without corner triads: the
  // Γ_i and K_i are sums of products of two blocks), else all three empty.
  std::vector<SlotEntries> pairs_, singles_;
  std::vector<int> zero_slots_;  // the 3-vectors of Bᵀ without entries
};

}  // namespace isoflex::elements
