#pragma once
// Prescribed motions of joints (joints `driver`, docs/theory/joints.md §Drivers): rheonomic rows
// Φ(q) = d(t) (joints/constraint.hpp) held at every time node t_{n+1} of the energy–momentum
// schemes (DNSM-III (9), (11), (14) with the rows' right-hand side at t_{n+1}; IGA-thesis
// (3.37)–(3.40) for prescribed motions by multipliers), their multiplier the driving torque or
// force.
//
//   revolute:   θ(q) = f(t), θ the angle of b about the axis relative to a, counted across turns
//               (elements/revolute_angle.hpp, as the joint's spring measures it), 0 at t = 0;
//               one row, not quadratic: its discrete derivative is Gonzalez's Dθ(qₙ, qₙ₊₁),
//               Dθ·Δq = θ(qₙ₊₁) − θ(qₙ) exactly;
//   prismatic:  s(q) = f(t), s = a₃·(x_b − x_a) the slide of b's joint point along the axis of a
//               (elements/frame_pair.hpp), 0 at t = 0; one row, quadratic: G(q_{n+½}) is exact;
//   spherical to the ground: the joint's own rows x_b − p₀ = p(t) − p₀ (joints::JointRows with a
//               prescribed right-hand side), p(t) the ground point's position.
//
// The driver rows are loop-closing ("cut") rows in every formulation: the revolute and prismatic
// joints stay tree joints (their other rows are eliminated by the reparametrization), the driver
// row is an n-ary constraint kept with its multiplier (the implicit null space (13) in the
// reduced schemes); a spherical joint with a moving point is itself a cut joint. With the
// exact discrete derivative, the constraint forces G̃ᵀλ do the work −λ·(d(tₙ₊₁) − d(tₙ)) in a
// step and nothing else: E − W_driver stays constant to the Newton tolerance (history.csv
// `driver_work`). The driving torque (force) on body_b about (along) the axis is −λ.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "isoflex/elements/frame_pair.hpp"
#include "isoflex/elements/revolute_angle.hpp"
#include "isoflex/joints/constraint.hpp"
#include "isoflex/loads/time_function.hpp"

namespace isoflex::system {

// How far a driver's value at t = 0 may be from the configuration at t = 0 (rad, length; a point
// driver: times max(1, |p₀|)): the joints' own assembly tolerance (System::check_assembled).
inline constexpr double kDriverTolerance = 1e-9;

class JointDriver final : public joints::Constraint {
 public:
  enum class Coordinate { angle, slide };
  // The angle or the slide of the pair's frame b relative to a (a on body_a's side; nodes: the
  // frame nodes of body_a and body_b that are not the ground, in that order), prescribed as the
  // time function `expression`. Throws std::invalid_argument when the angle is undefined at q0
  // or the expression is malformed.
  JointDriver(std::vector<int> nodes, const elements::FramePair& pair, Coordinate coordinate,
              const VecX& q0, const std::string& expression);

  Coordinate coordinate() const { return coordinate_; }
  // θ(q_c) (on the branch of the accepted angle) or s(q_c).
  double value(CRef q_c) const;
  const std::string& expression() const { return f_.expression(); }

  const std::vector<int>& nodes() const override { return nodes_; }
  int constraint_count() const override { return 1; }
  VecX constraints(CRef q_c) const override;
  MatX jacobian(CRef q_c) const override;
  void add_constraint_hessian(CRef q_c, CRef lambda, MatX& H) const override;
  // angle: Gonzalez's Dθ(q_a, q_b); slide: ∇s at the midpoint (exact, s quadratic).
  MatX discrete_jacobian(CRef q_a, CRef q_b) const override;
  bool rheonomic() const override { return true; }
  VecX prescribed(double t) const override;
  void accept(CRef q_c) const override;

 private:
  std::vector<int> nodes_;
  Coordinate coordinate_;
  std::optional<elements::RevoluteAngle> angle_;
  elements::QuadraticInvariant slide_;
  loads::TimeFunction f_;
};

}  // namespace isoflex::system
