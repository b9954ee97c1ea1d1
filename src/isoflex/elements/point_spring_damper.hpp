#pragma once
// A spring–damper between two material points (IGA-thesis (6.8)–(6.9)): a rigid-body point, a
// beam or director-shell node's point, a point of a Kirchhoff–Love patch (Σ R_A x_A) or a fixed
// point of the ground. Every such point is linear in its nodes' coordinates, x_i = P_i q + c_i
// (docs/theory/coupling.md §1), so the difference d = x₁ − x₂ = D q + e and ζ² = |d|² is quadratic
// in q. The spring's energy V = ½ k (ζ − L)² (free length L) is a function of ζ², and its discrete
// gradient is the one for a quadratic invariant (Gonzalez; DNSM-III (17)–(19)):
//   DV(qₙ, qₙ₊₁) = W̄′ 2 Dᵀ d_{n+½},  W̄′ = (W(ζ²ₙ₊₁) − W(ζ²ₙ)) / (ζ²ₙ₊₁ − ζ²ₙ) = ½ k (1 − 2L/(ζₙ +
//   ζₙ₊₁)),
// the difference quotient written without cancellation; DV·Δq = ΔV exactly, and the force, along
// d_{n+½}, keeps both momenta. The damper f = c ζ̇ along the line is a viscous force
// (Element::viscous_force_in_pattern): its power c ζ̇² ≥ 0 is what it dissipates.
//
// Nonlinear laws (docs/theory/coupling.md §6): a spring force N(e) of the elongation e = ζ − L
// with its energy V = ∫₀^e N (elements/force_law.hpp) has the same discrete gradient with
// W̄′ = N̄ / (ζₙ + ζₙ₊₁), N̄ = (V(eₙ₊₁) − V(eₙ)) / (eₙ₊₁ − eₙ) (since Δe = Δζ); a damper force
// N_d(ζ̇) along the line dissipates N_d(ζ̇) ζ̇, ≥ 0 when the law is dissipative (v N_d(v) ≥ 0,
// which the model reader checks on samples).
#include <string>
#include <vector>

#include "isoflex/elements/element.hpp"
#include "isoflex/elements/force_law.hpp"

namespace isoflex::elements {

// x = P q_e + c over the element's stacked coordinates q_e.
struct MaterialPointMap {
  Eigen::Matrix<double, 3, Eigen::Dynamic> P;
  Vec3 c = Vec3::Zero();
};

struct SpringDamperLaw {
  double stiffness = 0.0;    // k ≥ 0
  double damping = 0.0;      // c ≥ 0
  double free_length = 0.0;  // L ≥ 0
  // Nonlinear laws instead of k and c: N(e) in the elongation e, N_d(v) in the rate v (muParser
  // expressions; empty: the linear law).
  std::string stiffness_law, damping_law;
};

class PointSpringDamper final : public Element {
 public:
  // Throws std::invalid_argument for maps of a size other than 3 × (coordinates of nodes), a
  // negative or non-finite law, an invalid law expression, or points that coincide where the
  // spring has a free length, a nonlinear law or a damper (the line of action is undefined
  // there).
  PointSpringDamper(std::vector<int> nodes, int coordinates, MaterialPointMap a, MaterialPointMap b,
                    SpringDamperLaw law, const VecX& q0);

  const std::vector<int>& nodes() const override { return nodes_; }
  double potential(const VecX& q) const override;
  VecX gradient(const VecX& q) const override;
  VecX discrete_gradient(const VecX& qn, const VecX& qn1, MatX* dv_dqn1) const override;
  MatX mass() const override { return MatX::Zero(n_, n_); }
  SpMat sparse_mass() const override { return SpMat(n_, n_); }

  bool viscous() const override { return law_.damping > 0.0 || !damper_.linear(); }
  VecX viscous_force_in_pattern(const VecX& q, const VecX& qdot, double cq, double cv,
                                double* values) const override;

  const SpringDamperLaw& law() const { return law_; }
  // Moves end `end` (0: a, 1: b), a point of the ground (its map P = 0), to `point`, moving at
  // `velocity`: the anchor of a co-simulation (integrate/cosimulation.hpp), held over a step.
  // The rate ζ̇ and the damper then see the anchor's velocity.
  void move_anchor(int end, const Vec3& point, const Vec3& velocity);
  // The distance ζ = |x₁ − x₂|, its rate ζ̇ and the force N(ζ − L) + N_d(ζ̇) (tension > 0).
  double length(const VecX& q) const;
  double rate(const VecX& q, const VecX& qdot) const;
  double force(const VecX& q, const VecX& qdot) const;
  // The energy and the force at the distance ζ and the rate ζ̇ (the co-simulation's true values
  // of a spring whose ends live in two systems).
  double energy_at(double length) const { return spring_.energy(length - law_.free_length); }
  double force_at(double length, double rate) const {
    return spring_.force(length - law_.free_length) + damper_.force(rate);
  }

 private:
  Vec3 difference(const VecX& q) const { return D_ * q + e_; }
  std::vector<int> nodes_;
  int n_;
  Eigen::Matrix<double, 3, Eigen::Dynamic> D_;
  Vec3 e_;
  Vec3 ca_, cb_;           // the ends' constants, e = c_a − c_b
  Vec3 w_ = Vec3::Zero();  // the anchor's part of ḋ: ḋ = D q̇ + w
  SpringDamperLaw law_;
  ForceLaw spring_, damper_;
};

}  // namespace isoflex::elements
