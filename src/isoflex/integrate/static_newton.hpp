#pragma once
// Static equilibrium by Newton's method with load stepping, for any problem given as a callable
// (x, t) → (r, K): r(x, t) = f_int(x) − f_ext(x, t) and K = ∂r/∂x (IGA-thesis §6.2.1 with the
// mass terms dropped: (6.3)–(6.4) per load step). Every System is one provider
// (static_equilibrium.hpp); tests use small nonlinear spring problems and a bare KL patch
// (tests/support/kl_static_problem.hpp).
//
// Boundary conditions enter as LinearConstraints (the output of KLBoundaryConditions):
//   • eliminated dofs (IGA-thesis §4.2.3): x_i = X_i + ū_i(t), removed from the unknowns;
//   • multiplier rows (IGA-thesis (3.37)–(3.40), (4.27)): C (x − X) = d(t), adding C^T μ to the
//     residual. Newton then solves the saddle-point system
//         [ K_ff  C_fᵀ ] [Δx_f]     [ r_f + C_fᵀ μ        ]
//         [ C_f   0    ] [Δμ  ] = − [ C (x − X) − d(t)    ]
//     over the free dofs f (the constraint rows are linear, so one Newton step satisfies them).
//
// Load stepping: t runs from 0 to t_end in `steps` equal increments (the levels t_end·k/steps
// exactly, not sums of increments); adaptive: an increment whose
// Newton iteration fails (max_iterations, a singular matrix, a non-finite residual) is retried
// from the last equilibrium with half the increment, never below the nominal increment / 2^max_cuts
// (the run stops there), and after grow_after consecutive steps that converged in
// ≤ easy_iterations iterations it is doubled
// again (never beyond the nominal increment). Convergence per step (the one Newton loop,
// integrate/newton_loop.hpp): ‖R‖∞ ≤ residual_tolerance · scale with scale = max(force_floor,
// ‖f_ext‖∞, ‖reactions‖∞), or a correction ‖Δx‖∞ ≤ increment_tolerance · max(‖x‖∞, ‖X‖∞) over the
// configuration entries of x (a round-off-level step). Failure: integrate::NewtonFailure naming the
// load step, the load factor tried and the one reached, the iterations and the residual reached; a
// residual that grew by six orders of magnitude (or overflowed) is reported as diverged, with the
// scale at the start of the step.
//
// Path following (PathSettings, docs/theory/path-following.md): past a limit point the load
// factor cannot be prescribed. The load parameter then becomes an unknown λ (the loads, the
// prescribed values and the rows' right-hand sides are evaluated at t = λ) and each step adds one
// equation, solved by bordering with the factorization of A (two right-hand sides):
//     A [δz_R  δz_λ] = −[R  ∂R/∂λ],   δz = δz_R + δλ δz_λ,
// ∂R/∂λ by a central difference in λ (exact to round-off for loads affine in t). The equation:
//   • displacement control: c·(x − X) = ū t/t_end at the nominal levels t (a point's displacement
//     along a direction, ū at t_end), δλ linear; the levels, halvings and growth as above;
//   • arc length (Crisfield 1981): ‖Δu‖² + ψ² s Δλ² = Δl² per step, Δu the increment of the free
//     configuration entries, s = ‖δu_λ‖² of the first step (ψ = 0: the cylindrical arc length);
//     δλ the root of the quadratic whose increment turns least (Crisfield's angle criterion);
//     the first step by load control over Δλ = t_end/steps, its length Δl₀ (or, with a given Δl₀,
//     along the tangent); then the secant of the last increment scaled to Δl as predictor, which
//     follows the path around limit points; Δl scaled by √(target/iterations) after
//     every step (within ½…2 per step and Δl₀/2^max_cuts … max_arc_length), halved after a
//     failure. It
//     ends where λ first reaches t_end (that step is redone at λ = t_end exactly, by load control
//     from the secant between the two points around it) or after max_steps steps.
// The convergence scale of a path step is at least ‖∂R/∂λ‖∞ t_end at the reference (forces of
// the full load), so that equilibria at a small load factor on the path are converged as
// accurately as the others.
#include <Eigen/SparseCore>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "isoflex/math/types.hpp"
#include "isoflex/system/linear_constraints.hpp"

namespace isoflex::integrate {

using SpMat = Eigen::SparseMatrix<double>;

// What a provider returns for one (x, t).
struct ResidualEvaluation {
  VecX r;   // f_int(x) − f_ext(x, t), full size n
  SpMat K;  // ∂r/∂x (n × n, compressed); only when asked. Keep the pattern fixed between calls
            // (the analysis of the sparse factorization is then kept).
  double load_norm = 0.0;  // ‖f_ext(x, t)‖∞, the size of the applied forces (convergence scale)
};

struct StaticProblem {
  VecX reference;  // X: the start configuration, origin of the prescribed displacements
  // Writes r (and K if with_tangent) into out; out is reused between calls (keep its storage).
  std::function<void(const VecX& x, double t, bool with_tangent, ResidualEvaluation& out)> evaluate;
  // K symmetric for every x, t (conservative problem): the reduced matrix is then factorized by
  // sparse Cholesky, a saddle-point one (multiplier rows) by the method of
  // StaticSettings::saddle_point; otherwise (follower loads) by sparse LU.
  bool symmetric = true;
  // r is affine in x (linear kinematics, dead loads): one solve per load step, no iteration.
  bool linear = false;
  // Called at the start of every step's Newton iteration with its start x and load parameter
  // (a provider that chooses equations per step chooses them here); optional.
  std::function<void(const VecX& x, double t)> begin_step;
  // The leading entries of x that are configuration (the rest: multipliers of the problem's own
  // constraint rows, in force units); the correction test measures those only. −1: all of x.
  int configuration_size = -1;
  // Offsets in x of the positions of points (x, y, z each), whose rigid-body motions span the
  // near null space that algebraic multigrid is given (solve::rigid_body_modes); optional.
  std::vector<int> points;
  // The interpolations of geometric multigrid on x (system/kl_multigrid.hpp): P_1 (rows: the
  // entries of x), P_2, …; asked for by the cg_multigrid solver only.
  std::function<std::vector<SpMat>()> transfer_operators;
  // P_1 interpolates from a space that is not inside the fine one (p-multigrid's lower degree,
  // system/kl_multigrid.hpp Coarsening): a coarse coordinate that reaches a held row is held too
  // (its function is not zero there; the rows left would not tell it from its neighbours).
  bool first_transfer_not_nested = false;
  // The problem of one MPI rank among several (docs/theory/solvers.md §6): r is the whole
  // residual, the same on every rank, but K is this rank's part, and the Newton matrix is their
  // sum, which only the PETSc solvers form (solve/krylov_backend.hpp). No direct solver, no
  // multiplier rows or tied coordinates, symmetric only (the constructor throws otherwise); a
  // failed PETSc solve fails the Newton iteration instead of falling back; automatic picks
  // geometric multigrid (or MUMPS without transfer_operators) whatever the size.
  bool distributed = false;
};

using system::DofMap;
using system::LinearConstraints;

enum class PathControl { load, displacement, arc_length };

struct PathSettings {
  PathControl control = PathControl::load;
  // displacement: the control c·(x − X) = displacement · t / t_end (entries of c by index of x)
  std::vector<std::pair<int, double>> control_vector;
  double displacement = 0.0;
  // arc length: Δl of the first step (0: the first step by load control over t_end / steps, its
  // length Δl₀), the load weight ψ, the Newton iterations a step aims at, and the most steps
  double arc_length = 0.0;
  double max_arc_length = 0.0;  // the longest step, the first included (0: 10 Δl₀)
  double load_weight = 0.0;
  int target_iterations = 6;
  int max_steps = 1000;
};

// The solver of Newton matrices with multiplier rows (a symmetric saddle point): a sparse LU of
// the whole matrix, or the augmented Lagrangian with a Cholesky factorization and GMRES
// (solve/saddle_point.hpp); automatic: the latter from kIterativeSaddlePointUnknowns unknowns
// on, the LU below (small systems solve as before, to the last digit).
enum class SaddlePointMethod { automatic, lu, augmented_lagrangian };
inline constexpr int kIterativeSaddlePointUnknowns = 20000;

// The solver of Newton matrices without multiplier rows (symmetric positive definite at a stable
// equilibrium): CHOLMOD's supernodal Cholesky, or a PETSc solver (solve/krylov_solver.hpp):
// conjugate gradients with GAMG, BoomerAMG or geometric multigrid over the knot hierarchy of the
// NURBS patches (StaticProblem::transfer_operators), as an inexact Newton (the forcing term of
// docs/theory/solvers.md §3), or MUMPS's Cholesky. A PETSc solve that fails (not positive
// definite past a limit point, no convergence) falls back to the direct solvers, counted in
// LoadStepStats::linear_solver_fallbacks. A Newton matrix with multiplier rows goes to the same
// PETSc solver as a saddle point (docs/theory/solvers.md §5: FGMRES on the augmented Lagrangian
// with a block preconditioner, the method's preconditioner on the primal block). automatic:
// geometric multigrid for a model of Kirchhoff–Love patches (where PETSc loads) from
// kAutomaticMultigridUnknowns unknowns on if its Newton matrix has no multiplier rows, from
// kAutomaticSaddlePointMultigridUnknowns on if its only rows are the LinearConstraints' (weak
// supports; not the problem's own rows, couplings and joints, where it was not measured to pay),
// from kAutomaticTiedMultigridUnknowns on if it has tied coordinates of its own (AF-D) and no
// multiplier rows, else direct: the crossovers of bench/large_shells.md.
enum class LinearSolverMethod { automatic, direct, cg_gamg, cg_hypre, mumps, cg_multigrid };
inline constexpr int kAutomaticMultigridUnknowns = 50000;
inline constexpr int kAutomaticSaddlePointMultigridUnknowns = 100000;
// AF-D's tied coordinates: the direct solver was faster at 6.3·10⁴ and 2·10⁵ unknowns (4.4
// against 8.6 s, 20.9 against 23.8 s), but its memory (5.26 GB at 2·10⁵, 9.45 GB at 3·10⁵: n^1.4)
// extrapolates past the 24 GB of the machines of bench/large_shells.md at about 6·10⁵ unknowns,
// where cg_multigrid fits (16.85 GB at 10⁶).
inline constexpr int kAutomaticTiedMultigridUnknowns = 400000;

struct StaticSettings {
  double t_end = 1.0;
  SaddlePointMethod saddle_point = SaddlePointMethod::automatic;
  LinearSolverMethod linear_solver = LinearSolverMethod::automatic;
  // The homogeneous rows of the LinearConstraints (symmetry and clamp slopes) tied instead of
  // given multipliers where a PETSc solver takes the Newton matrix (docs/theory/solvers.md §7);
  // false: multiplier rows always (the saddle-point path of §5).
  bool tie_homogeneous_rows = true;
  int steps = 1;  // nominal number of load increments (Δt = t_end / steps)
  bool adaptive = false;
  int max_cuts = 10;   // the increment is at least the nominal one / 2^max_cuts (adaptive)
  int grow_after = 2;  // easy steps in a row before the increment is doubled (adaptive)
  // A step is easy if it converged in at most this many iterations (a geometrically nonlinear
  // shell step takes about 10: a membrane-dominated first correction, then quadratic).
  int easy_iterations = 12;
  int max_iterations = 25;
  double residual_tolerance = 1e-10;
  double increment_tolerance = 1e-12;
  double force_floor = 0.0;  // lower bound of the residual scale (in force units)
  PathSettings path;
};

struct LoadStepStats {
  int step = 0;    // 1, 2, … (accepted steps)
  double t = 0.0;  // load parameter reached (the load factor λ)
  // The path parameter: t under load control, the control displacement c·(x − X), the arc length
  // from the start (the sum of the steps' Δl).
  double path = 0.0;
  double dt = 0.0;                       // its increment
  int iterations = 0;                    // Newton corrections
  int cuts = 0;                          // failed attempts (halvings) before this step was accepted
  double residual = 0.0;                 // final ‖R‖∞
  std::vector<double> residual_history;  // ‖R‖∞ at every Newton iterate (first = start)
  double assembly_seconds = 0.0;         // residual/tangent evaluation and reduction
  double solve_seconds = 0.0;            // linear solves (factorization included)
  double wall_seconds = 0.0;             // the whole step, failed attempts included
  // Krylov iterations in all (GMRES of the augmented Lagrangian, CG of a PETSc solver), and
  // saddle-point solves that fell back to the sparse LU (Â not positive definite, GMRES short of
  // its tolerance).
  int krylov_iterations = 0;
  int saddle_point_fallbacks = 0;
  // PETSc solves (StaticSettings::linear_solver) that fell back to the direct solvers.
  int linear_solver_fallbacks = 0;
  std::string linear_solver_fallback_reason;  // the last one's (PETSc's reason)
};

struct StaticResult {
  VecX x;   // full configuration at t_end
  VecX mu;  // multipliers (size m)
  std::vector<LoadStepStats> steps;
  int analyses = 0;  // symbolic analyses of the sparse factorization
  // Why an arc-length run ended before λ reached t_end (max_steps), else empty.
  std::string stopped;
};

// Called after every accepted load step with its statistics (step, t, iterations, …) and x.
using StaticObserver = std::function<void(const LoadStepStats&, const VecX&)>;

class StaticNewtonSolver {
 public:
  // Throws std::invalid_argument for inconsistent sizes, bad settings (steps < 1, t_end not
  // finite, tolerances < 0, path following of a linear problem, a control vector out of range or
  // on eliminated entries only) or a multiplier row that acts on eliminated dofs only.
  StaticNewtonSolver(StaticProblem problem, LinearConstraints constraints, StaticSettings settings);
  ~StaticNewtonSolver();
  StaticNewtonSolver(StaticNewtonSolver&&) noexcept;
  StaticNewtonSolver& operator=(StaticNewtonSolver&&) noexcept;

  // Runs the load stepping from x = X (plus the prescribed values) at t = 0.
  StaticResult solve(const StaticObserver& observer = {});
  const DofMap& dofs() const;
  // Multiplier rows implied by the tied rows (and the others): kept with the equation μᵢ = 0.
  int implied_multiplier_rows() const;
  // The multiplier rows of the Newton matrix, and the homogeneous rows of the constraints given
  // (LinearConstraints::homogeneous: symmetry and clamp slopes) that were tied instead: a PETSc
  // solver takes the Newton matrix (docs/theory/solvers.md §7). Their multipliers in
  // StaticResult::mu are 0.
  int multiplier_rows() const;
  int tied_homogeneous_rows() const;
  const StaticSettings& settings() const;
  // "direct" (CHOLMOD, UMFPACK, the saddle-point solver), or the PETSc solver of the Newton
  // matrices (StaticSettings::linear_solver; automatic: by size).
  const char* linear_solver() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace isoflex::integrate
