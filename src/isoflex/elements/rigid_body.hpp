#pragma once
// Rigid body in director form (DNSM-III (15)–(16); docs/theory/rigid-body.md): one frame node at
// the centre of mass with the principal axes as directors.
// Kinetic energy T = ½ m |φ̇|² + ½ Σ E_I |ḋ_I|², E_I = ½(J₁ + J₂ + J₃) − J_I (Euler tensor in the
// principal frame), so M = diag(m, E₁, E₂, E₃) ⊗ I₃ is constant. Gravity: V = −m g·φ (linear, so
// the discrete gradient is the gradient).
#include "isoflex/elements/element.hpp"

namespace isoflex::elements {

class RigidBody final : public Element {
 public:
  RigidBody(int node, double mass, const Vec3& principal_inertia, const Vec3& gravity);

  const std::vector<int>& nodes() const override { return nodes_; }
  double potential(const VecX& q) const override;
  VecX gradient(const VecX& q) const override;
  VecX discrete_gradient(const VecX& qn, const VecX& qn1, MatX* dv_dqn1) const override;
  void add_discrete_gradient(const VecX& qn, const VecX& qn1, VecX& dv,
                             MatX* dv_dqn1) const override;
  MatX mass() const override;
  // Gravity is linear in q: ∂DV/∂qₙ₊₁ = 0, an empty pattern.
  SpMat pattern() const override { return SpMat(12, 12); }
  VecX discrete_gradient_in_pattern(const VecX& qn, const VecX&, double*) const override {
    return gradient(qn);
  }

  // Euler tensor diagonal E_I from principal moments J_I.
  static Vec3 euler_tensor(const Vec3& J);

 private:
  std::vector<int> nodes_;
  double m_;
  Vec3 E_;
  Vec3 g_;
};

}  // namespace isoflex::elements
