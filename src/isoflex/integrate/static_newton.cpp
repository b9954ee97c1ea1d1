#include "isoflex/integrate/static_newton.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <stdexcept>
#include <type_traits>
#include <utility>

#include "isoflex/integrate/arc_length.hpp"
#include "isoflex/integrate/newton_loop.hpp"
#include "isoflex/math/sparse_pattern.hpp"
#include "isoflex/solve/krylov_solver.hpp"
#include "isoflex/solve/linear_solver.hpp"
#include "isoflex/solve/saddle_point.hpp"

namespace isoflex::integrate {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

double inf_norm(const VecX& v) {
  return v.size() ? v.lpNorm<Eigen::Infinity>() : 0.0;
}

// The relative tolerance of a PETSc solve that is not a Newton step's (docs/theory/solvers.md §3).
constexpr double kKrylovTightTolerance = 1e-10;
// Solves of the augmented system per saddle-point solve, each from M's true residual.
constexpr int kKrylovRefinementCycles = 5;
// A saddle-point solve whose normwise backward error is this is accepted (round-off of M z).
constexpr double kKrylovBackwardError = 1e-13;
// The relative tolerance of one cycle of the saddle-point solve (krylov_saddle_point_solve), at
// least: 10⁻¹⁰ left the quarter roof at 2·10³ unknowns 10⁻⁷ from the LU's solution, 10⁻¹¹ 10⁻⁸,
// 10⁻¹² 10⁻⁹ (StaticPetsc.SaddlePoint*).
constexpr double kSaddlePointCycleTolerance = 1e-12;
// The augmented Lagrangian's penalty factor α of the PETSc path (SaddlePointOptions).
constexpr double kKrylovPenaltyFactor = 1.0;

}  // namespace

struct StaticNewtonSolver::Impl {
  StaticProblem problem;
  LinearConstraints cons;
  StaticSettings settings;
  DofMap dofs;
  int n = 0, nf = 0, m = 0;
  SpMat Cf;  // C on the free dofs (m × nf), the implied rows zero
  // Multiplier rows that the tied rows imply (C T dependent on the other rows: a symmetry row
  // on an interface whose G¹ rows are tied): their equation is μᵢ = 0 instead.
  std::vector<bool> implied;
  int implied_count = 0;
  // The rows of the constraints given (original_rows) kept as multiplier rows when the
  // homogeneous ones were tied (tie_homogeneous_rows; empty: all kept), and the slave
  // coordinates those ties added (their residual is the rows' reaction: convergence scale).
  int original_rows = 0;
  bool given_ties = false;  // the constraints given had tied rows (AF-D)
  std::vector<int> kept_rows;
  std::vector<int> reaction_slaves;

  void drop_implied_rows() {
    std::vector<int> cols;
    for (int j = 0; j < Cf.outerSize(); ++j)
      if (Cf.outerIndexPtr()[j + 1] > Cf.outerIndexPtr()[j]) cols.push_back(j);
    MatX D = MatX::Zero(m, static_cast<Eigen::Index>(cols.size()));
    for (std::size_t c = 0; c < cols.size(); ++c)
      for (SpMat::InnerIterator it(Cf, cols[c]); it; ++it)
        D(it.row(), static_cast<Eigen::Index>(c)) = it.value();
    implied.assign(static_cast<std::size_t>(m), true);
    for (int r : solve::independent_rows_lu(D)) implied[static_cast<std::size_t>(r)] = false;
    implied_count = static_cast<int>(std::count(implied.begin(), implied.end(), true));
    if (implied_count == 0) return;
    Cf.prune([&](Eigen::Index r, Eigen::Index, double) {
      return !implied[static_cast<std::size_t>(r)];
    });
  }

  // The free dofs and the rows from cons: the DofMap of the eliminated dofs and tied rows, C on
  // the free columns, the implied rows; throws for a row on eliminated dofs only.
  void set_up_rows() {
    dofs = DofMap::build(n, cons.eliminated, cons.tied);
    nf = dofs.n_free();
    nf_configuration = problem.configuration_size < 0
                           ? nf
                           : static_cast<int>(std::lower_bound(dofs.free.begin(), dofs.free.end(),
                                                               problem.configuration_size) -
                                              dofs.free.begin());
    m = static_cast<int>(cons.C.rows());
    implied.assign(static_cast<std::size_t>(m), false);
    // C on the free columns.
    std::vector<Eigen::Triplet<double>> trip;
    for (int j = 0; j < cons.C.outerSize(); ++j)
      for (const auto& [fj, w] : dofs.expansion(j))
        for (SpMat::InnerIterator it(cons.C, j); it; ++it)
          if (it.value() != 0.0) trip.emplace_back(static_cast<int>(it.row()), fj, w * it.value());
    Cf.resize(m, nf);
    Cf.setFromTriplets(trip.begin(), trip.end());
    Cf.makeCompressed();
    VecX row_norm = VecX::Zero(m);
    for (const auto& t : trip) row_norm(t.row()) += t.value() * t.value();
    if (!dofs.slaves.empty() && m > 0) drop_implied_rows();
    for (int r = 0; r < m; ++r)
      if (row_norm(r) == 0.0 && !implied[static_cast<std::size_t>(r)]) {
        const std::string label = static_cast<std::size_t>(r) < cons.row_labels.size()
                                      ? " (" + cons.row_labels[static_cast<std::size_t>(r)] + ")"
                                      : std::string();
        throw std::invalid_argument(fmt::format(
            "LinearConstraints: multiplier row {}{} acts on eliminated dofs only", r, label));
      }
    if (problem.distributed) {
      // Tied coordinates are not refused: Tᵀ K T is the sum of the ranks' Tᵀ K_r T, and the
      // residual is whole on every rank before its reduction.
      const char* why = m > 0                ? "multiplier rows"
                        : !problem.symmetric ? "an unsymmetric matrix"
                        : settings.linear_solver == LinearSolverMethod::direct ? "the direct solver"
                                                                               : nullptr;
      if (why)
        throw std::invalid_argument(
            fmt::format("StaticNewtonSolver: a distributed problem (MPI) with {}", why));
    }
  }

  // The homogeneous rows of cons as tied rows (master–slave, DofMap), the others kept as
  // multiplier rows (kept_rows: their indices in the constraints given); reaction_slaves: the
  // slave coordinates the ties add, whose residual is the rows' reaction.
  void tie_homogeneous_rows() {
    const std::vector<int> slaves_before = [&] {
      std::vector<int> out;
      for (const auto& sl : DofMap::build(n, cons.eliminated, cons.tied).slaves)
        out.push_back(sl.dof);
      return out;
    }();
    std::vector<std::vector<std::pair<int, double>>> rows(static_cast<std::size_t>(cons.C.rows()));
    for (int j = 0; j < cons.C.outerSize(); ++j)
      for (SpMat::InnerIterator it(cons.C, j); it; ++it)
        if (it.value() != 0.0) rows[static_cast<std::size_t>(it.row())].emplace_back(j, it.value());
    kept_rows.clear();
    std::vector<int> new_index(rows.size(), -1);
    std::vector<std::string> labels;
    for (int r = 0; r < static_cast<int>(rows.size()); ++r) {
      if (cons.is_homogeneous(r)) {
        cons.tied.push_back(std::move(rows[static_cast<std::size_t>(r)]));
        continue;
      }
      new_index[static_cast<std::size_t>(r)] = static_cast<int>(kept_rows.size());
      kept_rows.push_back(r);
      if (static_cast<std::size_t>(r) < cons.row_labels.size())
        labels.push_back(cons.row_labels[static_cast<std::size_t>(r)]);
    }
    std::vector<Eigen::Triplet<double>> t;
    for (int j = 0; j < cons.C.outerSize(); ++j)
      for (SpMat::InnerIterator it(cons.C, j); it; ++it)
        if (const int r = new_index[static_cast<std::size_t>(it.row())]; r >= 0)
          t.emplace_back(r, j, it.value());
    SpMat C(static_cast<Eigen::Index>(kept_rows.size()), n);
    C.setFromTriplets(t.begin(), t.end());
    C.makeCompressed();
    cons.C = std::move(C);
    cons.row_labels = std::move(labels);
    cons.homogeneous.clear();
    if (cons.rhs) {
      cons.rhs = [rhs = std::move(cons.rhs), kept = kept_rows](double time) {
        const VecX d = rhs(time);
        VecX out(static_cast<Eigen::Index>(kept.size()));
        for (std::size_t k = 0; k < kept.size(); ++k)
          out(static_cast<Eigen::Index>(k)) = d(kept[k]);
        return out;
      };
    }
    reaction_slaves.clear();
    for (const auto& sl : DofMap::build(n, cons.eliminated, cons.tied).slaves)
      if (!std::binary_search(slaves_before.begin(), slaves_before.end(), sl.dof))
        reaction_slaves.push_back(sl.dof);
  }

  // The multipliers of the constraints given from those of the rows kept (a tied row's: 0).
  VecX given_multipliers(const VecX& mu) const {
    if (kept_rows.empty() && original_rows == m) return mu;
    VecX out = VecX::Zero(original_rows);
    for (std::size_t k = 0; k < kept_rows.size(); ++k)
      out(kept_rows[k]) = mu(static_cast<Eigen::Index>(k));
    return out;
  }

  // Reduction of K into the Newton matrix A (nf + m square), kept for K's pattern (its
  // fingerprint: a copy of K's indices was 0.5 GB at 10⁶ unknowns).
  std::uint64_t key = 0;
  std::vector<int> value_map;  // K's value k → A's value index, −1 if not free × free
  struct TiedEntry {
    int k, a;  // K's value k adds w K_k to A's value a (a slave's row or column: Tᵀ K T)
    double w;
  };
  std::vector<TiedEntry> tied_entries;
  // A's values that K does not give (the C blocks, the implied rows' 1), as (index, value); the
  // others start at zero. Not a copy of all of A's values: nnz doubles, 1.2 GB at 10⁶ unknowns.
  std::vector<std::pair<int, double>> base_entries;
  SpMat A;
  bool have_reduction = false;

  solve::FixedPatternCholesky cholesky;
  solve::FixedPatternLU lu;
  solve::SaddlePointSolver saddle;
  // The augmented system of the PETSc path (krylov_saddle_point_solve), with its own penalty
  // factor α = 1: with multigrid on Â a penalty of α = 10² made Â hard for the cycle (FGMRES
  // took 248 iterations on the quarter roof at 3·10⁵ unknowns, 58 at α = 10, 32 at α = 1, 50 at
  // α = 0.3, 123 at α = 0.1; docs/theory/solvers.md §5).
  solve::SaddlePointSolver krylov_saddle{solve::SaddlePointOptions{kKrylovPenaltyFactor}};
  std::optional<solve::KrylovMethod> petsc;     // the PETSc solver in use (choose_petsc)
  std::unique_ptr<solve::KrylovSolver> krylov;  // made on first use
  int pattern_version = 0;                      // A's pattern, counted by build_reduction
  int krylov_pattern = -1;                      // the version the PETSc solver last saw
  // The tolerance of the next PETSc solve, ‖b − A x‖₂ ≤ max(rtol ‖b‖₂, atol): a Newton step sets
  // its forcing term (krylov_forcing); other solves (the bordered ones of path following, the
  // tangent at the reference) are solved to rtol alone.
  double krylov_rtol = kKrylovTightTolerance, krylov_atol = 0.0;
  LoadStepStats* stats = nullptr;  // the step whose solves are counted (saddle-point solver)
  int analyses_before = 0;

  ResidualEvaluation ev;
  int nf_configuration = 0;  // free dofs among the configuration entries (the first ones)

  // The configuration entries of a full x (problem.configuration_size).
  Eigen::Ref<const VecX> configuration(const VecX& x) const {
    return problem.configuration_size < 0 ? x.head(n) : x.head(problem.configuration_size);
  }

  void set_prescribed(VecX& x, double t) const {
    for (std::size_t k = 0; k < cons.eliminated.size(); ++k) {
      const int i = cons.eliminated[k];
      const auto& f = cons.eliminated_value[k];
      x(i) = problem.reference(i) + (f ? f(t) : 0.0);
    }
    dofs.set_slaves(x, problem.reference);
  }

  VecX constraint_rhs(double t) const {
    if (m == 0 || !cons.rhs) return VecX::Zero(m);
    VecX d = cons.rhs(t);
    if (d.size() != m)
      throw std::invalid_argument(
          fmt::format("LinearConstraints: rhs(t) has {} entries, expected {}", d.size(), m));
    return d;
  }

  void build_reduction(const SpMat& K) {
    key = pattern_fingerprint(K);
    std::vector<std::vector<std::pair<int, double>>> expansion(static_cast<std::size_t>(n));
    for (const auto& s : dofs.slaves)
      expansion[static_cast<std::size_t>(s.dof)] = dofs.expansion(s.dof);
    // Calls f(k, free row, free column, weight) for each of K's values and the entries of
    // Tᵀ K T it adds to.
    const auto for_each_entry = [&](auto&& f) {
      for (int j = 0; j < K.outerSize(); ++j) {
        const int fj = dofs.full_to_free[static_cast<std::size_t>(j)];
        const auto& ej = expansion[static_cast<std::size_t>(j)];
        if (fj < 0 && ej.empty()) continue;
        for (int k = K.outerIndexPtr()[j]; k < K.outerIndexPtr()[j + 1]; ++k) {
          const int i = K.innerIndexPtr()[k];
          const int fi = dofs.full_to_free[static_cast<std::size_t>(i)];
          if (fi >= 0 && fj >= 0) {
            f(k, fi, fj, 0.0);
            continue;
          }
          const auto one_i = std::pair<int, double>(fi, 1.0),
                     one_j = std::pair<int, double>(fj, 1.0);
          const auto& ei = expansion[static_cast<std::size_t>(i)];
          for (const auto& [ri, wi] : fi >= 0 ? std::span(&one_i, 1) : std::span(ei))
            for (const auto& [cj, wj] : fj >= 0 ? std::span(&one_j, 1) : std::span(ej))
              f(k, ri, cj, wi * wj);
        }
      }
    };
    // A's pattern column by column, counted first and then written (no triplets: at 10⁶
    // unknowns they and setFromTriplets' transposed copy were 4 GB beside K, its pattern and A).
    // Free column fj gathers K's column free[fj] and the slave columns whose expansion has fj;
    // column nf + r holds row r of C_f (C_fᵀ's column r), or the implied row's 1.
    std::vector<int> from_start(static_cast<std::size_t>(nf) + 1, 0);
    for (const auto& sl : dofs.slaves)
      for (const auto& [f, w] : expansion[static_cast<std::size_t>(sl.dof)])
        ++from_start[static_cast<std::size_t>(f) + 1];
    for (int f = 0; f < nf; ++f) from_start[f + 1] += from_start[f];
    std::vector<int> from_slave(static_cast<std::size_t>(from_start[nf]));
    {
      std::vector<int> next(from_start.begin(), from_start.end() - 1);
      for (const auto& sl : dofs.slaves)
        for (const auto& [f, w] : expansion[static_cast<std::size_t>(sl.dof)])
          from_slave[static_cast<std::size_t>(next[f]++)] = sl.dof;
    }
    const SpMat CfT = Cf.transpose();
    const auto column = [&](int c, std::vector<int>& rows) {
      const auto add_k_column = [&](int j) {
        for (int k = K.outerIndexPtr()[j]; k < K.outerIndexPtr()[j + 1]; ++k) {
          const int i = K.innerIndexPtr()[k];
          const int fi = dofs.full_to_free[static_cast<std::size_t>(i)];
          if (fi >= 0)
            rows.push_back(fi);
          else
            for (const auto& [ri, wi] : expansion[static_cast<std::size_t>(i)]) rows.push_back(ri);
        }
      };
      if (c < nf) {
        add_k_column(dofs.free[static_cast<std::size_t>(c)]);
        for (int s = from_start[c]; s < from_start[c + 1]; ++s)
          add_k_column(from_slave[static_cast<std::size_t>(s)]);
        for (SpMat::InnerIterator it(Cf, c); it; ++it)
          rows.push_back(nf + static_cast<int>(it.row()));
      } else {
        for (SpMat::InnerIterator it(CfT, c - nf); it; ++it)
          rows.push_back(static_cast<int>(it.row()));
        if (implied[static_cast<std::size_t>(c - nf)]) rows.push_back(c);
      }
    };
    pattern_by_columns(nf + m, nf + m, column, A);
    // The C blocks' values and the implied rows' 1 (the K part is summed in by assemble_matrix).
    const auto set_value = [&](int r, int c, double v) {
      const int* b = A.innerIndexPtr() + A.outerIndexPtr()[c];
      const int* e = A.innerIndexPtr() + A.outerIndexPtr()[c + 1];
      A.valuePtr()[std::lower_bound(b, e, r) - A.innerIndexPtr()] = v;
    };
    for (int j = 0; j < Cf.outerSize(); ++j)
      for (SpMat::InnerIterator it(Cf, j); it; ++it) {
        set_value(nf + static_cast<int>(it.row()), j, it.value());
        set_value(j, nf + static_cast<int>(it.row()), it.value());
      }
    for (int r = 0; r < m; ++r)
      if (implied[static_cast<std::size_t>(r)]) set_value(nf + r, nf + r, 1.0);
    base_entries.clear();
    for (int j = 0; j < A.outerSize(); ++j)
      for (int k = A.outerIndexPtr()[j]; k < A.outerIndexPtr()[j + 1]; ++k)
        if (j >= nf || A.innerIndexPtr()[k] >= nf) base_entries.emplace_back(k, A.valuePtr()[k]);
    value_map.assign(static_cast<std::size_t>(K.nonZeros()), -1);
    tied_entries.clear();
    for_each_entry([&](int k, int fi, int fj, double w) {
      const int* begin = A.innerIndexPtr() + A.outerIndexPtr()[fj];
      const int* end = A.innerIndexPtr() + A.outerIndexPtr()[fj + 1];
      const int a = static_cast<int>(std::lower_bound(begin, end, fi) - A.innerIndexPtr());
      if (w == 0.0)
        value_map[static_cast<std::size_t>(k)] = a;
      else
        tied_entries.push_back({k, a, w});
    });
    have_reduction = true;
    ++pattern_version;
  }

  bool same_pattern(const SpMat& K) const {
    return have_reduction && pattern_fingerprint(K) == key;
  }

  // A = [K_ff C_fᵀ; C_f 0] from the K in ev.
  void assemble_matrix() {
    SpMat& K = ev.K;
    if (K.rows() != n || K.cols() != n)
      throw std::invalid_argument(fmt::format("StaticProblem: tangent is {} x {}, expected {} x {}",
                                              K.rows(), K.cols(), n, n));
    if (!K.isCompressed()) K.makeCompressed();
    if (!same_pattern(K)) build_reduction(K);
    double* a = A.valuePtr();
    std::fill(a, a + A.nonZeros(), 0.0);
    for (const auto& [k, value] : base_entries) a[k] = value;
    const double* kv = K.valuePtr();
    for (std::size_t k = 0; k < value_map.size(); ++k)
      if (value_map[k] >= 0) a[value_map[k]] += kv[k];
    for (const TiedEntry& e : tied_entries) a[e.a] += e.w * kv[e.k];
  }

  // The single place where the Newton matrix is factorized (to be swapped for another solver).
  // Symmetric without multipliers: supernodal Cholesky (CHOLMOD), 3.8× faster than Eigen's
  // simplicial LDLᵀ at 5·10³ unknowns and 8.8× at 3·10⁴ (bench/kl_shell.md, solvers).
  VecX linear_solve(const SpMat& M, const VecX& b) { return factorize_and_solve<VecX>(M, b); }
  MatX linear_solve_columns(const SpMat& M, const MatX& B) {
    return factorize_and_solve<MatX>(M, B);
  }
  template <class Rhs>
  Rhs factorize_and_solve(const SpMat& M, const Rhs& b) {
    const auto with = [&](auto& solver) -> Rhs {
      if constexpr (std::is_same_v<Rhs, MatX>)
        return solver.solve_columns(M, b);
      else
        return solver.solve(M, b);
    };
    const bool multipliers = m > 0 || nf_configuration < nf;
    if (use_krylov() && stats && !problem.symmetric) {
      // Not symmetric: the solvers below (PETSc's unsymmetric solvers are not built in), said
      // once per solve.
      ++stats->linear_solver_fallbacks;
      stats->linear_solver_fallback_reason = "the Newton matrix is not symmetric (follower loads)";
    }
    if (problem.symmetric && use_krylov()) {
      make_krylov();
      try {
        return multipliers ? krylov_saddle_point_solve(M, b) : krylov_solve(M, b);
      } catch (const std::runtime_error& e) {
        // Each rank holds a part of M only: no direct solver can take over. The Newton
        // iteration fails (and the load step is halved), the same on every rank.
        if (problem.distributed) throw;
        // Not positive definite (past a limit point) or short of its tolerance: the direct
        // solvers below.
        if (stats) {
          ++stats->linear_solver_fallbacks;
          stats->linear_solver_fallback_reason = e.what();
        }
      }
    }
    if (problem.symmetric && !multipliers) {
      try {
        return with(cholesky);
      } catch (const std::runtime_error&) {
        // Not positive definite (past a limit point, or a singular direction): pivoted LU.
      }
    }
    if (problem.symmetric && multipliers && use_saddle_point_solver(M)) {
      try {
        saddle.factorize(M, nf_configuration);
        Rhs x(b.rows(), b.cols());
        for (Eigen::Index c = 0; c < b.cols(); ++c) {
          x.col(c) = saddle.solve(b.col(c));
          if (stats) stats->krylov_iterations += saddle.last().iterations;
        }
        return x;
      } catch (const std::runtime_error&) {
        // Â not positive definite (past a limit point) or GMRES short of its tolerance.
        if (stats) ++stats->saddle_point_fallbacks;
      }
    }
    return with(lu);
  }

  bool use_krylov() const { return petsc.has_value(); }
  solve::KrylovMethod krylov_method() const { return *petsc; }

  // The PETSc solver of settings.linear_solver; automatic: geometric multigrid for a model of
  // Kirchhoff–Love patches (symmetric, the module loads) from kAutomaticMultigridUnknowns free
  // dofs on without multiplier rows, from kAutomaticSaddlePointMultigridUnknowns on with the
  // LinearConstraints' rows only (weak supports: the crossover of bench/large_shells.md), from
  // kAutomaticTiedMultigridUnknowns on with tied coordinates of its own (AF-D) and no rows; else
  // none (the direct solvers).
  std::optional<solve::KrylovMethod> choose_petsc() const {
    switch (settings.linear_solver) {
      case LinearSolverMethod::cg_gamg:
        return solve::KrylovMethod::cg_gamg;
      case LinearSolverMethod::cg_hypre:
        return solve::KrylovMethod::cg_hypre;
      case LinearSolverMethod::mumps:
        return solve::KrylovMethod::mumps;
      case LinearSolverMethod::cg_multigrid:
        return solve::KrylovMethod::cg_multigrid;
      case LinearSolverMethod::direct:
        return std::nullopt;
      case LinearSolverMethod::automatic:
        break;
    }
    // Several ranks: a PETSc solver at any size (the direct ones are sequential).
    if (problem.distributed)
      return problem.transfer_operators ? solve::KrylovMethod::cg_multigrid
                                        : solve::KrylovMethod::mumps;
    const int threshold = given_ties ? kAutomaticTiedMultigridUnknowns
                          : m > 0    ? kAutomaticSaddlePointMultigridUnknowns
                                     : kAutomaticMultigridUnknowns;
    if (nf < threshold || nf_configuration < nf || !problem.symmetric ||
        !problem.transfer_operators || (given_ties && m > 0) || !solve::krylov_available())
      return std::nullopt;
    return solve::KrylovMethod::cg_multigrid;
  }

  // The PETSc solver, on first use. What the model cannot have (a module that does not load, a
  // multigrid without patches) is an error of the run, not a fallback: the model asked for it.
  void make_krylov() {
    if (krylov) return;
    try {
      auto solver = std::make_unique<solve::KrylovSolver>(krylov_method(), problem.distributed);
      if (krylov_method() == solve::KrylovMethod::cg_multigrid)
        solver->set_interpolations(free_transfer_operators());
      else if (!problem.points.empty())
        solver->set_near_null_space(free_rigid_body_modes());
      krylov = std::move(solver);
    } catch (const std::runtime_error& e) {
      throw std::invalid_argument(std::string("solver.linear_solver: ") + e.what());
    }
  }

  // The columns of b by the PETSc solver, each to the tolerance set for it.
  template <class Rhs>
  Rhs krylov_solve(const SpMat& M, const Rhs& b) {
    const double rtol = std::exchange(krylov_rtol, kKrylovTightTolerance);
    const double atol = std::exchange(krylov_atol, 0.0);
    Rhs x(b.rows(), b.cols());
    for (Eigen::Index c = 0; c < b.cols(); ++c) {
      x.col(c) =
          krylov->solve(M, krylov_pattern != pattern_version, b.col(c), rtol, c == 0 ? atol : 0.0);
      krylov_pattern = pattern_version;
      if (stats) stats->krylov_iterations += krylov->last().iterations;
    }
    return x;
  }

  // A Newton matrix with multiplier rows by the PETSc solver (docs/theory/solvers.md §5): the
  // augmented Lagrangian's system [Â B_Hᵀ; B_H 0] of solve/saddle_point.hpp (the compliant and
  // implied rows eliminated exactly, Â positive definite at a stable constrained equilibrium even
  // where K_ff is singular) by FGMRES with the block-triangular preconditioner, Â's block by the
  // method's preconditioner and S = −B_H Â⁻¹ B_Hᵀ by −W_H⁻¹. The solve is to M's own residual,
  // ‖b − M z‖₂ ≤ max(rtol ‖b‖₂, atol) as krylov_solve's, with a refinement cycle from the true
  // residual where the augmented system's residual (other weights) was not enough. A residual
  // at the round-off of M z is accepted too, a normwise backward error ‖b − M z‖∞ / (‖M‖∞ ‖z‖∞ +
  // ‖b‖∞) ≤ kKrylovBackwardError (the test of the direct saddle-point solver): the tenth of a
  // Newton tolerance of 10⁻¹⁶ that a linear analysis asks for is below it, and where CG's
  // recurrence reaches it, FGMRES's stalls at the round-off of the true residual.
  template <class Rhs>
  Rhs krylov_saddle_point_solve(const SpMat& M, const Rhs& b) {
    const double rtol = std::exchange(krylov_rtol, kKrylovTightTolerance);
    const double atol = std::exchange(krylov_atol, 0.0);
    solve::SaddlePointSolver& saddle = krylov_saddle;
    // M's pattern changes with pattern_version alone (build_reduction): no copy of it kept.
    saddle.augment(M, nf_configuration, pattern_version);
    const SpMat& Ahat = saddle.augmented_matrix();
    const Eigen::SparseMatrix<double, Eigen::RowMajor> BH = saddle.hard_rows();
    const VecX schur = -saddle.hard_weights().cwiseInverse();
    double norm_M = 0.0;  // ‖M‖∞, the largest column sum (M symmetric)
    for (int j = 0; j < M.outerSize(); ++j) {
      double sum = 0.0;
      for (SpMat::InnerIterator it(M, j); it; ++it) sum += std::abs(it.value());
      norm_M = std::max(norm_M, sum);
    }
    Rhs x(b.rows(), b.cols());
    for (Eigen::Index c = 0; c < b.cols(); ++c) {
      const VecX bc = b.col(c);
      const double target = std::max(rtol * bc.norm(), c == 0 ? atol : 0.0);
      VecX z = VecX::Zero(bc.size()), r = bc;
      for (int cycle = 0;; ++cycle) {
        const VecX f = saddle.augmented_rhs(r);
        const double scale = f.norm() / std::max(r.norm(), 1e-300);
        const bool new_pattern = krylov_pattern != pattern_version;
        const double f_atol = c == 0 ? scale * atol : 0.0;
        // A cycle reduces the residual by at most kSaddlePointCycleTolerance: the next starts
        // from the true residual, not from the recurrence's, which runs ahead of it below
        // round-off.
        const double f_rtol = std::max(rtol, kSaddlePointCycleTolerance);
        // The preconditioner is set up on the first cycle of a solve, not again for the others.
        const bool new_values = c == 0 && cycle == 0;
        // Every row compliant or implied: Â alone (conjugate gradients).
        const VecX u = BH.rows() == 0 ? krylov->solve(Ahat, new_pattern, f, f_rtol, f_atol)
                                      : krylov->solve_saddle_point(Ahat, new_pattern, new_values,
                                                                   BH, schur, f, f_rtol, f_atol);
        krylov_pattern = pattern_version;
        if (stats) stats->krylov_iterations += krylov->last().iterations;
        z += saddle.expand(u, r);
        r = bc - M * z;
        const double backward = inf_norm(r) / (norm_M * inf_norm(z) + inf_norm(bc));
        if (r.norm() <= target || backward <= kKrylovBackwardError) break;
        if (cycle == kKrylovRefinementCycles - 1)
          throw std::runtime_error(
              fmt::format("the saddle point's residual is {:.3g} after {} cycles, above {:.3g}",
                          r.norm(), kKrylovRefinementCycles, target));
      }
      x.col(c) = z;
    }
    return x;
  }

  // The rigid-body modes of problem.points at the reference, on the Newton unknowns that the
  // PETSc solver's multigrid sees: the free configuration dofs (a slave's entry is not one, and
  // the multipliers have none; with multiplier rows the augmented block is this size).
  MatX free_rigid_body_modes() const {
    const MatX full = solve::rigid_body_modes(problem.reference.head(n), problem.points);
    MatX out = MatX::Zero(nf_configuration, full.cols());
    for (int k = 0; k < nf_configuration; ++k)
      out.row(k) = full.row(dofs.free[static_cast<std::size_t>(k)]);
    return out;
  }

  // problem.transfer_operators on the Newton unknowns (docs/theory/solvers.md §4, §7): at every
  // level l the unknowns are the free coordinates of a DofMap D_l, and the interpolation is
  // P̂_l = S_l P_l T_{l+1} — the coarse unknowns expanded to the coarse coordinates by T_{l+1}
  // (slaves from their masters), interpolated, and the free rows of level l kept (S_l). A coarse
  // coordinate that reaches no free row is not an unknown (a coarse control point whose fine
  // image is held). The supports' ties (the homogeneous rows tied, reaction_slaves) are carried
  // down, C_{l+1} = C_l P_l (C_l: e_s − Σ_k c_k e_k per slave s of D_l, the held terms dropped),
  // so that a coarse correction interpolates to one that meets them exactly; their dependent rows
  // are dropped by the DofMap's elimination. The model's own ties (AF-D's G¹ rows) are not: the
  // fine level writes its slaves from their masters (T) whatever the coarse ones would be, and
  // carried down they ask the coarse splines of both patches to be G¹ at every fine triple, which
  // locks the coarse space at the interface (the two-patch roof: 47 CG iterations instead of 26
  // at 6.3·10⁴ unknowns, 87 instead of 27 at 2·10⁵; bench/large_shells.md). Without ties this is
  // P_l's rows of the free dofs and the coarse coordinates that reach them.
  std::vector<SpMat> free_transfer_operators() const {
    if (!problem.transfer_operators)
      throw std::runtime_error(
          "geometric multigrid (cg_multigrid): the model has no Kirchhoff–Love patch to coarsen");
    // Empty for a model small enough to be its own coarsest level.
    std::vector<SpMat> P = problem.transfer_operators();
    using Row = std::vector<std::pair<int, double>>;
    // Level index → unknown (−1: held or a slave): the free configuration dofs (with multiplier
    // rows, the rows of the augmented block Â; without, every free dof).
    std::vector<int> rows(static_cast<std::size_t>(n), -1);
    for (int k = 0; k < nf_configuration; ++k)
      rows[static_cast<std::size_t>(dofs.free[static_cast<std::size_t>(k)])] = k;
    int kept_rows = nf_configuration;
    // The slave rows of a DofMap over the level's coordinates, its free terms only.
    const auto slave_rows = [](const DofMap& d) {
      std::vector<Row> out;
      for (const auto& sl : d.slaves) {
        Row r{{sl.dof, 1.0}};
        for (const auto& [k, c] : sl.terms)
          if (d.full_to_free[static_cast<std::size_t>(k)] >= 0) r.emplace_back(k, -c);
        out.push_back(std::move(r));
      }
      return out;
    };
    // The supports' ties only (reaction_slaves: the homogeneous rows tied); the model's own (AF-D)
    // are left to the fine level's T.
    std::vector<Row> ties;
    for (const Row& r : slave_rows(dofs))
      if (std::binary_search(reaction_slaves.begin(), reaction_slaves.end(), r.front().first))
        ties.push_back(r);
    for (std::size_t l = 0; l < P.size(); ++l) {
      SpMat& Pl = P[l];
      const int n_coarse = static_cast<int>(Pl.cols());
      // The held rows of a level that is not nested in the coarse one: neither free nor slaves.
      std::vector<bool> held_row;
      if (l == 0 && problem.first_transfer_not_nested) {
        held_row.resize(static_cast<std::size_t>(Pl.rows()));
        for (std::size_t i = 0; i < held_row.size(); ++i) held_row[i] = rows[i] < 0;
        for (const auto& sl : dofs.slaves) held_row[static_cast<std::size_t>(sl.dof)] = false;
      }
      std::vector<bool> pinned(static_cast<std::size_t>(n_coarse), false);
      // The coarse coordinates that reach a free row, and C_l P_l row by row.
      std::vector<std::vector<std::pair<int, double>>> uses(static_cast<std::size_t>(Pl.rows()));
      for (std::size_t r = 0; r < ties.size(); ++r)
        for (const auto& [i, c] : ties[r]) uses[static_cast<std::size_t>(i)].emplace_back(r, c);
      std::vector<bool> reaches(static_cast<std::size_t>(n_coarse), false);
      std::vector<std::map<int, double>> coarse_ties(ties.size());
      for (int j = 0; j < Pl.outerSize(); ++j)
        for (SpMat::InnerIterator it(Pl, j); it; ++it) {
          if (rows[static_cast<std::size_t>(it.row())] >= 0)
            reaches[static_cast<std::size_t>(j)] = true;
          else if (!held_row.empty() && held_row[static_cast<std::size_t>(it.row())])
            pinned[static_cast<std::size_t>(j)] = true;
          for (const auto& [r, c] : uses[static_cast<std::size_t>(it.row())])
            coarse_ties[static_cast<std::size_t>(r)][j] += c * it.value();
        }
      std::vector<int> held;
      for (int j = 0; j < n_coarse; ++j)
        if (!reaches[static_cast<std::size_t>(j)] || pinned[static_cast<std::size_t>(j)])
          held.push_back(j);
      std::vector<Row> tied;
      for (const auto& t : coarse_ties) {
        Row r;
        for (const auto& [j, c] : t)
          if (c != 0.0) r.emplace_back(j, c);
        if (!r.empty()) tied.push_back(std::move(r));
      }
      const DofMap coarse = DofMap::build(n_coarse, held, tied);
      std::vector<Eigen::Triplet<double>> t;
      for (int j = 0; j < Pl.outerSize(); ++j) {
        const auto expansion = coarse.expansion(j);
        if (expansion.empty()) continue;
        for (SpMat::InnerIterator it(Pl, j); it; ++it)
          if (const int r = rows[static_cast<std::size_t>(it.row())]; r >= 0)
            for (const auto& [f, w] : expansion) t.emplace_back(r, f, w * it.value());
      }
      Pl = SpMat(kept_rows, coarse.n_free());
      Pl.setFromTriplets(t.begin(), t.end());
      Pl.makeCompressed();
      rows = coarse.full_to_free;
      kept_rows = coarse.n_free();
      ties = slave_rows(coarse);
    }
    return P;
  }

  bool use_saddle_point_solver(const SpMat& M) const {
    switch (settings.saddle_point) {
      case SaddlePointMethod::lu:
        return false;
      case SaddlePointMethod::augmented_lagrangian:
        return true;
      case SaddlePointMethod::automatic:
        break;
    }
    return M.rows() >= kIterativeSaddlePointUnknowns;
  }

  void evaluate(const VecX& x, double t, bool with_tangent, LoadStepStats& st) {
    stats = &st;  // every solve follows an evaluation of its step
    const auto t0 = Clock::now();
    problem.evaluate(x, t, with_tangent, ev);
    if (ev.r.size() != n)
      throw std::invalid_argument(
          fmt::format("StaticProblem: residual has {} entries, expected {}", ev.r.size(), n));
    if (with_tangent) assemble_matrix();
    // A linear problem needs K again only at its next load step, which evaluates it anew: its
    // storage (nnz doubles and ints, 1.7 GB at 10⁶ unknowns) is released while the Newton matrix
    // is solved (the solver's set-up is the peak of the run), and the evaluation writes the
    // pattern back in (the same pattern: the reduction's maps are kept).
    if (with_tangent && problem.linear) SpMat().swap(ev.K);  // (resize would keep it)
    st.assembly_seconds += seconds_since(t0);
  }

  // Residual of the reduced/bordered system at (x, μ) from ev.r; also the convergence scale.
  VecX reduced_residual(const VecX& x, const VecX& mu, double t, double& scale) const {
    VecX R(nf + m);
    VecX r = ev.r;
    if (m > 0) r += cons.C.transpose() * mu;
    double reactions = m > 0 ? inf_norm(r - ev.r) : 0.0;
    for (int i : cons.eliminated) reactions = std::max(reactions, std::abs(ev.r(i)));
    for (int i : reaction_slaves) reactions = std::max(reactions, std::abs(ev.r(i)));
    R.head(nf) = dofs.reduce(r);
    if (m > 0) R.tail(m) = cons.C * (x - problem.reference) - constraint_rhs(t);
    for (int r = 0; r < m; ++r)
      if (implied[static_cast<std::size_t>(r)]) R(nf + r) = mu(r);
    scale = std::max({settings.force_floor, ev.load_norm, reactions});
    return R;
  }

  // The forcing term of an inexact Newton step (docs/theory/solvers.md §3): the linear residual
  // at most min(10⁻², ‖R‖∞/scale) ‖R‖₂, which keeps the convergence quadratic, or a tenth of the
  // Newton tolerance, below which the next residual is converged whatever the quadratic term.
  void krylov_forcing(const VecX& R, double scale) {
    krylov_rtol = problem.linear ? 0.0 : std::min(1e-2, inf_norm(R) / std::max(scale, 1e-300));
    krylov_atol = 0.1 * settings.residual_tolerance * scale;
  }

  // A factorization of a singular matrix (a mechanism: a part held by neither supports nor
  // couplings, a c0 interface as a hinge) can succeed on round-off pivots and return a correction
  // of the size 1/eps; no static correction is 10⁸ times the size of the model (neither is one
  // from loads far beyond any structure's strength). Without a length scale (every coordinate 0
  // at the start) there is no test.
  void check_not_singular(const VecX& dz, double xscale) const {
    const double size = inf_norm(dz.head(nf_configuration));
    if (xscale > 1e-290 && !(size <= 1e8 * xscale))
      throw std::runtime_error(fmt::format(
          "the Newton correction {:.3g} is {:.2g} times the size of the model ({:.3g}): a singular "
          "Newton matrix — a mechanism, a part that the supports and couplings do not hold (a c0 "
          "interface is a hinge) — or loads far beyond the structure's strength",
          size, size / xscale, xscale));
  }

  // Newton at the load parameter t from (x, μ); x's eliminated dofs are set here.
  NewtonOutcome newton(VecX& x, VecX& mu, double t, LoadStepStats& st) {
    set_prescribed(x, t);
    if (problem.begin_step) problem.begin_step(x, t);
    const double xscale =
        std::max({inf_norm(configuration(x)), inf_norm(configuration(problem.reference)), 1e-300});
    NewtonOptions opt;
    opt.max_iterations = problem.linear ? 1 : settings.max_iterations;
    opt.residual_tolerance = settings.residual_tolerance;
    opt.stop_when_diverging = true;
    opt.predict_last_matrix = true;
    double scale = 0.0;
    return newton_loop(
        opt,
        [&](bool with_matrix) {
          evaluate(x, t, with_matrix, st);
          return reduced_residual(x, mu, t, scale);
        },
        [&] { return scale; },
        [&](const VecX& R) {
          const auto t0 = Clock::now();
          VecX dz;
          try {
            krylov_forcing(R, scale);
            dz = linear_solve(A, -R);
          } catch (...) {
            st.solve_seconds += seconds_since(t0);
            throw;
          }
          st.solve_seconds += seconds_since(t0);
          check_not_singular(dz, xscale);
          add_to_unknowns(x, mu, dz);
          // A linear problem is solved by one correction; otherwise a round-off-level correction
          // ends the iteration (its error is its square).
          return problem.linear ||
                 inf_norm(dz.head(nf_configuration)) <=
                     settings.increment_tolerance * std::max(xscale, inf_norm(configuration(x)));
        },
        &st.residual_history);
  }

  // --- Path following (header) -------------------------------------------------------------
  VecX control;             // c on the Newton unknowns z = (free dofs, μ) (displacement control)
  double path_scale = 0.0;  // ‖∂R/∂λ‖∞ t_end at the reference: the least convergence scale

  // The free configuration entries of x (the first nf_configuration unknowns of z).
  VecX free_configuration(const VecX& x) const {
    VecX u(nf_configuration);
    for (int k = 0; k < nf_configuration; ++k) u(k) = x(dofs.free[static_cast<std::size_t>(k)]);
    return u;
  }

  // x and μ moved by δz (free dofs and multipliers).
  void add_to_unknowns(VecX& x, VecX& mu, const VecX& dz) const {
    for (int k = 0; k < nf; ++k) x(dofs.free[static_cast<std::size_t>(k)]) += dz(k);
    dofs.set_slaves(x, problem.reference);
    if (m > 0) mu += dz.tail(m);
  }

  // z(x, μ) − z(x₀, μ₀).
  VecX unknowns_difference(const VecX& x, const VecX& mu, const VecX& x0, const VecX& mu0) const {
    VecX dz(nf + m);
    for (int k = 0; k < nf; ++k) {
      const int i = dofs.free[static_cast<std::size_t>(k)];
      dz(k) = x(i) - x0(i);
    }
    if (m > 0) dz.tail(m) = mu - mu0;
    return dz;
  }

  // ∂R/∂λ at (x, μ, λ) by a central difference, the prescribed entries of x following λ; leaves
  // the Newton matrix as it is.
  VecX load_derivative(const VecX& x, const VecX& mu, double lambda, LoadStepStats& st) {
    const double h = 1e-6 * std::max(std::abs(lambda), std::abs(settings.t_end));
    VecX xh = x;
    double s = 0.0;
    set_prescribed(xh, lambda + h);
    evaluate(xh, lambda + h, false, st);
    const VecX Rp = reduced_residual(xh, mu, lambda + h, s);
    set_prescribed(xh, lambda - h);
    evaluate(xh, lambda - h, false, st);
    return (Rp - reduced_residual(xh, mu, lambda - h, s)) / (2.0 * h);
  }

  // Newton on (x, μ, λ) with one more equation, by bordering (header); pick(δz_R, δz_λ)
  // returns δλ.
  template <class Pick>
  NewtonOutcome newton_bordered(VecX& x, VecX& mu, double& lambda, LoadStepStats& st,
                                int min_corrections, Pick&& pick) {
    set_prescribed(x, lambda);
    if (problem.begin_step) problem.begin_step(x, lambda);
    const double xscale =
        std::max({inf_norm(configuration(x)), inf_norm(configuration(problem.reference)), 1e-300});
    NewtonOptions opt;
    opt.max_iterations = settings.max_iterations;
    opt.residual_tolerance = settings.residual_tolerance;
    opt.stop_when_diverging = true;
    opt.predict_last_matrix = true;
    opt.min_corrections = min_corrections;
    double scale = 0.0;
    VecX dR;
    return newton_loop(
        opt,
        [&](bool with_matrix) {
          set_prescribed(x, lambda);
          evaluate(x, lambda, with_matrix, st);
          VecX R = reduced_residual(x, mu, lambda, scale);
          scale = std::max(scale, path_scale);
          if (with_matrix) dR = load_derivative(x, mu, lambda, st);
          return R;
        },
        [&] { return scale; },
        [&](const VecX& R) {
          const auto t0 = Clock::now();
          MatX B(nf + m, 2);
          B.col(0) = -R;
          B.col(1) = -dR;
          MatX D;
          try {
            D = linear_solve_columns(A, B);
          } catch (...) {
            st.solve_seconds += seconds_since(t0);
            throw;
          }
          st.solve_seconds += seconds_since(t0);
          const double dl = pick(VecX(D.col(0)), VecX(D.col(1)));
          const VecX dz = D.col(0) + dl * D.col(1);
          add_to_unknowns(x, mu, dz);
          lambda += dl;
          return inf_norm(dz.head(nf_configuration)) <=
                     settings.increment_tolerance * std::max(xscale, inf_norm(configuration(x))) &&
                 std::abs(dl) <= settings.increment_tolerance *
                                     std::max(std::abs(lambda), std::abs(settings.t_end));
        },
        &st.residual_history);
  }

  // Displacement control: c·(x − X) = target after the correction (linear in δλ).
  NewtonOutcome newton_displacement(VecX& x, VecX& mu, double& lambda, double target,
                                    LoadStepStats& st) {
    // The start is the last equilibrium, off the new control value: one correction at least.
    return newton_bordered(x, mu, lambda, st, 1, [&](const VecX& dzR, const VecX& dzl) {
      const double g = control_value(x) - target;
      const double slope = control.dot(dzl);
      if (!(std::abs(slope) > 0.0))
        throw std::runtime_error(
            "displacement control: the controlled displacement does not respond to the load");
      return -(g + control.dot(dzR)) / slope;
    });
  }

  double control_value(const VecX& x) const {
    double u = 0.0;
    for (const auto& [i, c] : settings.path.control_vector) u += c * (x(i) - problem.reference(i));
    return u;
  }

  // ‖∂R/∂λ‖∞ t_end at (x, μ) (the reference): the size of the full load.
  double reference_load_scale(const VecX& x, const VecX& mu) {
    LoadStepStats st;
    return inf_norm(load_derivative(x, mu, 0.0, st).head(nf)) * std::abs(settings.t_end);
  }

  // The times of failed attempts, added to the step that is accepted next.
  struct Carried {
    double wall = 0.0, assembly = 0.0, solve = 0.0;
    int krylov = 0, fallbacks = 0;
    void add(const LoadStepStats& st) {
      wall += st.wall_seconds;
      assembly += st.assembly_seconds;
      solve += st.solve_seconds;
      krylov += st.krylov_iterations;
      fallbacks += st.saddle_point_fallbacks;
    }
    void take(LoadStepStats& st) {
      st.wall_seconds += wall;
      st.assembly_seconds += assembly;
      st.solve_seconds += solve;
      st.krylov_iterations += krylov;
      st.saddle_point_fallbacks += fallbacks;
      *this = {};
    }
  };

  StaticResult solve_stepped(const StaticObserver& observer);
  StaticResult solve_arc_length(const StaticObserver& observer);
};

StaticNewtonSolver::StaticNewtonSolver(StaticProblem problem, LinearConstraints constraints,
                                       StaticSettings settings)
    : impl_(std::make_unique<Impl>()) {
  Impl& I = *impl_;
  I.problem = std::move(problem);
  I.cons = std::move(constraints);
  I.settings = settings;
  I.n = static_cast<int>(I.problem.reference.size());
  if (!I.problem.evaluate) throw std::invalid_argument("StaticNewtonSolver: no evaluate function");
  const StaticSettings& s = I.settings;
  if (s.steps < 1 || !std::isfinite(s.t_end) || !(s.t_end > 0.0) || s.max_iterations < 1 ||
      !(s.residual_tolerance >= 0.0) || !(s.increment_tolerance >= 0.0) || s.max_cuts < 0 ||
      s.grow_after < 1 || !(s.force_floor >= 0.0))
    throw std::invalid_argument(fmt::format(
        "StaticNewtonSolver: bad settings (steps {}, t_end {}, max_iterations {}, residual "
        "tolerance {}, increment tolerance {}, max_cuts {}, grow_after {}, force_floor {})",
        s.steps, s.t_end, s.max_iterations, s.residual_tolerance, s.increment_tolerance, s.max_cuts,
        s.grow_after, s.force_floor));
  if (I.cons.eliminated_value.size() < I.cons.eliminated.size())
    I.cons.eliminated_value.resize(I.cons.eliminated.size());
  if (I.cons.eliminated_value.size() != I.cons.eliminated.size())
    throw std::invalid_argument("LinearConstraints: more eliminated values than dofs");
  if (!std::is_sorted(I.cons.eliminated.begin(), I.cons.eliminated.end()) ||
      std::adjacent_find(I.cons.eliminated.begin(), I.cons.eliminated.end()) !=
          I.cons.eliminated.end())
    throw std::invalid_argument("LinearConstraints: eliminated dofs not sorted and unique");
  if (I.problem.configuration_size > I.n)
    throw std::invalid_argument("StaticProblem: configuration_size larger than x");
  if (I.cons.C.rows() == 0) I.cons.C.resize(0, I.n);
  if (I.cons.C.cols() != I.n)
    throw std::invalid_argument(
        fmt::format("LinearConstraints: C has {} columns, expected {}", I.cons.C.cols(), I.n));
  I.cons.C.makeCompressed();
  I.original_rows = static_cast<int>(I.cons.C.rows());
  I.given_ties = !I.cons.tied.empty();
  // The homogeneous rows (symmetry and clamp slopes) are tied instead of given multipliers where
  // a PETSc solver takes the Newton matrix (docs/theory/solvers.md §7): the matrix is then
  // symmetric positive definite, and geometric multigrid solves it by CG as a model without rows.
  // The direct solvers keep the rows (their results as before).
  bool tie = false;
  for (int r = 0; r < I.original_rows && !tie; ++r) tie = I.cons.is_homogeneous(r);
  tie = tie && s.tie_homogeneous_rows && s.linear_solver != LinearSolverMethod::direct &&
        I.problem.symmetric;
  if (tie) {
    LinearConstraints kept = I.cons;
    I.tie_homogeneous_rows();
    I.set_up_rows();
    I.petsc = I.choose_petsc();
    if (!I.petsc) {  // automatic chose the direct solvers: the rows as they were
      I.cons = std::move(kept);
      I.kept_rows.clear();
      I.reaction_slaves.clear();
      tie = false;
    }
  }
  if (!tie) {
    I.set_up_rows();
    I.petsc = I.choose_petsc();
  }
  const PathSettings& p = s.path;
  if (p.control == PathControl::load) return;
  if (I.problem.linear)
    throw std::invalid_argument(
        "StaticNewtonSolver: path following (arc length, displacement control) needs a "
        "nonlinear analysis");
  if (!(p.arc_length >= 0.0) || !std::isfinite(p.arc_length) || !(p.max_arc_length >= 0.0) ||
      !std::isfinite(p.max_arc_length) || !(p.load_weight >= 0.0) ||
      !std::isfinite(p.load_weight) || p.target_iterations < 1 || p.max_steps < 1 ||
      !std::isfinite(p.displacement))
    throw std::invalid_argument(fmt::format(
        "StaticNewtonSolver: bad path settings (arc length {}, load weight {}, target iterations "
        "{}, max steps {}, displacement {})",
        p.arc_length, p.load_weight, p.target_iterations, p.max_steps, p.displacement));
  if (p.control != PathControl::displacement) return;
  I.control = VecX::Zero(I.nf + I.m);
  for (const auto& [i, c] : p.control_vector) {
    if (i < 0 || i >= I.n)
      throw std::invalid_argument(
          fmt::format("StaticNewtonSolver: control vector entry {} outside 0..{}", i, I.n - 1));
    for (const auto& [fi, w] : I.dofs.expansion(i)) I.control(fi) += w * c;
  }
  if (I.control.lpNorm<Eigen::Infinity>() == 0.0)
    throw std::invalid_argument(
        "StaticNewtonSolver: the controlled displacement acts on eliminated (supported) "
        "coordinates only");
}

StaticNewtonSolver::~StaticNewtonSolver() = default;
StaticNewtonSolver::StaticNewtonSolver(StaticNewtonSolver&&) noexcept = default;
StaticNewtonSolver& StaticNewtonSolver::operator=(StaticNewtonSolver&&) noexcept = default;

const DofMap& StaticNewtonSolver::dofs() const {
  return impl_->dofs;
}
int StaticNewtonSolver::implied_multiplier_rows() const {
  return impl_->implied_count;
}
int StaticNewtonSolver::multiplier_rows() const {
  return impl_->m;
}
int StaticNewtonSolver::tied_homogeneous_rows() const {
  return impl_->kept_rows.empty() && impl_->original_rows == impl_->m
             ? 0
             : impl_->original_rows - impl_->m;
}
const StaticSettings& StaticNewtonSolver::settings() const {
  return impl_->settings;
}
const char* StaticNewtonSolver::linear_solver() const {
  return impl_->petsc ? solve::krylov_method_name(*impl_->petsc) : "direct";
}

StaticResult StaticNewtonSolver::solve(const StaticObserver& observer) {
  return impl_->settings.path.control == PathControl::arc_length ? impl_->solve_arc_length(observer)
                                                                 : impl_->solve_stepped(observer);
}

// Load control and displacement control: the nominal levels t = t_end k / steps, halved on
// failure (adaptive).
StaticResult StaticNewtonSolver::Impl::solve_stepped(const StaticObserver& observer) {
  const StaticSettings& s = settings;
  const bool displacement = s.path.control == PathControl::displacement;
  StaticResult res;
  VecX x = problem.reference;
  VecX mu = VecX::Zero(m);
  double lambda = 0.0;  // displacement control: the load factor reached
  set_prescribed(x, 0.0);
  if (displacement) path_scale = reference_load_scale(x, mu);
  const double dt_nominal = s.t_end / s.steps;
  double t = 0.0, dt = dt_nominal;
  int cuts = 0, easy = 0;
  Carried carried;
  const int analyses0 = cholesky.analyses() + lu.analyses() + saddle.analyses();
  while (t < s.t_end) {
    double dt_try = std::min(dt, s.t_end - t);
    if (dt < dt_nominal) {
      // After a halving the increments grow back, but never step over a nominal load level
      // k·Δt: the user's grid keeps its rows in the outputs (an unhalved run is unchanged).
      const double next = std::min(s.t_end, (std::floor(t / dt_nominal + 1e-9) + 1.0) * dt_nominal);
      if (t + dt_try > next - 1e-12 * dt_nominal) dt_try = next - t;
    }
    if (s.t_end - (t + dt_try) < 1e-12 * dt_nominal) dt_try = s.t_end - t;
    // A nominal level is k·Δt computed as such (t_end k / steps), not a sum of increments.
    const double k_level = std::round((t + dt_try) / dt_nominal);
    const double t_try = std::abs(t + dt_try - k_level * dt_nominal) < 1e-9 * dt_nominal
                             ? s.t_end * k_level / s.steps
                             : t + dt_try;
    dt_try = t_try - t;
    LoadStepStats st;
    st.step = static_cast<int>(res.steps.size()) + 1;
    VecX x_try = x, mu_try = mu;
    double lambda_try = lambda;
    const double target = s.path.displacement * t_try / s.t_end;
    const auto t0 = Clock::now();
    const NewtonOutcome out = displacement
                                  ? newton_displacement(x_try, mu_try, lambda_try, target, st)
                                  : newton(x_try, mu_try, t_try, st);
    st.wall_seconds = seconds_since(t0);
    if (!out.converged) {
      carried.add(st);
      // The increment is never cut below dt_nominal / 2^max_cuts (near a limit point it would
      // otherwise shrink without bound).
      const int depth = static_cast<int>(std::lround(std::log2(dt_nominal / dt_try)));
      if (!s.adaptive || depth >= s.max_cuts) {
        const std::string halvings =
            cuts > 0 ? fmt::format(", after {} halvings", cuts) : std::string();
        throw NewtonFailure(
            displacement
                ? fmt::format("static displacement control: step {} did not converge at control "
                              "displacement {:.6g} (load factor reached {:.6g} at control "
                              "displacement {:.6g}, increment {:.3g}{})",
                              st.step, target, lambda, s.path.displacement * t / s.t_end,
                              s.path.displacement * dt_try / s.t_end, halvings)
                : fmt::format("static load stepping: load step {} did not converge at load "
                              "factor {:.6g} (load factor reached {:.6g}, increment {:.3g}{})",
                              st.step, t_try, t, dt_try, halvings),
            out, s.residual_tolerance);
      }
      dt = 0.5 * dt_try;
      ++cuts;
      easy = 0;
      continue;
    }
    st.t = displacement ? lambda_try : t_try;
    st.path = displacement ? control_value(x_try) : t_try;
    st.dt = displacement ? lambda_try - lambda : dt_try;
    st.iterations = out.iterations;
    st.residual = out.residual;
    st.cuts = cuts;
    carried.take(st);
    cuts = 0;
    t = t_try;
    lambda = lambda_try;
    x = std::move(x_try);
    mu = std::move(mu_try);
    if (s.adaptive) {
      if (out.iterations <= s.easy_iterations) {
        if (++easy >= s.grow_after && dt < dt_nominal) {
          dt = std::min(2.0 * dt, dt_nominal);
          easy = 0;
        }
      } else {
        easy = 0;
      }
    }
    res.steps.push_back(std::move(st));
    if (observer) observer(res.steps.back(), x);
  }
  res.x = std::move(x);
  res.mu = given_multipliers(mu);
  res.analyses = cholesky.analyses() + lu.analyses() + saddle.analyses() - analyses0;
  return res;
}

// Arc length (header): from the reference along the path until λ reaches t_end.
StaticResult StaticNewtonSolver::Impl::solve_arc_length(const StaticObserver& observer) {
  const StaticSettings& s = settings;
  const PathSettings& p = s.path;
  StaticResult res;
  VecX x = problem.reference;
  VecX mu = VecX::Zero(m);
  double lambda = 0.0;
  set_prescribed(x, 0.0);
  // The tangent at the reference, δz_λ = −A⁻¹ ∂R/∂λ: the first predictor.
  LoadStepStats st0;
  evaluate(x, 0.0, true, st0);
  VecX dz_prev = linear_solve(A, VecX(-load_derivative(x, mu, 0.0, st0)));
  path_scale = reference_load_scale(x, mu);
  double dlam_prev = 1.0;
  const double w = p.load_weight * p.load_weight * dz_prev.head(nf_configuration).squaredNorm();
  const auto length = [&](const VecX& dz, double dlam) {
    return std::sqrt(dz.head(nf_configuration).squaredNorm() + w * dlam * dlam);
  };
  if (!(length(dz_prev, 1.0) > 0.0) || !std::isfinite(length(dz_prev, 1.0)))
    throw NewtonFailure(fmt::format(
        "static arc length: the tangent at the reference has no length ({:.3g}): the loads do not "
        "move the free coordinates",
        length(dz_prev, 1.0)));
  double arc = 0.0;
  int cuts = 0;
  Carried carried;
  const int analyses0 = cholesky.analyses() + lu.analyses() + saddle.analyses();
  // An accepted step: its increment is the next secant, its length adds to the path.
  const auto accept = [&](VecX& x_new, VecX& mu_new, double lambda_new, const NewtonOutcome& out,
                          LoadStepStats& st) {
    dz_prev = unknowns_difference(x_new, mu_new, x, mu);
    dlam_prev = lambda_new - lambda;
    arc += length(dz_prev, dlam_prev);
    st.t = lambda_new;
    st.dt = dlam_prev;
    st.path = arc;
    st.iterations = out.iterations;
    st.residual = out.residual;
    st.cuts = cuts;
    carried.take(st);
    cuts = 0;
    x = std::move(x_new);
    mu = std::move(mu_new);
    lambda = lambda_new;
    res.steps.push_back(std::move(st));
    if (observer) observer(res.steps.back(), x);
  };
  if (!(p.arc_length > 0.0)) {
    // The first step by load control over Δλ = dt (halved on failure): its increment is the first
    // secant and its length the first arc, so that the first arc does not leap along the linear
    // tangent off a strongly curved path (on a director beam's roll-up the tangent's length led
    // to a kinked equilibrium with 300 times the strain energy).
    double dlam = std::min(s.t_end / s.steps, s.t_end);
    for (;;) {
      LoadStepStats st;
      st.step = 1;
      VecX x1 = x, mu1 = mu;
      const auto t0 = Clock::now();
      const NewtonOutcome out = newton(x1, mu1, dlam, st);
      st.wall_seconds = seconds_since(t0);
      if (!out.converged) {
        carried.add(st);
        if (cuts >= s.max_cuts)
          throw NewtonFailure(
              fmt::format("static arc length: the first step (load control) did not converge at "
                          "load factor {:.6g}{}",
                          dlam, cuts > 0 ? fmt::format(", after {} halvings", cuts) : ""),
              out, s.residual_tolerance);
        dlam *= 0.5;
        ++cuts;
        continue;
      }
      accept(x1, mu1, dlam, out, st);
      break;
    }
  }
  const double dl_first = p.arc_length > 0.0 ? p.arc_length : arc;
  const double dl0 = p.max_arc_length > 0.0 ? std::min(dl_first, p.max_arc_length) : dl_first;
  const double dl_min = dl0 / std::ldexp(1.0, s.max_cuts);
  const double dl_max = p.max_arc_length > 0.0 ? p.max_arc_length : 10.0 * dl0;
  double dl = dl0;
  while (lambda < s.t_end) {
    if (static_cast<int>(res.steps.size()) >= p.max_steps) {
      res.stopped = fmt::format(
          "arc length: stopped after {} steps at load factor {:.6g} (t_end {:.6g} not reached)",
          p.max_steps, lambda, s.t_end);
      break;
    }
    LoadStepStats st;
    st.step = static_cast<int>(res.steps.size()) + 1;
    // Predictor: the last increment (or the tangent) scaled to the arc length.
    const double f = dl / length(dz_prev, dlam_prev);
    VecX x_try = x, mu_try = mu;
    add_to_unknowns(x_try, mu_try, f * dz_prev);
    double lambda_try = lambda + f * dlam_prev;
    const auto t0 = Clock::now();
    NewtonOutcome out =
        newton_bordered(x_try, mu_try, lambda_try, st, 0, [&](const VecX& dzR, const VecX& dzl) {
          const VecX dz = unknowns_difference(x_try, mu_try, x, mu);
          return arc_length_correction(dz.head(nf_configuration), lambda_try - lambda,
                                       dzR.head(nf_configuration), dzl.head(nf_configuration), w,
                                       dl);
        });
    bool last = false;
    if (out.converged && lambda_try >= s.t_end) {
      // λ = t_end exactly: load control from the secant between the two points around it.
      const double a = (s.t_end - lambda) / (lambda_try - lambda);
      VecX x_end = x + a * (x_try - x), mu_end = mu + a * (mu_try - mu);
      const NewtonOutcome end = newton(x_end, mu_end, s.t_end, st);
      if (end.converged) {
        x_try = std::move(x_end);
        mu_try = std::move(mu_end);
        lambda_try = s.t_end;
        out.iterations += end.iterations;
        out.residual = end.residual;
      }
      last = true;
    }
    st.wall_seconds = seconds_since(t0);
    if (!out.converged) {
      carried.add(st);
      if (0.5 * dl < dl_min * (1.0 - 1e-12))
        throw NewtonFailure(
            fmt::format("static arc length: step {} did not converge with arc length {:.3g} "
                        "(load factor reached {:.6g}, path length {:.6g}{})",
                        st.step, dl, lambda, arc,
                        cuts > 0 ? fmt::format(", after {} halvings", cuts) : std::string()),
            out, s.residual_tolerance);
      dl *= 0.5;
      ++cuts;
      continue;
    }
    accept(x_try, mu_try, lambda_try, out, st);
    if (last) break;
    const double growth = std::sqrt(static_cast<double>(p.target_iterations) /
                                    std::max(1, res.steps.back().iterations));
    dl = std::min(dl * std::clamp(growth, 0.5, 2.0), dl_max);
  }
  res.x = std::move(x);
  res.mu = given_multipliers(mu);
  res.analyses = cholesky.analyses() + lu.analyses() + saddle.analyses() - analyses0;
  return res;
}

}  // namespace isoflex::integrate
