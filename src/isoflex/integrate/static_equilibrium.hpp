#pragma once
// Static equilibrium of any System by load stepping: the one static solver (StaticNewtonSolver,
// static_newton.hpp) on the System's static problem. The time t of the load functions is read as
// a load parameter, and at each level the solver finds x = (q, λ) with
//   R(x, t) = [ ∇V(q) − f_ext(q, t) + G(q)ᵀ λ ;  Φ_sel(q) − C λ ] = 0  (DNSM-III (9) without M)
// with the Newton matrix
//   J = [ ∇²V − ∂f_ext/∂q + Σ λᵢ Hᵢ(q) ,  Gᵀ ;  G , −C ]
// (the constraint Hessians Hᵢ; ∇V and ∇²V from each element's gradient_in_pattern,
// elements/element.hpp; C the diagonal of the rows' compliances, System::selected_compliance():
// 0 but for perturbed Lagrange rows, IGA-thesis (5.24b)). Rows reselected in every load step
// (System::reselected_groups(): the AF-BS strip forces of a nonlinear analysis) that are not
// kept in this step have the equation λᵢ = 0 instead. Φ_sel are the selected rows of System:
// the nodes' internal rows and the joints. The System's linear conditions (linear_constraints(): a
// Kirchhoff–Love patch's supports in a static analysis) are the solver's eliminated coordinates and
// multiplier rows. A model of Kirchhoff–Love patches alone has no Φ_sel rows: then J = K, symmetric
// for dead loads, and solved by sparse Cholesky (docs/theory/kl-static.md).
//
// Settings from model::Solver: load increment dt up to t_end (nominal levels k·dt); a failing
// increment is halved, at most max_subdivisions times, and after easy steps the increment grows
// back onto the nominal levels (static_newton.hpp); max_iterations and the tolerances; path
// following (arc length, displacement control of a probe; static_newton.hpp). The
// convergence scale is the size of the forces that balance: max(‖f_ext‖∞, ‖Gᵀλ‖∞, the reactions
// of the linear conditions). `linear`: the geometrically linear problem, R linearized at the
// unloaded reference (q₀, 0), one solve per load step; a patch with linear kinematics
// (elements::KLKinematics::linear) is already affine and is evaluated as it is. `formulation` and
// the mass data are ignored.
#include <memory>
#include <string>

#include "isoflex/integrate/newton_loop.hpp"  // NewtonFailure
#include "isoflex/integrate/static_newton.hpp"
#include "isoflex/model/model.hpp"
#include "isoflex/system/system.hpp"

namespace isoflex::integrate {

// The load-stepping settings of a model's solver entry.
StaticSettings static_settings(const model::Solver& s);
// The same with the control vector of displacement control: the gradient of the probe's
// displacement along the direction (System::probe_gradient).
StaticSettings static_settings(const model::Solver& s, const system::System& sys);

// Why a System cannot be solved on several MPI ranks with these settings (empty: it can).
// Distributed (docs/theory/solvers.md §6) are the models of Kirchhoff–Love patches alone
// (point nodes, no other elements, no rows of System, no multiplier rows or tied coordinates in
// its linear conditions: supports that eliminate coordinates), with dead loads and a PETSc
// solver (not `direct`).
std::string why_not_distributed(const system::System& sys, const model::Solver& settings);

// R(x, t) and J of the header for a System, x = (q, λ_sel). A System whose patches are
// partitioned (System::partition_kl_patches, an MPI run) gives a distributed problem: R is summed
// over the ranks (each rank's elements; the loads counted once), J is each rank's own part
// (StaticProblem::distributed). Throws std::invalid_argument if such a System cannot be
// distributed (why_not_distributed with linear_solver auto).
StaticProblem static_problem(
    const system::System& sys, bool linear,
    model::MultigridCoarsening coarsening = model::MultigridCoarsening::knots);

class StaticEquilibrium {
 public:
  StaticEquilibrium(const system::System& sys, const model::Solver& settings);

  // Newton unknowns: free coordinates, multipliers of the linear conditions, selected rows.
  int unknowns() const;
  int eliminated() const { return static_cast<int>(sys_.linear_constraints().eliminated.size()); }
  // The multiplier rows of the linear conditions (those not tied).
  int multipliers() const { return solver_.multiplier_rows(); }
  // The homogeneous rows of the linear conditions (symmetry and clamp slopes) tied instead of
  // given multipliers (a PETSc solver: docs/theory/solvers.md §7).
  int tied_rows() const { return solver_.tied_homogeneous_rows(); }
  // The slave coordinates of the tied rows (AF-D's straight triples, the tied homogeneous rows)
  // and the rows dropped as implied by the others.
  int tied() const { return static_cast<int>(solver_.dofs().slaves.size()); }
  int dropped_tied_rows() const { return solver_.dofs().dropped_tied_rows; }
  // Multiplier rows that the tied rows imply (their multipliers 0).
  int implied_multipliers() const { return solver_.implied_multiplier_rows(); }
  // The degrees of freedom: coordinates less the selected rows, the eliminated and slave
  // coordinates and the independent multiplier rows.
  int dof() const {
    return sys_.n() - sys_.m_selected() - eliminated() - tied() -
           (multipliers() - implied_multipliers());
  }
  const StaticSettings& settings() const { return solver_.settings(); }
  const char* linear_solver() const { return solver_.linear_solver(); }
  bool linear() const { return linear_; }
  // The load stepping from (q₀, 0); observer(stats, x) after every accepted load step with
  // x = (q, λ) (q = x.head(sys.n())). Throws NewtonFailure when a step fails for good.
  StaticResult solve(const StaticObserver& observer = {}) { return solver_.solve(observer); }
  // R(x, t) and (if J is not null) J(x, t) (tests).
  VecX residual(double t, const VecX& x, MatX* J) const;
  // The 2-norm condition number of J(x, t) over the unknowns the solver solves for (the eliminated
  // coordinates removed): dense SVD, for studies (bench/kl_multipatch_bench), not for runs.
  double newton_matrix_condition(double t, const VecX& x) const;

 private:
  const system::System& sys_;
  bool linear_;
  StaticProblem problem_;
  StaticNewtonSolver solver_;
};

}  // namespace isoflex::integrate
