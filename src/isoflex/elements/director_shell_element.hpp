#pragma once
// Bilinear four-node Reissner–Mindlin shell in director form (DNSM-III §4, (38)–(45); Simo–Fox
// stress resultants as in Betsch & Sänger 2009; docs/theory/shell.md). Each node is a director
// node q_a = (φ_a, d_a) ∈ R⁶ (DNSM-III (40)); the element's q = (q_0, …, q_3) ∈ R²⁴, i.e. eight
// 3-vector blocks φ_0, d_0, φ_1, d_1, … . φ and d are interpolated with the bilinear Lagrange
// functions N_a(ξ¹, ξ²) (DNSM-III (39)); the interpolated director is not a unit vector between
// the nodes (the constraint (41) lives at the nodes only).
//
// Strains in natural (covariant) components, ( ),α = ∂/∂ξ^α, reference values from q₀ subtracted:
//   ε_αβ = ½(φ,α·φ,β − Φ,α·Φ,β),  κ_αβ = ½(φ,α·d,β + φ,β·d,α) − (same with Φ, D),
//   γ_α = φ,α·d − Φ,α·D,  the last one by assumed natural strains (MITC4) if requested;
// the in-plane shear by an assumed strain too (the Cartesian membrane shear at the Gauss points
// replaced by its value at the element centre, docs/theory/shell.md §3.1) if requested.
// Each of them, at each Gauss point, is a quadratic form ½ qᵀ (h_k ⊗ I₃) q − E_k⁰ with a constant
// 8 × 8 matrix h_k over the eight blocks; the assumed strains only combine such forms with
// constant coefficients. That is what keeps the average-strain discrete gradient exact and the
// element objective.
//
// Stored energy V = ∫ W dA (2 × 2 Gauss on the reference surface) with
// W = ½(n^{αβ} ε_αβ + m^{αβ} κ_αβ + q^α γ_α), minus the gravity work ρh ∫ g·φ dA.
// Kinetic energy T = ½ ∫ ρh (|φ̇|² + (h²/12)|ḋ|²) dA (consistent, constant mass matrix).
#include <array>

#include "isoflex/elements/element.hpp"

namespace isoflex::elements {

struct ShellMaterial {
  double E = 0, nu = 0, thickness = 0, density = 0;
  double shear_correction = 5.0 / 6.0;  // κ_s in q^α = κ_s G h A^{αβ} γ_β
  double eta = 0.0;  // Kelvin–Voigt damping factor η: viscous resultants η C (ε̇, κ̇, γ̇)
};

class DirectorShellElement final : public Element {
 public:
  // Node coordinates q = (φ, d) ∈ R⁶ per node (DNSM-III (40)), stacked in node order: 24 entries.
  // Nodes counter-clockwise, natural coordinates (ξ¹, ξ²) = (−1,−1), (1,−1), (1,1), (−1,1).
  // q0: reference configuration (unit directors D_a, typically the mid-surface normals at the
  // nodes). assumed_shear: true = ANS/MITC4 transverse shear (default); false = plain 2×2
  // integration (locks; for tests only). assumed_membrane_shear: true = the in-plane shear of
  // docs/theory/shell.md §3.1 (default: no parasitic in-plane shear); false = the membrane strains
  // at the Gauss points (too stiff in in-plane bending; for tests only). Throws
  // std::invalid_argument for bad material data, non-unit reference directors, a degenerate element
  // or a director on the wrong side of the reference surface (nodes not counter-clockwise seen from
  // the director tips).
  DirectorShellElement(const std::array<int, 4>& nodes, const Vec<24>& q0, const ShellMaterial& m,
                       const Vec3& gravity, bool assumed_shear = true,
                       bool assumed_membrane_shear = true);

  const std::vector<int>& nodes() const override { return nodes_; }
  // Strain energy − gravity work (ρh ∫ g·φ dA).
  double potential(const VecX& q) const override;
  VecX gradient(const VecX& q) const override;  // 24
  // Average-strain discrete gradient (docs/theory/shell.md §5), 24 (+ 24 × 24, not symmetric).
  VecX discrete_gradient(const VecX& qn, const VecX& qn1, MatX* dv_dqn1) const override;
  // Ê on every strain of every Gauss point (assumed strains included); the tangent
  // ½ Σ_k Ŝ_k H_k + ½ B(q_{n+½})ᵀ C B(qₙ₊₁) with Ŝ = C ½(E(qₙ) + Ê).
  VecX mixed_discrete_gradient_in_pattern(const VecX& qn, const VecX& qn1, const VecX* q_lin,
                                          double* values, VecX* stress_force) const override;
  MatX mass() const override;  // 24 × 24, constant, consistent
  // Kelvin–Voigt viscous force f_v = B(q)ᵀ η C B(q) q̇ over the Gauss points (the strain rates
  // with the stiffnesses times η, assumed strains included; docs/theory/shell.md §11); B linear in
  // q, so ∂f_v/∂q = Σ_k S_v,k H_k + Bᵀ η C B(q̇) and ∂f_v/∂q̇ = Bᵀ η C B.
  bool viscous() const override { return material_.eta > 0.0; }
  VecX viscous_force_in_pattern(const VecX& q, const VecX& qdot, double cq, double cv,
                                double* values) const override;
  // Algorithmic stress χ C (ΔEₙ₊₁ − r ΔEₙ) on every strain of every Gauss point (assumed strains
  // included); ∂f_d/∂qₙ₊₁ = ½ Σ_k S_d,k H_k + B(q_{n+½})ᵀ χ C B(qₙ₊₁).
  bool strain_dissipation() const override { return true; }
  VecX strain_dissipation_force_in_pattern(const VecX& q_prev, const VecX& qn, const VecX& qn1,
                                           double chi, double ratio, double* values) const override;
  VecX mixed_strain_dissipation_force_in_pattern(const VecX& q_prev, const VecX& qn,
                                                 const VecX& qn1, const VecX* q_lin, double chi,
                                                 double ratio, double* values,
                                                 VecX* stress_force) const override;
  // Strain-energy Hessian (24 × 24) at q (for linear analysis and tests).
  Mat<24, 24> stiffness(const Vec<24>& q) const;
  double reference_area() const { return area_; }
  // ∫ N_a dA (a = 0..3) and ∫ N_a N dA with N the reference unit normal, for dead area loads and
  // pressure.
  Vec<4> nodal_areas() const { return nodal_areas_; }
  Mat<3, 4> nodal_normal_areas() const { return nodal_normal_areas_; }

  struct Resultants {
    Mat3 frame;  // columns e₁, e₂ (tangent plane, e₁ along Φ,₁) and e₃ the reference normal, at
                 // the element centre
    Eigen::Matrix2d n;  // membrane forces n^{αβ} in the frame (e₁, e₂), per unit length
    Eigen::Matrix2d m;  // bending moments m^{αβ}, per unit length
    Eigen::Vector2d q;  // transverse shear forces q^α
  };
  Resultants stress_resultants(const Vec<24>& q) const;  // at the element centre (ξ = 0)

 private:
  static constexpr int kCoords = 24;
  static constexpr int kGauss = 4;
  // Per evaluation point: ε₁₁, ε₂₂, ε₁₂, κ₁₁, κ₂₂, κ₁₂, γ₁, γ₂.
  static constexpr int kPointStrains = 8;
  static constexpr int kStrains = kGauss * kPointStrains;  // 32
  using Q = Vec<kCoords>;
  using Block8 = Mat<8, 8>;
  using StrainForms = std::array<Block8, kPointStrains>;
  using Strains = Vec<kStrains>;
  using Jacobian = Mat<kStrains, kCoords>;

  // B(q) = ∂E/∂q over all Gauss points; row k = ((h_k ⊗ I₃) q)ᵀ, linear in q.
  Jacobian strain_jacobian(const Q& q) const;
  // Σ_k S_k (h_k ⊗ I₃) = (Σ_k S_k h_k) ⊗ I₃.
  Mat<kCoords, kCoords> weighted_strain_hessian(const Strains& S) const;
  // Σ_g B_lᵀ C_g B_r over the Gauss points (C block diagonal).
  Mat<kCoords, kCoords> material_stiffness(const Jacobian& Bl, const Jacobian& Br) const;
  // Quadrature-weighted stresses S = C E (the weights w_g j_g are in C).
  Strains stresses(const Strains& e) const;
  // Ê + E⁰ of mixed_discrete_gradient_in_pattern: E(q_l) + B(q_l)(qₙ₊₁ − q_l) + E⁰, or en (the
  // strains of qₙ plus E⁰) at a start.
  Strains estimated_strains(const Q& qn1, const VecX* q_lin, const Strains& en) const;
  // f_d of strain_dissipation_force_in_pattern; mixed: its geometric part with Ê.
  VecX dissipation(const VecX& q_prev, const VecX& qn, const VecX& qn1, const VecX* q_lin,
                   bool mixed, double chi, double ratio, double* values, VecX* stress_force) const;
  Vec<kCoords> gravity_gradient() const;
  static Q as_element_q(const VecX& q);

  std::vector<int> nodes_;
  ShellMaterial material_;
  Vec3 g_;
  std::array<Block8, kStrains> h_;  // strain forms at the Gauss points (ANS already applied)
  std::array<Block8, kGauss> C_;    // w_g j_g · blockdiag(membrane, bending, shear) at point g
  Strains e0_;                      // raw strains of q₀
  StrainForms h_centre_;            // strain forms at ξ = 0, for the resultant output
  Vec<kPointStrains> e0_centre_;
  Eigen::Matrix2d A_inv_centre_;  // A^{αβ} at ξ = 0
  Eigen::Matrix2d T_centre_;      // T(i, α) = e_i·Φ,α at ξ = 0
  Mat3 frame_centre_;
  double area_ = 0.0;
  Vec<4> nodal_areas_;
  Mat<3, 4> nodal_normal_areas_;
  Mat<4, 4> mass_n_;  // ∫ N_a N_b dA
};

}  // namespace isoflex::elements
