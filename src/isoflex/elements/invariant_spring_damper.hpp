#pragma once
// Linear springs and dampers on strains that are quadratic in the coordinates (docs/theory/
// coupling.md §7–§8): e = π(q) − π(q₀), π quadratic invariants of two frames (elements/
// frame_pair.hpp). The bushing has the six strains (u₁, u₂, u₃, θ₁, θ₂, θ₃) of its frames; the
// spring of a prismatic joint the one slide u₃ − s₀.
//
// Energy V = ½ eᵀ K e (K symmetric positive semi-definite). Because every strain is quadratic,
// ∇e(q_{n+½}) Δq = Δe exactly, and the discrete gradient
//   DV(qₙ, qₙ₊₁) = ∇e(q_{n+½})ᵀ K ½ (eₙ + eₙ₊₁)
// satisfies DV·Δq = Δeᵀ K ē = ½ (eₙ₊₁ᵀ K eₙ₊₁ − eₙᵀ K eₙ) = ΔV exactly (DNSM-III (17)); it is
// symmetric in its arguments, and the strains being invariant under rigid motions of the pair,
// its forces have no resultant and no moment at the midpoint: both momenta are kept.
// Damping: the viscous force f_v = ∇e(q)ᵀ C ė, ė = ∇e(q) q̇ (C symmetric positive
// semi-definite), whose power ėᵀ C ė ≥ 0 is what it dissipates (Element::viscous).
#include <vector>

#include "isoflex/elements/element.hpp"
#include "isoflex/elements/frame_pair.hpp"

namespace isoflex::elements {

class InvariantSpringDamper final : public Element {
 public:
  // strains.size() × strains.size() matrices K and C; the strains are measured from their values
  // at q0 plus `offsets` (e = π(q) − π(q₀) − offsets; empty: none). Throws std::invalid_argument
  // for sizes that do not match.
  InvariantSpringDamper(std::vector<int> nodes, std::vector<QuadraticInvariant> strains,
                        const MatX& K, const MatX& C, const VecX& q0, const VecX& offsets = {});

  const std::vector<int>& nodes() const override { return nodes_; }
  double potential(const VecX& q) const override;
  VecX gradient(const VecX& q) const override;
  VecX discrete_gradient(const VecX& qn, const VecX& qn1, MatX* dv_dqn1) const override;
  MatX mass() const override { return MatX::Zero(n_, n_); }
  SpMat sparse_mass() const override { return SpMat(n_, n_); }

  bool viscous() const override { return viscous_; }
  VecX viscous_force_in_pattern(const VecX& q, const VecX& qdot, double cq, double cv,
                                double* values) const override;

  // The strains e(q), their rates ė = ∇e(q) q̇ and the forces K e + C ė (forces.csv).
  VecX strains(const VecX& q) const;
  VecX strain_rates(const VecX& q, const VecX& qdot) const { return strain_gradient(q) * qdot; }
  VecX forces(const VecX& q, const VecX& qdot) const {
    return K_ * strains(q) + C_ * strain_rates(q, qdot);
  }

 private:
  MatX strain_gradient(const VecX& q) const;  // rows ∇e_iᵀ
  std::vector<int> nodes_;
  int n_;
  std::vector<QuadraticInvariant> pi_;
  VecX pi0_;
  MatX K_, C_;
  bool viscous_;
};

}  // namespace isoflex::elements
