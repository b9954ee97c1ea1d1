#pragma once
// Residual and Newton matrix of the reparametrized scheme (DNSM-III (14)) on a spanning forest
// without loop-closing rows, assembled block by block into a fixed sparsity pattern.
//
//   R(u) = 𝖯ᵀ r₀(q_{n+1}),  q_{n+1} = F_{qₙ}(u),  𝖯 = P_tree(q_{n+½}) = P_int(q_{n+½}) E(q_{n+½}),
//   J(u) = 𝖯ᵀ K̂ P_tree(q_{n+1}) D(u),  K̂ = (2/Δt) M + Δt ∂f/∂q + ½Δt Σ λ̂ᵢ Hᵢ
// (energy_momentum.hpp; P_tree = P_int E is (57), D(u) the T(θ) blocks of the update (37)).
// Node by node, with twist-level blocks E_{i,g} (6 × r_g) of node i and ν-group g (a root twist
// or the τ of a tree joint) on the path from i to its root,
//   J_{gh} = Σ_{(i,j)} E_{i,g}(q_{n+½})ᵀ K̃_{ij} E_{j,h}(q_{n+1}) D_h,
//   K̃_{ij} = P_int,i(q_{n+½})ᵀ K̂_{ij} P_int,j(q_{n+1})   (6 × 6),
// summed over the node pairs (i, j) that K̂ couples: the diagonal, element node pairs, joint
// parent/child pairs. The pattern of K̂, the paths, the (g, h) pattern of J with the positions of
// its values, the elimination order of its block LU, and the patterns of 𝖦 and 𝖦𝖦ᵀ (λ̂ by the
// normal equations, LDLᵀ ordering kept) are computed once; an iteration costs a few fixed-size
// products per node pair and numeric factorizations. R is the leaves-to-root
// sweep System::reduce, so 𝖯 is never formed. For shallow forests (a beam's nodes are roots of
// their own) J stays sparse; for deep trees (chains) it fills in as 𝖯 does.
#include <Eigen/SparseCholesky>
#include <vector>

#include "isoflex/elements/beam_element.hpp"
#include "isoflex/integrate/block_lu.hpp"
#include "isoflex/math/types.hpp"
#include "isoflex/solve/linear_solver.hpp"
#include "isoflex/solve/normal_equations.hpp"
#include "isoflex/system/system.hpp"

namespace isoflex::integrate {

class ReducedNewtonMatrix {
 public:
  // True for a system without loop-closing rows whose every node is a root or the child of a
  // tree joint.
  static bool applicable(const system::System& sys);
  explicit ReducedNewtonMatrix(const system::System& sys);

  // R(u) for the step from (qₙ, vₙ); J (if not null) receives the Newton matrix (k × k, compressed,
  // always the same pattern). λ̂ of K̂ by least squares from r₀ ≈ −Δt 𝖦ᵀλ; `normal` only if 𝖦
  // has a nonzero outside its fixed pattern (then 𝖦 = System::jacobian). `lambda_start`: λ̂ to
  // take instead (if it has the selected rows' size): at a Newton start the multipliers of the
  // step that ended at qₙ estimate λ better than the start's residual does (slider-crank:
  // 3.877 → 3.841 iterations per step, bench/slider_crank.md).
  // The reference is to a kept workspace, valid until the next call: an iteration (evaluate and
  // solve) allocates nothing once the first has sized the workspaces.
  const VecX& evaluate(const VecX& qn, const VecX& vn, const VecX& u, double dt, double t_mid,
                       solve::NormalEquations& normal, system::SpMat* J,
                       const VecX* lambda_start = nullptr) const;
  // The multipliers of the selected rows for the step qₙ → q1 (State::lambda; what
  // EnergyMomentumIntegrator::step_multipliers computes through System): the least-squares
  // solution of 𝖦ᵀλ = −r, r = (1/Δt) M (vₙ₊₁ − vₙ) + f (DNSM-III (9)), with 𝖦 = G(q_{n+½}) in its
  // fixed pattern and 𝖦𝖦ᵀ by the kept LDLᵀ (`normal`: its pivoted QR where that fails);
  // vₙ₊₁ = (2/Δt) dq − vₙ from the step's increment dq, as in evaluate().
  // mismatch: ‖r + 𝖦ᵀλ‖∞. False (nothing written) if 𝖦 has a nonzero outside its pattern; throws
  // std::runtime_error where 𝖦 is rank deficient.
  bool multipliers(const VecX& qn, const VecX& vn, const VecX& q1, const VecX& dq, double dt,
                   double t_mid, solve::NormalEquations& normal, VecX& lambda,
                   double& mismatch) const;
  // q_{n+1} = F_{qₙ}(u) of the last evaluate() if it was at (qn, u) (a converged iterate: its
  // residual was the last one), and its increment q_{n+1} − qₙ (System::update), else null.
  const VecX* configuration(const VecX& qn, const VecX& u, VecX* increment = nullptr) const;
  // Solves J x = b for a J of evaluate(): block LU in a fixed elimination order (block_lu.hpp),
  // checked by its residual; the sparse LU with its kept symbolic analysis where that fails.
  // refactorize = false: J is the matrix of the last call, solved with its kept factorization.
  const VecX& solve(const system::SpMat& J, const VecX& b, bool refactorize = true) const;
  const system::SpMat& pattern() const { return pattern_; }
  int analyses() const { return lu_.analyses(); }  // symbolic analyses of the sparse LU so far
  int fallbacks() const { return fallbacks_; }     // solves that needed the sparse LU
  int factorizations() const { return factorizations_; }  // block LU factorizations so far

 private:
  using Block = Mat<12, 12>;
  // 6 × r blocks (r ≤ 6) without heap allocation.
  using Twist = Eigen::Matrix<double, 6, Eigen::Dynamic, 0, 6, 6>;
  using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>;  // g × h block of J
  struct Group {
    int offset = 0, width = 0;
    int rotvec = -1;  // θ inside the group (T(θ) block of D), −1 = none
  };
  struct Pair {
    int i = 0, j = 0;
    int first = 0;  // first entry of its J-block indices (path(i) × path(j), row-major)
  };
  struct JBlock {
    int g = 0, h = 0;
    int first_slot = 0;  // slots_[first_slot + c]: value index of (offset_g, offset_h + c)
  };

  int pair(int i, int j) const;  // index into pairs_, −1 if K̂ does not couple i and j
  // Node i is a root whose group is a frame node's twist (width 6, θ in its last three).
  bool frame_root(int i) const {
    return parent_joint_[i] < 0 && path_[i].size() == 1 && groups_[path_[i][0]].width == 6 &&
           groups_[path_[i][0]].rotvec == 3;
  }
  // f = DV(qₙ, q₁) − f_ext(q_{n+½}, t_{n+½}) into f_ (System::discrete_force); with `want` the
  // node blocks of (2/Δt) M + Δt ∂f/∂q₁ into K_. Without `want`, f_ is kept if it is already
  // that of (qₙ, q₁, Δt, t_{n+½}): the multipliers of a step are those of the configuration
  // whose residual ended its Newton iteration.
  void force(const VecX& qn, const VecX& q1, double dt, double t_mid, bool want) const;
  // 𝖦 = G(q_{n+½}) of the selected rows ((22), joint Jacobians) into G_; false if an entry
  // outside its fixed pattern is nonzero.
  bool midpoint_jacobian(const VecX& qm) const;
  // E(q) node blocks along the paths (path_[i] order), (57).
  void twist_blocks(const VecX& q, std::vector<std::vector<Twist>>& E) const;

  const system::System& sys_;
  std::vector<Group> groups_;
  std::vector<std::vector<int>> path_;  // groups on the path of node i, root first
  std::vector<int> parent_joint_;       // tree joint whose child is node i, −1 for a root
  std::vector<Pair> pairs_;
  std::vector<int> diagonal_pair_;                           // pair (i, i) of node i
  std::vector<std::vector<std::pair<int, int>>> row_pairs_;  // node i: (j, pair), sorted by j
  std::vector<int> pair_blocks_;                             // J block of each path combination
  std::vector<std::vector<int>> element_pairs_;              // ne × ne pair indices per element
  std::vector<const elements::BeamElement*> beams_;  // the element as a beam (fixed sizes), or null
  std::vector<Block> mass_;                          // M blocks of the pairs
  bool mass_symmetric_ = false;  // M = Mᵀ bit for bit (its rows are its columns)
  struct LoadEntry {
    int pair, row, col;
  };
  std::vector<std::vector<LoadEntry>> load_entries_;  // per load, its tangent's entries
  std::vector<JBlock> jblocks_;
  std::vector<int> slots_;
  system::SpMat pattern_;
  std::vector<int> selected_all_;  // all-rows index of each selected row
  // 𝖦 = G(q_{n+½}) (selected rows) in a fixed pattern: value slots of the 6 × 12 blocks of the
  // internal constraints and the m × 24 blocks of the joints (−1: ground or unselected row).
  system::SpMat G_pattern_;
  std::vector<int> node_slots_, joint_slots_, joint_first_slot_;
  // 𝖦𝖦ᵀ of the normal equations for λ̂, assembled straight into the upper triangle of its
  // permuted form C = Π 𝖦𝖦ᵀ Πᵀ, Π the AMD ordering FixedPatternLDLT would compute:
  // C[target] += G[a]·G[b]. The factorization then neither copies nor permutes, allocates
  // nothing, and does FixedPatternLDLT's arithmetic.
  struct Product {
    int a, b, target;
  };
  std::vector<Product> products_;
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> ggt_perm_, ggt_perm_inv_;
  // SimplicialLDLT on a matrix already ordered, its numeric factorization in place.
  class PreorderedLDLT
      : public Eigen::SimplicialLDLT<system::SpMat, Eigen::Upper, Eigen::NaturalOrdering<int>> {
   public:
    bool factorize_ordered(const system::SpMat& C) {
      this->template factorize_preordered<true>(C);
      return this->info() == Eigen::Success;
    }
  };
  // Π 𝖦𝖦ᵀ Πᵀ (upper) into GGt_, LDLᵀ, λ of 𝖦𝖦ᵀ λ = rhs into lambda; throws std::runtime_error
  // if the factorization fails (as FixedPatternLDLT).
  void solve_normal(const VecX& rhs, VecX& lambda) const;
  // Workspace and the kept LU (caches; an integrator is not shared between threads).
  mutable std::vector<Block> K_;
  mutable Mat<24, 24> beam_K_;
  mutable std::vector<Block> scaled_mass_;  // (2/Δt) M of the pairs at Δt = scaled_mass_dt_
  mutable double scaled_mass_dt_ = 0.0;
  mutable MatX Ke_;
  mutable VecX a_, b_, l_, f_, element_dv_, q1_, dq_, qm_, v1_, dv_, r0_, R_, y_, rhs_, lambda_, x_,
      check_;
  mutable std::vector<Mat3> steps_, step_increments_;
  mutable std::vector<double> tangent_;
  mutable std::vector<Mat3> T_;
  mutable system::SpMat G_, GGt_;
  mutable PreorderedLDLT ldlt_;
  mutable VecX permuted_, solved_;
  mutable std::vector<std::vector<Twist>> Em_, E1_;
  mutable VecX force_qn_, force_q1_;  // the arguments f_ was computed for
  mutable VecX q1_qn_, q1_u_;         // the arguments q1_ was computed for
  mutable std::vector<elements::BeamElement::Strain6> beam_strains_n_;  // raw strains at force_qn_
  mutable double force_dt_ = 0.0, force_t_ = 0.0;
  mutable std::vector<Small> J_;
  mutable BlockLU block_lu_;
  mutable std::vector<BlockLU::Block6> values_;  // J's blocks as BlockLU takes them
  mutable solve::FixedPatternLU lu_;
  mutable int fallbacks_ = 0;
  mutable bool factorized_ = false;  // block_lu_ holds the factors of the last J
  mutable int factorizations_ = 0;
};

}  // namespace isoflex::integrate
