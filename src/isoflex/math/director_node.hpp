#pragma once
// Director node q = (φ, d) ∈ R⁶ on R³ × S² (DNSM-III (40)), used by Reissner–Mindlin shell nodes.
// Generalized velocity s = (φ̇, θ̇₁, θ̇₂) ∈ R⁵ (47), relative to an orthonormal basis (d₁, d₂) of
// T_d S² (tangent_basis(dₙ), taken afresh in every time step).
#include "isoflex/math/types.hpp"

namespace isoflex::director_node {
inline constexpr int kCoords = 6;
inline constexpr int kTwist = 5;
inline constexpr int kConstraints = 1;
using Q = Vec<6>;

// Orthonormal (d₁, d₂) with d₁ × d₂ = d (d normalized first). Not continuous in d (the helper
// axis switches), which is harmless: each time step takes the basis at dₙ afresh.
Mat<3, 2> tangent_basis(const Vec3& d);

double constraint(const Q& q);                 // (41)
Mat<1, 6> jacobian(const Q& q);                // (42)
Mat<6, 5> null_space(const Mat<3, 2>& basis);  // (48)
// Discrete null space (49)–(50); satisfies G(q_{n+½}) 𝖯 = 0 for every q_{n+1}.
Mat<6, 5> discrete_null_space(const Q& qn, const Mat<3, 2>& basis_n, const Q& qn1);
// Reparametrization (53)–(54): φ + u_φ, exp_{dₙ}(D θ).
Q update(const Q& qn, const Mat<3, 2>& basis_n, const Vec<5>& u);
Mat<6, 5> update_derivative(const Q& qn, const Mat<3, 2>& basis_n, const Vec<5>& u);

// --- The node in the system's twist form (joints/joint.hpp) -----------------------------------
// q̇ = P(q) t with t = (φ̇, ω), ḋ = ω × d: P = [I 0; 0 −d̂] (DNSM-III (68)), rank 5 (ω ∥ d is
// the drilling part). G(q) P(q) = 0 for every q ∈ R⁶, so P(q_{n+½}) is a discrete null space; its
// director columns are those of (49)–(50) times dₙ·d_{n+½} (docs/theory/shell.md).
Mat<6, 6> twist_null_space(const Q& q);
// A free node's twist from its five velocities s = (φ̇, θ̇₁, θ̇₂) (47): ω = θ̇₁ d₂ − θ̇₂ d₁ (45)
// with (d₁, d₂) = tangent_basis(d).
Mat<6, 5> root_block(const Q& q);
// The reparametrization (53)–(54) of a free node with the basis tangent_basis(dₙ): the director
// turns by θ = u₄ d₂ − u₅ d₁ (⊥ dₙ, so exp(θ̂) dₙ = exp_{dₙ}(D θ)); `step` receives exp(θ̂).
// increment: q − qn, step_increment: exp(θ̂) − I, both without subtracting rounded coordinates
// (NodeType::root_update).
Q root_update(const Q& qn, const Vec<5>& u, Mat3* step, Q* increment = nullptr,
              Mat3* step_increment = nullptr);
// The rotation increments u of a step from qn (in the axes of dₙ) in the axes of d₁ = the
// director after it: the rotation vector θ = [d₂ −d₁]ₙ u is normal to both dₙ and d₁, so its
// coordinates in the axes at d₁ are [d₂ −d₁]₁ᵀ θ, exactly. The tangent basis is not transported
// along (it is built from e₁ or e₂, and switches between them), so the same u in the new axes
// would be another rotation.
void transport_increments(const Q& qn, const Q& q1, Eigen::Ref<VecX> u);
// ∂t/∂u of root_update at t_{n+1}: [I 0; 0 T(θ) [d₂ −d₁]] (bases at tₙ).
Mat<6, 5> root_update_block(const Q& qn, const Vec<5>& u);
}  // namespace isoflex::director_node
