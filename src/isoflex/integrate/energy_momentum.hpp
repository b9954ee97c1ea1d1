#pragma once
// The three energy–momentum formulations of DNSM-III, all on the same element kernels
// (docs/theory/schemes.md). With v_{n+1} = (2/Δt)(q_{n+1} − q_n) − v_n inserted,
//   r₀(q_{n+1}) = M (v_{n+1} − v_n) + Δt [DV(q_n, q_{n+1}) − f_ext(q_{n+½}, t_{n+½})],
//   constrained (9):      r₀ + Δt 𝖦ᵀ λ = 0,  Φ(q_{n+1}) = 0;     unknowns (Δq, λ),      n + m
//   null space (11):      𝖯ᵀ r₀ = 0,         Φ(q_{n+1}) = 0;     unknowns Δq,           n
//   reparametrized (14):  𝖯ᵀ r₀(F(u)) = 0,   Φ_cut(F(u)) = 0;    unknowns u,            n − m
//                                                                 (+ independent loop rows)
// with Δq = q_{n+1} − q_n: every formulation iterates on increments, and the velocities come
// from them, not from the difference of rounded coordinates (schemes.md §7).
// with 𝖦 = G(q_{n+½}) (all constraints are at most quadratic, (23)), 𝖯 = P_tree(q_{n+½}) for
// the internal and tree joint constraints (Table 3, iii.1) times the implicit null space (13) of
// the loop-closing rows (iii.3).
//
// Newton tangent. The derivative of 𝖯ᵀ r₀ contains (∂𝖯ᵀ/∂q) r₀. Differentiating the identity
// 𝖯ᵀ(q) 𝖦ᵀ(q) ≡ 0 gives (∂𝖯ᵀ·δq) 𝖦ᵀλ = −½ 𝖯ᵀ (Σ λᵢ Hᵢ) δq, and at the solution r₀ = −Δt 𝖦ᵀλ,
// so the term equals ½ Δt 𝖯ᵀ (Σ λᵢ Hᵢ) δq with the constraint Hessians Hᵢ (constant). λ is
// estimated in every iteration by least squares from r₀ ≈ −Δt 𝖦ᵀλ; the tangent is then exact at
// the solution and Newton converges quadratically (tests/integrate).
#include <optional>
#include <stdexcept>

#include "isoflex/integrate/newton_loop.hpp"
#include "isoflex/integrate/reduced_newton_matrix.hpp"
#include "isoflex/integrate/snapshot.hpp"
#include "isoflex/integrate/time_integrator.hpp"
#include "isoflex/model/model.hpp"
#include "isoflex/solve/normal_equations.hpp"
#include "isoflex/system/system.hpp"
#include "isoflex/system/tree_newton_solver.hpp"

namespace isoflex::integrate {

// How the reduced Newton systems (null space, reparametrized) are solved: by forming 𝖯 and the
// reduced matrix (dense-ish for chains: O(N²) entries), or in the equivalent sparse bordered form
// with the tree factors (I − 𝒜) t = ℬ ν, which grows linearly with N (docs/theory/schemes.md).
// The reparametrized system on a tree whose elements couple only tree neighbours is solved by an
// O(N) recursion over the tree instead (system/tree_newton_solver.hpp).
// `blocks`: the reparametrized matrix 𝖯ᵀ K̂ F′ of a forest without loop-closing rows assembled
// node block by node block into a fixed pattern (integrate/reduced_newton_matrix.hpp).
// Automatic: the tree recursion where it applies (reparametrized), else bordered for trees
// without loop-closing rows, k ≥ 48 and a dense 𝖯 (more than 20 n entries: deep trees such as
// chains), else blocks (reparametrized, no loop-closing rows), else explicit.
enum class ReducedSolve { automatic, explicit_null_space, bordered, tree, blocks };

class EnergyMomentumIntegrator final : public TimeIntegrator {
 public:
  EnergyMomentumIntegrator(const system::System& sys, const model::Solver& settings,
                           ReducedSolve how = ReducedSolve::automatic);
  bool bordered() const { return bordered_; }
  bool tree_recursion() const { return tree_.has_value(); }
  bool block_assembly() const { return blocks_.has_value(); }

  model::Formulation formulation() const { return settings_.formulation; }
  std::string name() const override { return model::to_string(settings_.formulation); }
  // Size of the linear system solved per Newton iteration.
  int unknowns() const override;
  State initial_state() const override;
  // Advances s by one step; throws NewtonFailure when Newton does not converge.
  StepStats step(State& s) const override;
  void set_joint_reactions(bool on) override;

  // Residual R(x) and Newton matrix J(x) of the step from s, at the unknowns x (for tests and
  // condition numbers). start_unknowns(s) is the Newton start value: q_{n+1} = qₙ (u = 0) at the
  // first step, the extrapolation of the last step after that. Here x holds coordinates,
  // (q_{n+1}, λ), q_{n+1} or u; the step itself iterates on Δq = q_{n+1} − qₙ in place of q_{n+1}
  // (docs/theory/schemes.md §1).
  VecX start_unknowns(const State& s) const;
  VecX residual(const State& s, const VecX& x, MatX* J) const;

  Snapshot snapshot(
      const State& s, const StepStats& st,
      const std::vector<std::string>& body_names) const;  // integrate::snapshot(system, …)

 private:
  struct StepContext;
  StepContext context(const State& s, double dt) const;
  // Newton start values: qₙ + Δt vₙ with the directors turned as in the last step (λₙ; the last
  // u with the free nodes' positions moved by Δt vₙ), qₙ (u = 0), or the secant
  // qₙ + (Δt/Δtₙ₋₁)(qₙ − qₙ₋₁) (the last u). The constrained and null-space starts are the
  // increments Δq (the step's unknowns), or coordinates with q0 = qₙ (start_unknowns(s)).
  enum class Predictor { extrapolated, at_rest, secant };
  VecX start_unknowns(const State& s, double dt, Predictor p, const VecX* q0 = nullptr) const;
  void secant_directors(const State& s, double ratio, const VecX* q0, VecX& x) const;
  // One step of length dt (s.step unchanged); throws NewtonFailure.
  // The Newton residual scale of a step from s; `full` = (2/Δt)‖M qₙ‖∞ + ‖M vₙ‖∞.
  double residual_scale(const State& s, double dt, double full) const;
  StepStats attempt(State& s, double dt) const;
  // Newton matrix, possibly bordered: the correction is x-block [col, col + size) of A⁻¹ b with
  // b = −R placed at rows [row, row + R.size()).
  // On the tree path only K̂ and the configurations are kept; the solve is the recursion.
  struct NewtonMatrix {
    system::SpMat A;
    int row = 0, col = 0;
    bool tree = false;
    bool blocks = false;  // A in the fixed pattern of blocks_
    VecX qm, q1, u;
  };
  // The residual and the correction are kept workspaces (valid until the next call): the block
  // path's Newton iteration allocates nothing.
  // start: x is a Newton start (λ̂ = State::lambda on the block path,
  // ReducedNewtonMatrix::evaluate; the mixed tangent's stresses from qₙ).
  const VecX& evaluate(const StepContext& c, const VecX& x, NewtonMatrix* J, bool bordered,
                       bool start = false) const;
  VecX evaluate_assembled(const StepContext& c, const VecX& x, NewtonMatrix* J,
                          bool bordered) const;  // every path but the blocks
  // Numerical dissipation (model::Solver::numerical_dissipation, docs/theory/schemes.md §10): on
  // from the second step (it needs qₙ₋₁, kept in State::q_prev); the elements' f_d and its
  // ∂f_d/∂qₙ₊₁ (K, if not null, += it); with stress_force (not null) the mixed tangent's
  // (System::mixed_strain_dissipation_force at the last iterate).
  bool dissipating(const State& s) const;
  VecX dissipative_force(const State& s, const VecX& q1, double dt, system::SpMat* K,
                         VecX* stress_force = nullptr) const;
  // −A⁻¹R for the kept matrix; `fresh`: A was evaluated since the last call (else its
  // factorization is reused where one is kept: the chord corrections of newton_loop).
  const VecX& correction(const NewtonMatrix& J, const VecX& R, bool fresh) const;
  // 1, or the factor that shortens a reparametrized correction to max_rotation_correction.
  double rotation_trust_factor(const VecX& dx) const;
  // ‖R‖∞ at a predictor's start (no Newton matrix).
  double start_residual(const StepContext& c, Predictor p, bool bordered) const;
  // (2/Δt) M + Δt ∂f/∂q + ½Δt Σ λ̂ᵢ Hᵢ(q_{n+½}) of the reduced schemes, λ̂ from r₀.
  system::SpMat reduced_stiffness(const VecX& qm, const system::SpMat& Gm, const VecX& r0,
                                  const system::SpMat& Kf, double dt) const;
  VecX configuration(const StepContext& c, const VecX& x, VecX* increment = nullptr) const;
  // The multipliers of the selected rows for the step qₙ → q1 (State::lambda, for the joint
  // reactions): the least-squares solution of G̃ᵀλ = −r₀/Δt, r₀ = M(vₙ₊₁ − vₙ) + Δt f, i.e. the
  // constrained form (DNSM-III (9)) that every formulation solves in its own unknowns — exact to
  // the Newton tolerance. Empty where G̃ is rank deficient (the step's reactions are not written).
  // mismatch, if given: ‖r₀/Δt + G̃ᵀλ‖∞, how far the step is from solving (9) (∞ if rank
  // deficient); a reduced step is refused above the Newton tolerance (attempt). dq is the step's
  // increment (configuration()): vₙ₊₁ = (2/Δt) dq − vₙ as in the Newton residual, not from
  // q1 − qₙ, which carries the rounding of q1 (docs/theory/schemes.md §7).
  VecX step_multipliers(const State& s, const VecX& q1, const VecX& dq, double dt, double t_mid,
                        double* mismatch = nullptr) const;

  const system::System& sys_;
  model::Solver settings_;
  bool bordered_ = false;
  bool reactions_ = false;  // some joint between frame nodes: State::lambda after every step
  // Joint drivers (system/joint_drivers.hpp): State::lambda and State::driver_work after every
  // step, whether reactions are written or not.
  bool drivers_ = false;
  // Rows Φ(q_{n+1}) = 0 of the reduced schemes are multiplied by (2/Δt)·(mean diagonal of M), the
  // scale of the rows 𝖯ᵀ(M(vₙ₊₁ − vₙ) + Δt f): the solution is unchanged and the condition
  // number of the Newton matrix no longer grows as Δt⁻¹ (docs/theory/schemes.md).
  double constraint_scale_ = 1.0;
  system::SpMat abs_mass_;  // |M| entrywise (reparametrized: residual_scale)
  // λ̂ of reduced_stiffness: the fill-reducing ordering of 𝖦𝖦ᵀ is kept while its pattern is
  // unchanged (a cache; an integrator is not shared between threads).
  mutable solve::NormalEquations normal_equations_;
  mutable solve::FixedPatternLU newton_lu_;  // keeps its column ordering while J keeps its pattern
  mutable VecX residual_, correction_, minus_residual_;  // workspaces of evaluate and correction
  mutable NewtonMatrix newton_matrix_;                   // attempt's Newton matrix
  // The last iterate of the step's Newton iteration, where the mixed tangent linearizes the
  // strains (none yet at a start).
  mutable VecX last_iterate_;
  mutable bool have_last_iterate_ = false;
  std::optional<system::TreeNewtonSolver> tree_;
  std::optional<ReducedNewtonMatrix> blocks_;
};

// The Snapshot of state s of sys (energies, momenta, max |Φ|, node poses, probes, resultants,
// patches) with the step's Newton figures; body_names name the first nodes.
Snapshot snapshot(const system::System& sys, const State& s, const StepStats& st,
                  const std::vector<std::string>& body_names);

}  // namespace isoflex::integrate
