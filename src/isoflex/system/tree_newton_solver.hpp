#pragma once
// O(N) solution of the reparametrized Newton system on a spanning tree (docs/theory/schemes.md,
// "tree recursion").
//
// The Newton matrix of DNSM-III (11)+(14) without loop-closing rows is
//   J = 𝖯(q_{n+½})ᵀ K̂ P_tree(q_{n+1}) D(u),  P_tree = P_int (I − 𝒜)⁻¹ ℬ,
// i.e. J Δu = b reads, node by node (t: twists, y: accumulated twist-space forces),
//   t_g = A¹_g t_p + ℬ¹_g D_g Δu_g,   y_i = Σ_j K̃_ij t_j + Σ_{children c} Aᵐ_cᵀ y_c,
//   ℬᵐ_gᵀ y_g = b_g,   K̃_ij = P_int,i(q_{n+½})ᵀ K̂_ij P_int,j(q_{n+1}).
// When K̂ couples a node only with itself and its tree neighbours (rigid bodies, joint Hessians,
// single-node loads), eliminating Δu from the leaves to the roots is fill-free, as in
// articulated-body algorithms: with y_g = Â_g t_g + Ĉ_g t_p + ẑ_g for a processed subtree,
//   S_g = ℬᵐ_gᵀ Â_g E_g (E_g = ℬ¹_g D_g),  Δu_g = δ_g + Γ_g t_p,
//   δ_g = S_g⁻¹ (b_g − ℬᵐ_gᵀ ẑ_g),  Γ_g = −S_g⁻¹ ℬᵐ_gᵀ (Â_g A¹_g + Ĉ_g),
//   t_g = T_g t_p + τ_g,  T_g = A¹_g + E_g Γ_g,  τ_g = E_g δ_g,
//   Â_p += K̃_pg T_g + Aᵐ_gᵀ (Â_g T_g + Ĉ_g),  ẑ_p += K̃_pg τ_g + Aᵐ_gᵀ (Â_g τ_g + ẑ_g),
// followed by one sweep from the roots to the leaves for t and Δu. Cost: a few 6 × 6 products per
// node instead of a sparse LU of the 15N bordered matrix.
#include <optional>
#include <vector>

#include "isoflex/system/system.hpp"

namespace isoflex::system {

class TreeNewtonSolver {
 public:
  explicit TreeNewtonSolver(const System& sys);

  // Solves J Δu = b (J as above, K̂ = K). Returns nothing if K couples two nodes that no tree
  // joint joins (then the recursion would fill in; use the bordered form).
  // Throws std::runtime_error if a pivot block S_g is singular.
  std::optional<VecX> solve(const VecX& qm, const VecX& q1, const VecX& u, const SpMat& K,
                            const VecX& b) const;

  // True if every element's nodes are equal or tree neighbours and no joint closes a loop, so
  // that K̂ couples only tree neighbours (loads act on single nodes).
  bool applicable() const;

 private:
  struct Link {
    int node = -1;
    int parent = -1;    // node, −1 = ground
    int joint = -1;     // tree joint index, −1 = free root (twist of the node itself)
    int nu_offset = 0;  // first entry of Δu_g
    int freedoms = 0;   // r_g
    int rotvec = -1;    // rotation vector inside Δu_g (T(θ) block of D), −1 = none
  };
  const System& sys_;
  std::vector<Link> links_;  // parents before children
  std::vector<int> link_of_node_;

  bool neighbours(int a, int b) const;
};

}  // namespace isoflex::system
