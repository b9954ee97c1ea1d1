#include "isoflex/integrate/static_equilibrium.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <utility>

#include "isoflex/solve/linear_solver.hpp"
#include "isoflex/solve/process_group.hpp"
#include "isoflex/system/kl_multigrid.hpp"
#include "isoflex/system/row_selection.hpp"

namespace isoflex::integrate {

using system::SpMat;

StaticSettings static_settings(const model::Solver& s) {
  StaticSettings out;
  out.t_end = s.t_end;
  out.steps = std::max(1, static_cast<int>(std::lround(s.t_end / s.dt)));
  out.adaptive = s.max_subdivisions > 0;
  if (out.adaptive) out.max_cuts = s.max_subdivisions;
  out.max_iterations = s.max_iterations;
  out.residual_tolerance = s.residual_tolerance;
  out.increment_tolerance = s.increment_tolerance;
  out.saddle_point = s.saddle_point_solver == model::SaddlePointSolver::lu ? SaddlePointMethod::lu
                     : s.saddle_point_solver == model::SaddlePointSolver::augmented_lagrangian
                         ? SaddlePointMethod::augmented_lagrangian
                         : SaddlePointMethod::automatic;
  out.tie_homogeneous_rows = !s.support_rows_as_multipliers;
  switch (s.linear_solver) {
    case model::LinearSolver::automatic:
      out.linear_solver = LinearSolverMethod::automatic;
      break;
    case model::LinearSolver::direct:
      out.linear_solver = LinearSolverMethod::direct;
      break;
    case model::LinearSolver::cg_gamg:
      out.linear_solver = LinearSolverMethod::cg_gamg;
      break;
    case model::LinearSolver::cg_hypre:
      out.linear_solver = LinearSolverMethod::cg_hypre;
      break;
    case model::LinearSolver::mumps:
      out.linear_solver = LinearSolverMethod::mumps;
      break;
    case model::LinearSolver::cg_multigrid:
      out.linear_solver = LinearSolverMethod::cg_multigrid;
      break;
  }
  const model::PathFollowing& f = s.path;
  out.path.control = f.method == model::PathMethod::arc_length     ? PathControl::arc_length
                     : f.method == model::PathMethod::displacement ? PathControl::displacement
                                                                   : PathControl::load;
  out.path.arc_length = f.arc_length;
  out.path.max_arc_length = f.max_arc_length;
  out.path.load_weight = f.load_weight;
  out.path.target_iterations = f.target_iterations;
  out.path.max_steps = f.max_steps;
  out.path.displacement = f.displacement;
  return out;
}

StaticSettings static_settings(const model::Solver& s, const system::System& sys) {
  StaticSettings out = static_settings(s);
  if (out.path.control != PathControl::displacement) return out;
  const auto& probes = sys.probes();
  const auto it = std::find_if(probes.begin(), probes.end(), [&](const system::ProbeInstance& p) {
    return p.name == s.path.probe;
  });
  if (it == probes.end())
    throw std::invalid_argument("solver.path_following.probe: no probe named \"" + s.path.probe +
                                "\"");
  out.path.control_vector = sys.probe_gradient(*it, s.path.direction);
  return out;
}

namespace {

// Loads whose force depends on q (follower pressure, moments that turn with a director): their
// tangent is not symmetric.
bool has_follower_loads(const system::System& sys) {
  return std::any_of(sys.loads().begin(), sys.loads().end(),
                     [](const auto& L) { return L->follower(); });
}

// The selected rows of the System's reselected groups that are not kept at q: per group, the
// group.rank rows of the largest pivots of the full-pivot LU of its rows modulo the linear
// conditions and the rows kept in the groups before it (IGA-thesis Alg. 5.1, (5.35);
// system::select_group_rows), a mask over the m selected rows.
// The count stays that of the reference: off the constraint manifold the strip's stress adds
// rank (geometric stiffness) that the constraints do not have. At the reference itself (the first
// load step) the choice is the one System::compile made there (the same factorizations: the rank
// leading pivots are the independent rows) — on a 20-patch plate of 1.2·10⁵ unknowns the joint
// selection takes 17 s.
std::vector<bool> dropped_rows(const system::System& sys, const VecX& q) {
  std::vector<bool> out(static_cast<std::size_t>(sys.m_selected()), false);
  std::vector<int> counts;
  std::vector<std::vector<int>> reference;
  for (const auto& g : sys.reselected_groups()) {
    counts.push_back(g.rank);
    reference.push_back(g.reference_rows);
    for (int p : g.positions) out[static_cast<std::size_t>(p)] = true;
  }
  const auto chosen = q == sys.q0()
                          ? reference
                          : system::select_group_rows(sys.reselected_group_jacobians(q), counts);
  for (std::size_t k = 0; k < chosen.size(); ++k)
    for (int i : chosen[k])
      out[static_cast<std::size_t>(
          sys.reselected_groups()[k].positions[static_cast<std::size_t>(i)])] = false;
  return out;
}

// The rows dropped in the current load step: chosen at the start of its Newton iteration
// (StaticProblem::begin_step; for a bare evaluation, at the first one at a new t) and kept for the
// step, so that the equations do not change between iterations (a selection in every iteration
// switches rows back and forth off the manifold and stalls Newton, as the thesis warns after
// (5.34)). A path-following step evaluates at many t: its selection is pinned to the step.
struct RowSelection {
  double t = std::numeric_limits<double>::quiet_NaN();
  std::vector<bool> dropped;
  bool pinned = false;
};

// [A Gᵀ; G D] in compressed columns, written column by column (A and G compressed: no sort),
// D's diagonal entries where on_diagonal (the pattern a triplet assembly of the same entries
// gives, so that the factorizations see the same matrix).
void bordered_matrix(const SpMat& A, const SpMat& G, const VecX& diagonal,
                     const std::vector<bool>& on_diagonal, SpMat& out) {
  const int n = static_cast<int>(A.rows()), m = static_cast<int>(G.rows());
  const Eigen::SparseMatrix<double, Eigen::RowMajor> Gr = G;
  out.resize(n + m, n + m);
  out.resizeNonZeros(A.nonZeros() + 2 * G.nonZeros() +
                     std::count(on_diagonal.begin(), on_diagonal.end(), true));
  int* outer = out.outerIndexPtr();
  int* inner = out.innerIndexPtr();
  double* value = out.valuePtr();
  int k = 0;
  const auto put = [&](int row, double v) {
    inner[k] = row;
    value[k++] = v;
  };
  for (int j = 0; j < n; ++j) {
    outer[j] = k;
    for (SpMat::InnerIterator it(A, j); it; ++it) put(static_cast<int>(it.row()), it.value());
    for (SpMat::InnerIterator it(G, j); it; ++it) put(n + static_cast<int>(it.row()), it.value());
  }
  for (int i = 0; i < m; ++i) {
    outer[n + i] = k;
    for (decltype(Gr)::InnerIterator it(Gr, i); it; ++it)
      put(static_cast<int>(it.col()), it.value());
    if (on_diagonal[static_cast<std::size_t>(i)]) put(n + i, diagonal(i));
  }
  outer[n + m] = k;
}

// R(x, t) of the header and, if with_tangent, J in out.K; out.load_norm the force scale. The
// reselected rows not kept (RowSelection) get the equation λᵢ = 0 instead, their forces and
// Hessians left out.
void evaluate(const system::System& sys, RowSelection& selection, const VecX& x, double t,
              bool with_tangent, ResidualEvaluation& out) {
  const int n = sys.n(), m = sys.m_selected();
  const VecX q = x.head(n);
  double load_norm = 0.0;
  if (m == 0) {  // K straight into out.K, whose storage is kept between calls
    out.r = sys.static_force(q, t, with_tangent ? &out.K : nullptr, &load_norm);
    out.load_norm = load_norm;
    return;
  }
  SpMat K;
  const VecX f = sys.static_force(q, t, with_tangent ? &K : nullptr, &load_norm);
  const VecX lambda = x.tail(m);
  SpMat G = sys.jacobian(q);
  if (!selection.pinned && !(selection.t == t)) selection = {t, dropped_rows(sys, q), false};
  const std::vector<bool>& dropped = selection.dropped;
  VecX lambda_kept = lambda;
  if (!sys.reselected_groups().empty()) {
    VecX keep = VecX::Ones(m);
    for (int i = 0; i < m; ++i)
      if (dropped[static_cast<std::size_t>(i)]) keep(i) = lambda_kept(i) = 0.0;
    G = keep.asDiagonal() * G;
  }
  const VecX reactions = G.transpose() * lambda_kept;
  out.r.resize(n + m);
  out.r.head(n) = f + reactions;
  const VecX phi = sys.constraints(q, t);
  const VecX& compliance = sys.selected_compliance();
  for (int i = 0; i < m; ++i)
    out.r(n + i) = dropped[static_cast<std::size_t>(i)]
                       ? lambda(i)
                       : phi(sys.selected_rows()[i]) - compliance(i) * lambda(i);
  out.load_norm = std::max(load_norm, reactions.lpNorm<Eigen::Infinity>());
  if (!with_tangent) return;
  const SpMat A = K + sys.constraint_hessian(q, lambda_kept);
  VecX diagonal = VecX::Zero(m);  // the multiplier block: −compliance, 1 for a dropped row
  std::vector<bool> on_diagonal(static_cast<std::size_t>(m), false);
  for (int i = 0; i < m; ++i) {
    const bool drop = dropped[static_cast<std::size_t>(i)];
    on_diagonal[static_cast<std::size_t>(i)] = compliance(i) != 0.0 || drop;
    diagonal(i) = -compliance(i) + (drop ? 1.0 : 0.0);
  }
  bordered_matrix(A, G, diagonal, on_diagonal, out.K);
}

}  // namespace

std::string why_not_distributed(const system::System& sys, const model::Solver& settings) {
  if (settings.analysis != model::Analysis::statics)
    return "dynamic analyses run on one process only (use --static, or run without mpirun)";
  if (settings.linear_solver == model::LinearSolver::direct)
    return "solver.linear_solver direct (CHOLMOD) runs on one process only: choose cg_multigrid, "
           "cg_gamg, cg_hypre or mumps (or auto)";
  std::size_t strips = 0;
  for (const system::KLInterfaceInstance& I : sys.kl_interfaces())
    if (I.element_index >= 0) ++strips;
  if (sys.kl_patches().empty() || sys.elements().size() != sys.kl_patches().size() + strips ||
      sys.node_count(NodeKind::point) != sys.node_count())
    return "only models of Kirchhoff-Love patches alone (and their bending strips) are "
           "distributed (this one has other bodies or elements)";
  if (sys.m_selected() > 0)
    return fmt::format(
        "the model has {} constraint rows (patch couplings or joints): their saddle point is "
        "solved on one process only",
        sys.m_selected());
  // The homogeneous support rows (symmetry planes, clamp slopes) are tied on every rank alike
  // (StaticNewtonSolver, docs/theory/solvers.md §7), and so are the model's tied coordinates;
  // the other rows would stay multiplier rows.
  const system::LinearConstraints& c = sys.linear_constraints();
  const auto label = [&c](int r) {
    return static_cast<std::size_t>(r) < c.row_labels.size() &&
                   !c.row_labels[static_cast<std::size_t>(r)].empty()
               ? c.row_labels[static_cast<std::size_t>(r)]
               : fmt::format("row {}", r);
  };
  if (settings.support_rows_as_multipliers && c.multipliers() > 0)
    return fmt::format(
        "solver.support_rows: multipliers keeps the supports' {} rows (the first: {}) as "
        "multiplier rows, whose saddle point is solved on one process only (leave support_rows "
        "out to tie them)",
        c.multipliers(), label(0));
  std::vector<int> kept;
  for (int r = 0; r < c.multipliers(); ++r)
    if (!c.is_homogeneous(r)) kept.push_back(r);
  if (!kept.empty())
    return fmt::format(
        "the supports have {} rows with a prescribed value or a weak condition (the first: {}): "
        "their saddle point is solved on one process only",
        kept.size(), label(kept.front()));
  if (has_follower_loads(sys))
    return "follower loads (pressure that turns with the shell) give an unsymmetric matrix, "
           "solved on one process only";
  return {};
}

StaticProblem static_problem(const system::System& sys, bool linear,
                             model::MultigridCoarsening coarsening) {
  const int n = sys.n(), m = sys.m_selected();
  const bool follower = has_follower_loads(sys);
  // Patches alone: the patch's own kinematics decides whether R is affine.
  const bool patches_only = m == 0 && sys.node_count(NodeKind::point) == sys.node_count();
  StaticProblem pb;
  pb.reference = VecX::Zero(n + m);
  pb.reference.head(n) = sys.q0();
  pb.configuration_size = n;
  pb.symmetric = !follower;
  pb.linear = linear && !(patches_only && follower);
  for (int i = 0; i < sys.node_count(); ++i)
    if (sys.node_kind(i) == NodeKind::point) pb.points.push_back(sys.q_offset(i));
  const system::System* S = &sys;
  if (!sys.kl_patches().empty()) {
    const system::Coarsening how = coarsening == model::MultigridCoarsening::degree
                                       ? system::Coarsening::degree_then_knots
                                       : system::Coarsening::knots;
    pb.first_transfer_not_nested = system::first_level_lowers_degree(sys, how);
    pb.transfer_operators = [S, how] { return system::kl_transfer_operators(*S, 3000, how); };
  }
  auto selection = std::make_shared<RowSelection>();
  // Every load step starts from the last equilibrium: the elements keep their history from it
  // (System::accept), and rows reselected at every step are chosen there.
  const bool reselect = !sys.reselected_groups().empty();
  pb.begin_step = [S, selection, reselect](const VecX& x, double t) {
    S->accept(x.head(S->n()));
    if (reselect) *selection = {t, dropped_rows(*S, x.head(S->n())), true};
  };
  if (sys.kl_parts() > 1) {
    model::Solver automatic;
    automatic.analysis = model::Analysis::statics;
    if (const std::string why = why_not_distributed(sys, automatic); !why.empty())
      throw std::invalid_argument("a run on several MPI ranks: " + why);
    const solve::ProcessGroup& group = solve::processes();
    if (group.size() != sys.kl_parts())
      throw std::invalid_argument(fmt::format("the patches are cut into {} parts for {} MPI ranks",
                                              sys.kl_parts(), group.size()));
    pb.distributed = true;
    pb.evaluate = [S, selection, &group](const VecX& x, double t, bool with_tangent,
                                         ResidualEvaluation& out) {
      evaluate(*S, *selection, x, t, with_tangent, out);
      // out.r is this rank's elements' internal force less the whole external force, which must
      // be counted once: on rank 0. (A second evaluation of the loads on the other ranks; the
      // System has no call for its internal force alone.)
      if (group.rank() != 0) out.r += S->external_force(x.head(S->n()), t);
      group.sum(out.r.data(), static_cast<long>(out.r.size()));
    };
    return pb;
  }
  if (!linear || patches_only) {
    pb.evaluate = [S, selection](const VecX& x, double t, bool with_tangent,
                                 ResidualEvaluation& out) {
      evaluate(*S, *selection, x, t, with_tangent, out);
    };
    return pb;
  }
  // Geometrically linear: R(X, t) + J(X, t) (x − X), linearized at the unloaded reference.
  const VecX X = pb.reference;
  pb.evaluate = [S, X, selection](const VecX& x, double t, bool, ResidualEvaluation& out) {
    evaluate(*S, *selection, X, t, true, out);
    out.r += out.K * (x - X);
  };
  return pb;
}

namespace {

// The System's linear conditions over x = (q, λ_sel): C gets zero columns for the multipliers of
// the selected rows (a model with both, e.g. KL supports and multipatch coupling rows).
system::LinearConstraints over_unknowns(const system::System& sys) {
  system::LinearConstraints c = sys.linear_constraints();
  c.C.conservativeResize(c.C.rows(), sys.n() + sys.m_selected());
  return c;
}

}  // namespace

StaticEquilibrium::StaticEquilibrium(const system::System& sys, const model::Solver& settings)
    : sys_(sys),
      linear_(settings.linear),
      problem_(static_problem(sys, settings.linear, settings.multigrid_coarsening)),
      solver_(problem_, over_unknowns(sys), static_settings(settings, sys)) {}

int StaticEquilibrium::unknowns() const {
  return solver_.dofs().n_free() + multipliers();
}

VecX StaticEquilibrium::residual(double t, const VecX& x, MatX* J) const {
  ResidualEvaluation ev;
  problem_.evaluate(x, t, J != nullptr, ev);
  if (J) *J = MatX(ev.K);
  return ev.r;
}

double StaticEquilibrium::newton_matrix_condition(double t, const VecX& x) const {
  MatX J;
  residual(t, x, &J);
  const system::DofMap& map = solver_.dofs();
  MatX T = MatX::Zero(J.rows(), map.n_free());  // x − X = T u (+ prescribed)
  for (int i = 0; i < static_cast<int>(J.rows()); ++i)
    for (const auto& [f, w] : map.expansion(i)) T(i, f) = w;
  const MatX Jf = T.transpose() * J * T;
  return solve::condition_number(Jf);
}

}  // namespace isoflex::integrate
