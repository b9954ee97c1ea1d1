#pragma once
// The node-kind contract (docs/architecture.md, "node kinds"): one description per kind of node
// holds everything `System` and the integrators need to know about it, so that adding a kind
// means adding a description here and nothing in `System` or `integrate/`.
//
// A node's configuration q ∈ R^{n_i} lives on a manifold embedded in a flat space (DNSM-III §2):
// internal constraints g(q) = 0, at most quadratic, with a constant Hessian; velocities in the
// twist form q̇ = P_int(q) t with t = (φ̇, ω) ∈ R⁶, the common currency of the spanning-tree
// machinery (joints/joint.hpp), and G(q) P_int(q) = 0 for every q (so the midpoint evaluation is
// a discrete null space, DNSM-III Table 3 iii.1); a free node (a root of the spanning forest) has
// `free_velocities` independent velocities s with t = B(q) s, and moves over a step by the update
// map q_{n+1} = F_{qₙ}(u) (DNSM-III (14)) whose derivative in the twist form is ∂t/∂u.
//
//   kind      coordinates          internal rows     free velocities   update (DNSM-III)
//   frame     (φ, d₁, d₂, d₃) 12   6 (20)            6 (φ̇, ω)          φ + u_φ, Rodrigues (37)
//   director  (φ, d) 6             1 (41)            5 (φ̇, θ̇₁, θ̇₂)     φ + u_φ, exp on S² (53)–(54)
//   point     φ 3                  0                 3 φ̇               φ + u
//
// Node matrices are at most 12 × 12 (kMaxCoordinates): fixed maximum sizes, no heap allocation.
#include "isoflex/math/types.hpp"

namespace isoflex {

enum class NodeKind { frame, director, point };
inline constexpr int kNodeKinds = 3;
inline constexpr int kMaxCoordinates = 12;

using NodeVec = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, kMaxCoordinates, 1>;
using NodeMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor,
                              kMaxCoordinates, kMaxCoordinates>;

class NodeType {
 public:
  using CRef = Eigen::Ref<const VecX>;
  virtual ~NodeType() = default;

  virtual NodeKind kind() const = 0;
  virtual const char* name() const = 0;  // "frame", "director", "point"
  virtual int coordinates() const = 0;
  virtual int internal_rows() const = 0;
  virtual int free_velocities() const = 0;

  // Internal constraints g(q) (internal_rows), their Jacobian (internal_rows × coordinates) and
  // H += Σ λᵢ ∂²gᵢ/∂q² (coordinates², constant).
  virtual NodeVec constraints(CRef q) const = 0;
  virtual NodeMat jacobian(CRef q) const = 0;
  virtual void add_constraint_hessian(CRef lambda, NodeMat& H) const = 0;

  // P_int(q) (coordinates × 6): q̇ = P_int(q) t.
  virtual NodeMat twist_null_space(CRef q) const = 0;
  // B(q) (6 × free_velocities): the twist of a free node, t = B(q) s.
  virtual NodeMat root_block(CRef q) const = 0;
  // The transposes applied to a generalized force r of the node: P_int(q)ᵀ r and B(q)ᵀ y, in the
  // kinds' fixed-size kernels (what System::reduce sweeps with).
  virtual Vec<6> twist_force(CRef q, CRef r) const = 0;
  virtual NodeVec free_force(CRef q, const Vec<6>& y) const = 0;
  // The update map of a free node and the node's rotation over the step (identity for a kind
  // without one): what the tree joints below it apply (joints/joint.hpp).
  // With its increment q_{n+1} − qₙ without subtracting rounded coordinates: a position's is u
  // itself, a rotated vector's (exp(θ̂) − I) v from the update's own factors. The step's
  // velocities come from it, so that their round-off scales with the increments, not with the
  // node's distance from the origin (the momenta's drift, docs/theory/schemes.md §7).
  // step_increment: the step's rotation less the identity, from the same factors (what the
  // joints below the node compose their children's increments from).
  virtual NodeVec root_update(CRef qn, CRef u, Mat3& step, NodeVec& increment,
                              Mat3& step_increment) const = 0;
  NodeVec root_update(CRef qn, CRef u, Mat3& step, NodeVec& increment) const {
    Mat3 step_increment;
    return root_update(qn, u, step, increment, step_increment);
  }
  NodeVec root_update(CRef qn, CRef u, Mat3& step) const {
    NodeVec increment;
    return root_update(qn, u, step, increment);
  }
  NodeVec root_increment(CRef qn, CRef u) const {
    Mat3 step;
    NodeVec increment;
    root_update(qn, u, step, increment);
    return increment;
  }
  // ∂t/∂u of root_update at t_{n+1} (6 × free_velocities).
  virtual NodeMat root_update_block(CRef qn, CRef u) const = 0;
  // The increments of a step of length dt at the constant velocity v, written into u, for the
  // Newton predictor; false if the kind has none better than the last step's increments scaled
  // by the step ratio (a frame node: its increments are in a fixed basis). u holds those on
  // entry; a kind may overwrite only some of them (a director node its position).
  virtual bool extrapolate(CRef q, CRef v, double dt, Eigen::Ref<VecX> u) const = 0;
  // The increments u of a step from qn to q1, rewritten in the bases the next step from q1 uses
  // (the secant predictor); a kind whose increments are in fixed bases keeps them.
  virtual void transport_increments(CRef, CRef, Eigen::Ref<VecX>) const {}

  // A material point of the node: X in the node's own coordinates (a frame node's body frame,
  // the position X₃ along a director (38); a point node has only itself) and back from a global
  // point at configuration q.
  virtual Vec3 material_point(CRef q, const Vec3& X) const = 0;
  virtual Vec3 local_coordinates(CRef q, const Vec3& x) const = 0;
  // The node's frame (columns d₁, d₂, d₃; a director node: a tangent basis and d; a point node:
  // the identity) and angular velocity (½ Σ d_I × ḋ_I; d × ḋ; 0), for output.
  virtual Mat3 frame(CRef q) const = 0;
  virtual Vec3 angular_velocity(CRef q, CRef v) const = 0;
};

// The description of a kind. Every kind has one: the switch in node_kind.cpp has no default, so
// a kind added to the enum without a description fails to compile (-Werror=switch).
const NodeType& node_type(NodeKind kind);

inline int coordinate_count(NodeKind kind) {
  return node_type(kind).coordinates();
}

}  // namespace isoflex
