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
#include <Eigen/SparseCore>
#include <functional>
#include <memory>
#include <string>
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
  // sparse LDLᵀ, otherwise (follower loads) and for the saddle-point system by sparse LU.
  bool symmetric = true;
  // r is affine in x (linear kinematics, dead loads): one solve per load step, no iteration.
  bool linear = false;
  // The leading entries of x that are configuration (the rest: multipliers of the problem's own
  // constraint rows, in force units); the correction test measures those only. −1: all of x.
  int configuration_size = -1;
};

using system::DofMap;
using system::LinearConstraints;

struct StaticSettings {
  double t_end = 1.0;
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
};

struct LoadStepStats {
  int step = 0;                          // 1, 2, … (accepted steps)
  double t = 0.0;                        // load parameter reached
  double dt = 0.0;                       // its increment
  int iterations = 0;                    // Newton corrections
  int cuts = 0;                          // failed attempts (halvings) before this step was accepted
  double residual = 0.0;                 // final ‖R‖∞
  std::vector<double> residual_history;  // ‖R‖∞ at every Newton iterate (first = start)
  double assembly_seconds = 0.0;         // residual/tangent evaluation and reduction
  double solve_seconds = 0.0;            // linear solves (factorization included)
  double wall_seconds = 0.0;             // the whole step, failed attempts included
};

struct StaticResult {
  VecX x;   // full configuration at t_end
  VecX mu;  // multipliers (size m)
  std::vector<LoadStepStats> steps;
  int analyses = 0;  // symbolic analyses of the sparse factorization
};

// Called after every accepted load step with its statistics (step, t, iterations, …) and x.
using StaticObserver = std::function<void(const LoadStepStats&, const VecX&)>;

class StaticNewtonSolver {
 public:
  // Throws std::invalid_argument for inconsistent sizes, bad settings (steps < 1, t_end not
  // finite, tolerances < 0) or a multiplier row that acts on eliminated dofs only.
  StaticNewtonSolver(StaticProblem problem, LinearConstraints constraints, StaticSettings settings);
  ~StaticNewtonSolver();
  StaticNewtonSolver(StaticNewtonSolver&&) noexcept;
  StaticNewtonSolver& operator=(StaticNewtonSolver&&) noexcept;

  // Runs the load stepping from x = X (plus the prescribed values) at t = 0.
  StaticResult solve(const StaticObserver& observer = {});
  const DofMap& dofs() const;
  const StaticSettings& settings() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace isoflex::integrate
