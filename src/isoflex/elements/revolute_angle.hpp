#pragma once
// The angle θ of frame b about the joint axis a₃ relative to frame a, counted across turns
// (docs/theory/coupling.md §8), and its discrete derivative: what a revolute joint's spring
// (elements/revolute_spring.hpp) and its driver (system/joint_drivers.hpp) measure.
//
// The angle enters through two invariants quadratic in q (elements/frame_pair.hpp),
// π = (c, s) = (a₁·b₁, a₂·b₁) = (cos θ, sin θ) in the joint, θ = atan2(s, c) + 2π m. Its
// discrete derivative is built in the plane of the invariants (Gonzalez 1996): with
// π̄ = ½ (πₙ + πₙ₊₁), Δπ = πₙ₊₁ − πₙ,
//   D_πθ = ∇θ(π̄) + [(Δθ − ∇θ(π̄)·Δπ) / |Δπ|²] Δπ,  so D_πθ·Δπ = Δθ exactly,
//   Dθ(qₙ, qₙ₊₁) = ∇π(q_{n+½})ᵀ D_πθ,  so Dθ·Δq = Δπ·D_πθ = Δθ exactly (π quadratic).
// Dθ lies in the span of ∇π(q_{n+½}), orthogonal to the rigid motions of the pair at the midpoint.
// Δθ is the angle from πₙ to πₙ₊₁, atan2(πₙ × πₙ₊₁, πₙ·πₙ₊₁) (a step turns less than π). Below
// |Δπ| = 1e-5 |π̄| the correction, O(|Δπ|²), is dropped (error O(|Δπ|³), below round-off); it is
// computed without 0/0 above.
//
// The branch m (the turns) is the one piece of history: the angle last accepted (accept, after
// every converged step) picks the branch nearest to it, so θ(q) is continuous along a motion
// whose steps turn less than π. It starts at the configuration given to the constructor
// (θ = atan2(s, c) there, 0 for a joint assembled at t = 0).
#include "isoflex/elements/frame_pair.hpp"
#include "isoflex/math/types.hpp"

namespace isoflex::elements {

class RevoluteAngle {
 public:
  // c = a₁·b₁ and s = a₂·b₁ of the pair. Throws std::invalid_argument for (c, s) = 0 at q0 or q0
  // of another size than the pair's.
  RevoluteAngle(const FramePair& frames, const VecX& q0);

  int size() const { return n_; }
  // θ(q) on the branch nearest the accepted angle.
  double angle(const VecX& q) const;
  // Makes the angle at q the reference of the branch (a converged step).
  void accept(const VecX& q) const { reference_ = angle(q); }
  // ∇θ(q) and ∇²θ(q) (if H is not null).
  VecX gradient(const VecX& q, MatX* H) const;

  // The discrete derivative Dθ(qₙ, qₙ₊₁) (header) with θ(qₙ), Δθ and, if asked, ∂Dθ/∂qₙ₊₁ and
  // ∇θ(qₙ₊₁).
  struct Discrete {
    double theta_n = 0.0, dtheta = 0.0;
    VecX D;
    MatX dD_dqn1;  // filled when asked
    VecX gradient_n1;
  };
  Discrete discrete(const VecX& qn, const VecX& qn1, bool derivative) const;

 private:
  using Vec2 = Vec<2>;
  using Mat2 = Mat<2, 2>;
  Vec2 invariants(const VecX& q) const { return {c_.value(q), s_.value(q)}; }
  Mat<2, Eigen::Dynamic> invariant_gradient(const VecX& q) const;
  double angle(const Vec2& pi) const;
  // ∇θ and its Hessian in the (c, s) plane.
  static Vec2 angle_gradient(const Vec2& pi);
  static Mat2 angle_hessian(const Vec2& pi);

  int n_;
  QuadraticInvariant c_, s_;
  mutable double reference_ = 0.0;  // the accepted angle
};

}  // namespace isoflex::elements
