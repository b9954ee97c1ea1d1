#pragma once
// The rotational spring–damper of a revolute joint (joints `spring`; docs/theory/coupling.md §8):
// V = ½ k (θ − θ₀)², the moment −k (θ − θ₀) − c θ̇ about the axis, θ the angle of frame b about
// the joint axis a₃ relative to frame a, counted across turns.
//
// The angle enters through two invariants quadratic in q (elements/frame_pair.hpp),
// π = (c, s) = (a₁·b₁, a₂·b₁) = (cos θ, sin θ) in the joint, θ = atan2(s, c) + 2π m. Its
// discrete gradient is built in the plane of the invariants (Gonzalez 1996): with
// π̄ = ½ (πₙ + πₙ₊₁), Δπ = πₙ₊₁ − πₙ,
//   D_πθ = ∇θ(π̄) + [(Δθ − ∇θ(π̄)·Δπ) / |Δπ|²] Δπ,  so D_πθ·Δπ = Δθ exactly,
//   Dθ(qₙ, qₙ₊₁) = ∇π(q_{n+½})ᵀ D_πθ,  so Dθ·Δq = Δπ·D_πθ = Δθ exactly (π quadratic),
// and DV = k (θ̄ − θ₀) Dθ with θ̄ = ½ (θₙ + θₙ₊₁) (V quadratic in θ): DV·Δq = ΔV. The forces lie
// in the span of ∇π(q_{n+½}), orthogonal to the rigid motions at the midpoint: momenta kept.
// Δθ is the angle from πₙ to πₙ₊₁, atan2(πₙ × πₙ₊₁, πₙ·πₙ₊₁) (a step turns less than π). Below
// |Δπ| = 1e-5 |π̄| the correction, O(|Δπ|²), is dropped (energy error O(|Δπ|³), below
// round-off); it is computed without 0/0 above.
//
// The branch m (the turns) is the element's one piece of history: the angle it last accepted
// (Element::accept, after every converged step) picks the branch nearest to it, so θ(q) is
// continuous along a motion whose steps turn less than π. It starts at the configuration given
// to the constructor (θ = atan2(s, c) there, 0 for a joint assembled at t = 0).
#include <vector>

#include "isoflex/elements/element.hpp"
#include "isoflex/elements/frame_pair.hpp"

namespace isoflex::elements {

class RevoluteSpring final : public Element {
 public:
  // c = a₁·b₁ and s = a₂·b₁ of the pair; stiffness k, damping c ≥ 0, free angle θ₀ (rad, any
  // number of turns). Throws std::invalid_argument for a negative law or (c, s) = 0 at q0.
  RevoluteSpring(std::vector<int> nodes, const FramePair& frames, double stiffness, double damping,
                 double free_angle, const VecX& q0);

  const std::vector<int>& nodes() const override { return nodes_; }
  double potential(const VecX& q) const override;
  VecX gradient(const VecX& q) const override;
  VecX discrete_gradient(const VecX& qn, const VecX& qn1, MatX* dv_dqn1) const override;
  MatX mass() const override { return MatX::Zero(n_, n_); }
  SpMat sparse_mass() const override { return SpMat(n_, n_); }
  bool viscous() const override { return damping_ > 0.0; }
  VecX viscous_force_in_pattern(const VecX& q, const VecX& qdot, double cq, double cv,
                                double* values) const override;
  void accept(const VecX& q) const override { reference_ = angle(q); }

  // θ(q) on the branch nearest the accepted angle.
  double angle(const VecX& q) const;
  // θ̇ = ∇θ(q)·q̇ and the moment k (θ − θ₀) + c θ̇ about the axis (forces.csv).
  double rate(const VecX& q, const VecX& qdot) const;
  double moment(const VecX& q, const VecX& qdot) const;
  double free_angle() const { return free_angle_; }

 private:
  using Vec2 = Vec<2>;
  using Mat2 = Mat<2, 2>;
  Vec2 invariants(const VecX& q) const { return {c_.value(q), s_.value(q)}; }
  Mat<2, Eigen::Dynamic> invariant_gradient(const VecX& q) const;
  double angle(const Vec2& pi) const;
  // ∇θ and its Hessian in the (c, s) plane.
  static Vec2 angle_gradient(const Vec2& pi);
  static Mat2 angle_hessian(const Vec2& pi);
  // ∇θ(q) and ∇²θ(q) (if H is not null).
  VecX angle_gradient(const VecX& q, MatX* H) const;

  std::vector<int> nodes_;
  int n_;
  QuadraticInvariant c_, s_;
  double stiffness_, damping_, free_angle_;
  mutable double reference_ = 0.0;  // the accepted angle (Element::accept)
};

}  // namespace isoflex::elements
