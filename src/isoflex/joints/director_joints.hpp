#pragma once
// Joints that involve director nodes (Reissner–Mindlin shell nodes q = (φ, d) ∈ R⁶, |d| = 1,
// DNSM-III (40)–(41)), against the generic contract joints/joint.hpp. The derivations, and why
// G(q)·P(q) = 0 on all of R^{n_A + n_B}, are in docs/theory/director-joints.md.
//
//   ShellIntersection  director parent, director child: DNSM-III Ex. 5.3, (64)–(68)   m 4, r 1
//   DirectorOnFrame    frame parent (body, beam node or ground), director child fixed   m 5, r 0
//                      to it (with the ground as parent: a clamped shell node)
//   FrameOnDirector    director parent, frame child (body or beam node) fixed to the    m 5, r 1
//                      shell node; it turns freely about d_A (no drilling stiffness)
//   DirectorSupport    ground parent, director child: translation components and the    m + r = 5
//                      director (free, fixed, or turning about a symmetry-plane normal)
//
// m + r is the child's number of velocities: 5 for a director child, 6 for a frame child.
// Twists are t = (φ̇, ω) for both node kinds; a director node's P_int(q) = [I 0; 0 −d̂]
// (director_node::twist_null_space) ignores the drilling part ω ∥ d, but the joints below a
// director node see the full ω (ShellIntersection and FrameOnDirector pass it on).
#include <array>
#include <vector>

#include "isoflex/joints/joint.hpp"
#include "isoflex/math/director_node.hpp"
#include "isoflex/math/frame_node.hpp"
#include "isoflex/math/types.hpp"

namespace isoflex::joints {

namespace detail {
// The constraint rows of a joint on q = (q_A, q_B) ∈ R^N. Every row is linear, g·q − c, or a
// product of two linear maps of q into R³, (L₁q)·(L₂q) − c: at most quadratic, so the discrete
// derivative is G(q_{n+½}) (DNSM-III (23)) and the Hessian L₁ᵀL₂ + L₂ᵀL₁ is constant. The offsets
// c are constants of the joint (η of (64), a fixed coordinate); whether the rows hold at t = 0 is
// for the caller to check (System::compile), not something an offset may absorb.
template <int N>
class QuadraticRows {
 public:
  using Map = Mat<3, N>;  // q ↦ R³, linear

  void add_linear(const Vec<N>& g, double c = 0.0);
  void add_vector(const Map& L);  // the three rows of L q (a point coincidence)
  void add_product(const Map& L1, const Map& L2, double c = 0.0);

  int size() const { return static_cast<int>(rows_.size()); }
  VecX values(const Vec<N>& q) const;
  MatX jacobian(const Vec<N>& q) const;  // size() × N
  void add_hessian(const Eigen::Ref<const VecX>& lambda, MatX& H) const;

 private:
  struct Row {
    bool product = false;
    Vec<N> g = Vec<N>::Zero();
    Map L1 = Map::Zero(), L2 = Map::Zero();
    double c = 0.0;
  };
  double value(const Row& row, const Vec<N>& q) const;
  std::vector<Row> rows_;
};
}  // namespace detail

// DNSM-III Ex. 5.3: two shell nodes rigidly joined at an intersection. Rows (64):
// φ_B − φ_A (3) and d_A·d_B − η (1), η = cos β₀ = d_A·d_B at t = 0. τ is the rotation of B about
// d_A: φ̇_B = φ̇_A, ω_B = ω_A + τ d_A (A = I₆, B = (0; d_A)). ω_B is the angular velocity ω of
// the paper's shared node (65)–(67); (68) is P_int of each node applied to it.
class ShellIntersection final : public Joint {
 public:
  // Throws std::invalid_argument if d_A ∥ d_B at t = 0 (β₀ ∈ {0, π}: the row d_A·d_B is then
  // stationary on S² × S², and τ would not move d_B).
  ShellIntersection(const director_node::Q& qa0, const director_node::Q& qb0);
  double eta() const { return eta_; }

  NodeKind parent_kind() const override { return NodeKind::director; }
  NodeKind child_kind() const override { return NodeKind::director; }
  int constraint_count() const override { return rows_.size(); }
  int freedom_count() const override { return 1; }
  VecX constraints(CRef qa, CRef qb) const override;
  MatX jacobian(CRef qa, CRef qb) const override;
  void add_constraint_hessian(CRef lambda, MatX& H) const override;
  Mat<6, 6> parent_block(CRef qa, CRef qb) const override;
  FreedomBlock freedom_block(CRef qa, CRef qb) const override;
  using Joint::update;
  NodeVec update(CRef qa_n, CRef qa_n1, const Mat3& step_a, CRef qb_n, CRef tau, Mat3* step_b,
                 const StepIncrement* parent, StepIncrement* child) const override;
  FreedomBlock update_freedom_block(CRef qa_n1, CRef qb_n, CRef qb_n1, CRef tau) const override;

 private:
  detail::QuadraticRows<12> rows_;
  double eta_ = 0.0;
};

// A shell node fixed to a frame node A (body, beam node or the ground): rows
// φ_B − (φ_A + R_A X_A) (3), d_B·(R_A e), d_B·(R_A f) (2), with X_A = R_A0ᵀ(φ_B0 − φ_A0),
// D = R_A0ᵀ d_B0 and (e, f) an orthonormal basis of D^⊥ (body coordinates of A).
// No freedoms: φ̇_B = φ̇_A + ω_A × R_A X_A, ω_B = ω_A.
class DirectorOnFrame final : public Joint {
 public:
  DirectorOnFrame(const frame_node::Q& qa0, const director_node::Q& qb0);

  NodeKind parent_kind() const override { return NodeKind::frame; }
  NodeKind child_kind() const override { return NodeKind::director; }
  int constraint_count() const override { return rows_.size(); }
  int freedom_count() const override { return 0; }
  VecX constraints(CRef qa, CRef qb) const override;
  MatX jacobian(CRef qa, CRef qb) const override;
  void add_constraint_hessian(CRef lambda, MatX& H) const override;
  Mat<6, 6> parent_block(CRef qa, CRef qb) const override;
  FreedomBlock freedom_block(CRef qa, CRef qb) const override;
  using Joint::update;
  NodeVec update(CRef qa_n, CRef qa_n1, const Mat3& step_a, CRef qb_n, CRef tau, Mat3* step_b,
                 const StepIncrement* parent, StepIncrement* child) const override;
  FreedomBlock update_freedom_block(CRef qa_n1, CRef qb_n, CRef qb_n1, CRef tau) const override;

 private:
  detail::QuadraticRows<18> rows_;
  Vec3 X_A_, D_;  // in A's body coordinates
};

// A body or beam node B fixed to a shell node A: rows φ_B + R_B X_B − φ_A (3), (R_B e)·d_A,
// (R_B f)·d_A (2), with X_B = R_B0ᵀ(φ_A0 − φ_B0), D_B = R_B0ᵀ d_A0 and (e, f) an orthonormal basis
// of D_B^⊥ (body coordinates of B). τ turns B about d_A (a single shell node has no drilling
// stiffness): ω_B = ω_A + τ d_A, φ̇_B = φ̇_A + ρ_B × ω_B with ρ_B = R_B X_B.
class FrameOnDirector final : public Joint {
 public:
  FrameOnDirector(const director_node::Q& qa0, const frame_node::Q& qb0);

  NodeKind parent_kind() const override { return NodeKind::director; }
  NodeKind child_kind() const override { return NodeKind::frame; }
  int constraint_count() const override { return rows_.size(); }
  int freedom_count() const override { return 1; }
  VecX constraints(CRef qa, CRef qb) const override;
  MatX jacobian(CRef qa, CRef qb) const override;
  void add_constraint_hessian(CRef lambda, MatX& H) const override;
  Mat<6, 6> parent_block(CRef qa, CRef qb) const override;
  FreedomBlock freedom_block(CRef qa, CRef qb) const override;
  using Joint::update;
  NodeVec update(CRef qa_n, CRef qa_n1, const Mat3& step_a, CRef qb_n, CRef tau, Mat3* step_b,
                 const StepIncrement* parent, StepIncrement* child) const override;
  FreedomBlock update_freedom_block(CRef qa_n1, CRef qb_n, CRef qb_n1, CRef tau) const override;

 private:
  detail::QuadraticRows<18> rows_;
  Vec3 X_B_;  // in B's body coordinates
};

// Boundary condition of a shell node (parent: the ground, whose coordinates the rows do not use).
enum class DirectorCondition {
  free,        // ω ∈ span{d₂, −d₁} of tangent_basis(d): 2 freedoms, as a free node (45)
  fixed,       // rows d·e, d·f with e, f ⊥ d₀: no freedom
  about_axis,  // symmetry plane with unit normal n: row d·n − d₀·n, ω = τ n: 1 freedom
};

struct DirectorSupportSpec {
  std::array<bool, 3> fix_translation = {true, true, true};  // global x, y, z of φ
  DirectorCondition director = DirectorCondition::free;
  Vec3 axis = Vec3::Zero();  // n for about_axis (normalized by the constructor)
};

// Rows: e_iᵀ(φ_B − φ_B0) for each fixed i, then the director rows. τ: the free translation
// components (x, y, z order), then the director's rotations. A pinned node is
// {{true, true, true}, free}; a symmetry plane with normal e_x is {{true, false, false},
// about_axis, e_x}; {{true, true, true}, fixed} clamps the node (as DirectorOnFrame on the ground).
class DirectorSupport final : public Joint {
 public:
  // Throws std::invalid_argument for an about_axis condition whose axis is zero, not finite or
  // parallel to d_B0 (then ω = τ n would not move the director).
  DirectorSupport(const director_node::Q& qb0, const DirectorSupportSpec& spec);

  NodeKind parent_kind() const override { return NodeKind::frame; }
  NodeKind child_kind() const override { return NodeKind::director; }
  int constraint_count() const override { return rows_.size(); }
  int freedom_count() const override { return free_count_ + rotation_count(); }
  VecX constraints(CRef qa, CRef qb) const override;
  MatX jacobian(CRef qa, CRef qb) const override;
  void add_constraint_hessian(CRef lambda, MatX& H) const override;
  // Zero: the rows are fixed in space (the ground does not move).
  Mat<6, 6> parent_block(CRef qa, CRef qb) const override;
  FreedomBlock freedom_block(CRef qa, CRef qb) const override;
  using Joint::update;
  NodeVec update(CRef qa_n, CRef qa_n1, const Mat3& step_a, CRef qb_n, CRef tau, Mat3* step_b,
                 const StepIncrement* parent, StepIncrement* child) const override;
  FreedomBlock update_freedom_block(CRef qa_n1, CRef qb_n, CRef qb_n1, CRef tau) const override;

 private:
  int rotation_count() const;
  // (u_φ, θ₁, θ₂) of director_node::root_update from τ (free director).
  Vec<5> root_increment(CRef tau) const;

  DirectorSupportSpec spec_;
  detail::QuadraticRows<18> rows_;
  int free_count_ = 0;
  Vec3 d0_ = Vec3::Zero();
};

}  // namespace isoflex::joints
