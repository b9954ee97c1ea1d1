#pragma once
// The rotational spring–damper of a revolute joint (joints `spring`; docs/theory/coupling.md §8):
// V = ½ k (θ − θ₀)², the moment −k (θ − θ₀) − c θ̇ about the axis, θ the angle of frame b about
// the joint axis a₃ relative to frame a, counted across turns.
//
// The angle and its discrete derivative Dθ (Gonzalez 1996, exact: Dθ·Δq = Δθ) are
// elements/revolute_angle.hpp's; DV = k (θ̄ − θ₀) Dθ with θ̄ = ½ (θₙ + θₙ₊₁) (V quadratic in θ):
// DV·Δq = ΔV. The forces lie in the span of ∇π(q_{n+½}), orthogonal to the rigid motions at the
// midpoint: momenta kept. The branch of the angle (the turns) is the element's one piece of
// history, kept by Element::accept.
#include <vector>

#include "isoflex/elements/element.hpp"
#include "isoflex/elements/frame_pair.hpp"
#include "isoflex/elements/revolute_angle.hpp"

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
  void accept(const VecX& q) const override { angle_.accept(q); }

  // θ(q) on the branch nearest the accepted angle.
  double angle(const VecX& q) const;
  // θ̇ = ∇θ(q)·q̇ and the moment k (θ − θ₀) + c θ̇ about the axis (forces.csv).
  double rate(const VecX& q, const VecX& qdot) const;
  double moment(const VecX& q, const VecX& qdot) const;
  double free_angle() const { return free_angle_; }

 private:
  std::vector<int> nodes_;
  int n_;
  RevoluteAngle angle_;
  double stiffness_, damping_, free_angle_;
};

}  // namespace isoflex::elements
