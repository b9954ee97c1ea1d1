#pragma once
// The joint contract (docs/architecture.md, "joints"): constraints between a parent node A (or the
// ground, a frame node at the origin that is not part of q) and a child node B of any node kind,
// with the velocity analysis and the update map that let the spanning forest eliminate them.
//
// Every node has a twist t = (φ̇, ω) ∈ R⁶ in the tree machinery. A frame node's twist is its own
// (q̇ = P_int(q) t, DNSM-III (31)); a director node's ω acts on its director, ḋ = ω × d, so its
// P_int(q) = [I 0; 0 −d̂] has the drilling part ω ∥ d in its kernel (DNSM-III (68)). The
// drilling part still matters for what hangs below the node: a shell intersection (64)–(68) and
// a body on a director node rotate with the full ω.
//
// Rules every implementation keeps (the joint tests check them):
//   - the rows are at most quadratic in q, so 𝖦 = G(q_{n+½}) (DNSM-III (23));
//   - G(q) [P_int(q_A) t_A; P_int(q_B)(A t_A + B τ)] = 0 for every q, not only on the manifold,
//     so the midpoint evaluation is a discrete null space (DNSM-III Table 3, iii.1);
//   - the update map keeps every row at zero, and its derivative is the velocity analysis at
//     t_{n+1}: δq_B = P_int(q_B,n+1)(A δt_A + B̃ δτ), with B̃ = update_freedom_block and δt_A the
//     parent's variation (δφ_A and δω_A with δQ_A = δω̂_A Q_A).
#include "isoflex/math/node_kind.hpp"
#include "isoflex/math/types.hpp"

namespace isoflex::joints {

using isoflex::coordinate_count;
using isoflex::NodeKind;

// 6 × r blocks of the velocity analysis (r ≤ 6); a child's coordinates are a NodeVec (≤ 12):
// fixed maximum sizes, so that the tree sweeps of every Newton iteration allocate nothing.
using FreedomBlock = Eigen::Matrix<double, 6, Eigen::Dynamic, Eigen::ColMajor, 6, 6>;

// A node's motion over a step, formed without subtracting rounded coordinates: the increment
// q_{n+1} − qₙ and its rotation over the step less the identity, Q − I. The step's velocities
// come from the increments, so that their round-off scales with the increments, not with the
// node's distance from the origin (docs/theory/schemes.md §7); a free node's are
// NodeType::root_update's, a child's its joint's update from its parent's.
struct StepIncrement {
  NodeVec dq;
  Mat3 dQ = Mat3::Zero();
};

class Joint {
 public:
  using CRef = Eigen::Ref<const VecX>;
  virtual ~Joint() = default;

  virtual NodeKind parent_kind() const = 0;  // the ground is a frame node
  virtual NodeKind child_kind() const = 0;
  virtual int constraint_count() const = 0;
  virtual int freedom_count() const = 0;  // joint velocities τ (r)

  // Φ (m) and [∂Φ/∂q_A, ∂Φ/∂q_B] (m × (n_A + n_B)).
  virtual VecX constraints(CRef qa, CRef qb) const = 0;
  virtual MatX jacobian(CRef qa, CRef qb) const = 0;
  // H += Σ λᵢ ∂²Φᵢ/∂(q_A, q_B)² ((n_A + n_B)², constant).
  virtual void add_constraint_hessian(CRef lambda, MatX& H) const = 0;

  // Velocity analysis t_B = A t_A + B τ.
  virtual Mat<6, 6> parent_block(CRef qa, CRef qb) const = 0;
  virtual FreedomBlock freedom_block(CRef qa, CRef qb) const = 0;  // 6 × r

  // Update map: the child at t_{n+1} from the parent at t_n and t_{n+1}, the parent's rotation
  // over the step Q_A (Q_A R_A,n = R_A,n+1 for a frame node; the rotation the tree applied to a
  // director node, drilling included), the child at t_n and the increments τ. `step_b` receives
  // the child's rotation over the step, for the joints below it. With `parent` (the parent's
  // StepIncrement), `child` receives the child's, composed from the parent's and the joint's own
  // rotations' increments (the same terms as the update, less those of the step's start).
  virtual NodeVec update(CRef qa_n, CRef qa_n1, const Mat3& step_a, CRef qb_n, CRef tau,
                         Mat3* step_b, const StepIncrement* parent, StepIncrement* child) const = 0;
  NodeVec update(CRef qa_n, CRef qa_n1, const Mat3& step_a, CRef qb_n, CRef tau,
                 Mat3* step_b) const {
    return update(qa_n, qa_n1, step_a, qb_n, tau, step_b, nullptr, nullptr);
  }
  // ∂t_B/∂τ of the update map at (q_A,n+1, q_B,n+1), 6 × r: freedom_block at t_{n+1} with
  // rotation-vector columns multiplied by T(θ) (DNSM-III (37)) and director tangent bases taken
  // at t_n.
  virtual FreedomBlock update_freedom_block(CRef qa_n1, CRef qb_n, CRef qb_n1, CRef tau) const = 0;
};

}  // namespace isoflex::joints
