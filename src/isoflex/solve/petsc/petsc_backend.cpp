// The PETSc module (libisoflex_petsc.so): KrylovBackend on PETSc's KSP and PC
// (solve/krylov_backend.hpp, docs/theory/solvers.md §3).
#include <petscksp.h>

#include <algorithm>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include "isoflex/solve/krylov_backend.hpp"
#include "isoflex/solve/petsc/upper_triangle.hpp"
#include "isoflex/solve/row_cuts.hpp"

static_assert(sizeof(PetscInt) == sizeof(int), "isoflex passes 32-bit index arrays to PETSc");
static_assert(sizeof(PetscScalar) == sizeof(double), "isoflex needs PETSc's real double build");

namespace isoflex::solve {

namespace {

// A PETSc error code as an exception with PETSc's own text (the error handler is
// PetscReturnErrorHandler: PETSc prints nothing itself).
void check(PetscErrorCode code, const char* what) {
  if (code == 0) return;
  const char* text = nullptr;
  PetscErrorMessage(code, &text, nullptr);
  throw std::runtime_error(std::string("PETSc: ") + what + ": " + (text ? text : "error"));
}

void finalize() {
  PetscFinalize();
}

// Unknowns per block of the multigrid smoother (setup_multigrid).
constexpr PetscInt kSmootherBlock = 1000;
// FGMRES iterations before a restart in the saddle point (make_saddle_point): 2 × 100 vectors.
constexpr PetscInt kSaddlePointRestart = 100;

// PETSc (and MPI, under mpirun or as a singleton) is started once per process, on the first
// backend. PETSc's signal handlers are off (isoflex handles SIGINT itself, app/interrupt.hpp);
// PETSC_OPTIONS still reaches every solver (their options prefix is isoflex_).
void initialize() {
  PetscBool started = PETSC_FALSE;
  check(PetscInitialized(&started), "PetscInitialized");
  if (started) return;
  check(PetscOptionsSetValue(nullptr, "-no_signal_handler", nullptr), "PetscOptionsSetValue");
  check(PetscInitializeNoArguments(), "PetscInitialize");
  check(PetscPushErrorHandler(PetscReturnErrorHandler, nullptr), "PetscPushErrorHandler");
  std::atexit(finalize);
}

// MPI's world as isoflex sees it (process_group.hpp).
class MpiWorld final : public ProcessGroup {
 public:
  MpiWorld() {
    MPI_Comm_rank(PETSC_COMM_WORLD, &rank_);
    MPI_Comm_size(PETSC_COMM_WORLD, &size_);
  }
  int rank() const override { return rank_; }
  int size() const override { return size_; }
  // A reduction onto rank 0 and its broadcast rather than MPI_Allreduce: MPI does not promise
  // that an all-reduce gives every rank the same rounding, and the ranks' Newton iterations must
  // take the same decisions on the same residuals.
  void sum(double* values, long count) const override {
    while (count > 0) {
      const int chunk = static_cast<int>(std::min<long>(count, INT_MAX));
      if (MPI_Reduce(rank_ == 0 ? MPI_IN_PLACE : values, rank_ == 0 ? values : nullptr, chunk,
                     MPI_DOUBLE, MPI_SUM, 0, PETSC_COMM_WORLD) != MPI_SUCCESS ||
          MPI_Bcast(values, chunk, MPI_DOUBLE, 0, PETSC_COMM_WORLD) != MPI_SUCCESS)
        throw std::runtime_error("MPI: the sum over the ranks failed");
      values += chunk;
      count -= chunk;
    }
  }
  [[noreturn]] void abort(int code) const override {
    std::fflush(nullptr);
    MPI_Abort(PETSC_COMM_WORLD, code);
    std::_Exit(code);  // MPI_Abort does not return
  }

 private:
  int rank_ = 0, size_ = 1;
};

const MpiWorld& world() {
  static const MpiWorld group;
  return group;
}

// The rows [begin, end) of a level that a rank owns in the distributed matrices and vectors:
// contiguous blocks, rank by rank, between the level's borders (rank_borders, row_cuts.hpp).
// P_l's rows are level l's, its columns level l + 1's.
struct RowBlock {
  PetscInt begin = 0, end = 0;
  PetscInt size() const { return end - begin; }
};

// The borders of the ranks' rows where the cut weights are `local`'s summed over the ranks.
std::vector<PetscInt> borders_of(const CutWeights& local) {
  CutWeights summed = local;
  std::vector<double>& d = summed.differences();
  world().sum(d.data(), static_cast<long>(d.size()));
  return rank_borders(summed.weights(), world().size());
}

// Rows [block.begin, block.end) of a CSR matrix with their own row starts (from 0).
std::vector<PetscInt> local_row_starts(const CsrView& M, RowBlock block) {
  std::vector<PetscInt> start(static_cast<std::size_t>(block.size()) + 1);
  for (PetscInt i = 0; i <= block.size(); ++i)
    start[static_cast<std::size_t>(i)] = M.row_start[block.begin + i] - M.row_start[block.begin];
  return start;
}

class PetscKrylov final : public KrylovBackend {
 public:
  PetscKrylov(KrylovMethod method, bool distributed)
      : method_(method),
        distributed_(distributed && world().size() > 1),
        comm_(distributed_ ? PETSC_COMM_WORLD : PETSC_COMM_SELF) {}
  ~PetscKrylov() override {
    destroy_saddle_point();
    if (ksp_) KSPDestroy(&ksp_);
    drop_levels();
    if (A_) MatDestroy(&A_);
    if (null_space_) MatNullSpaceDestroy(&null_space_);
    drop_interpolations();
  }
  PetscKrylov(const PetscKrylov&) = delete;
  PetscKrylov& operator=(const PetscKrylov&) = delete;

  void set_near_null_space(int n, int count, const double* columns) override {
    if (null_space_) check(MatNullSpaceDestroy(&null_space_), "MatNullSpaceDestroy");
    if (distributed_) {
      // Each rank's rows of the modes are taken when the matrix (its row blocks) is made.
      modes_.assign(columns, columns + static_cast<std::ptrdiff_t>(count) * n);
      modes_count_ = count;
      if (A_) attach_distributed_null_space();
      return;
    }
    std::vector<Vec> vectors(static_cast<std::size_t>(count));
    for (int k = 0; k < count; ++k) {
      check(VecCreateSeq(PETSC_COMM_SELF, n, &vectors[static_cast<std::size_t>(k)]),
            "VecCreateSeq");
      double* v = nullptr;
      check(VecGetArray(vectors[static_cast<std::size_t>(k)], &v), "VecGetArray");
      std::copy(columns + static_cast<std::ptrdiff_t>(k) * n,
                columns + static_cast<std::ptrdiff_t>(k + 1) * n, v);
      check(VecRestoreArray(vectors[static_cast<std::size_t>(k)], &v), "VecRestoreArray");
    }
    check(MatNullSpaceCreate(PETSC_COMM_SELF, PETSC_FALSE, count, vectors.data(), &null_space_),
          "MatNullSpaceCreate");
    for (Vec& v : vectors) VecDestroy(&v);
    if (A_) check(MatSetNearNullSpace(A_, null_space_), "MatSetNearNullSpace");
  }

  void set_interpolations(int count, const CsrView* P) override {
    drop_levels();
    drop_interpolations();
    // On MPI's ranks the interpolations are made with the levels' borders, which their Galerkin
    // products choose (make_distributed_levels).
    if (distributed_) interpolation_views_.assign(P, P + count);
    interpolations_.assign(distributed_ ? 0 : static_cast<std::size_t>(count), nullptr);
    for (int l = 0; l < count && !distributed_; ++l)
      check(MatCreateSeqAIJWithArrays(
                PETSC_COMM_SELF, P[l].n, P[l].cols, const_cast<PetscInt*>(P[l].row_start),
                const_cast<PetscInt*>(P[l].columns), const_cast<PetscScalar*>(P[l].values),
                &interpolations_[static_cast<std::size_t>(l)]),
            "MatCreateSeqAIJWithArrays");
    if (ksp_) check(KSPDestroy(&ksp_), "KSPDestroy");
    destroy_saddle_point();
  }

  KrylovReport solve(const CsrView& A, bool new_pattern, const double* b, double* x, double rtol,
                     double atol, int max_iterations) override {
    if (distributed_) return solve_distributed(A, new_pattern, b, x, rtol, atol, max_iterations);
    if (new_pattern || !A_ || A.row_start != row_start_ || A.columns != columns_ ||
        A.values != values_ || A.n != n_)
      make_matrix(A);
    else
      values_changed();
    if (own_galerkin_) form_level_operators(A);
    const bool first = !ksp_;
    if (!ksp_) make_ksp();
    if (own_galerkin_)
      attach_level_operators(first);
    else
      check(KSPSetOperators(ksp_, A_, A_), "KSPSetOperators");
    // MUMPS is a factorization: its one "iteration" is the triangular solves.
    return run(ksp_, A.n, b, x, rtol, atol, max_iterations, method_ != KrylovMethod::mumps,
               method_name());
  }

  KrylovReport solve_saddle_point(const CsrView& A, bool new_pattern, bool new_values,
                                  const CsrView& B, const double* schur, const double* b, double* x,
                                  double rtol, double atol, int max_iterations) override {
    if (distributed_)
      throw std::runtime_error(
          "PETSc: the saddle point (a Newton matrix with multiplier rows) is not distributed: run "
          "it on one process");
    const bool same = !new_pattern && A_ && saddle_ksp_ && A.row_start == row_start_ &&
                      A.columns == columns_ && A.values == values_ && A.n == n_ && B.n == rows_ &&
                      B.row_start[B.n] == rows_nonzeros_;
    if (same && !new_values) {
      // The same matrices (a refinement step): the preconditioner as it is.
    } else if (same) {
      values_changed();
      set_rows(B, schur);
      // A nest does not see its blocks' values change: assembling it raises its state, so that
      // the preconditioner is set up again on them (the multigrid's Galerkin products, MUMPS's
      // numbers).
      check(MatAssemblyBegin(nest_, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
      check(MatAssemblyEnd(nest_, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
    } else {
      make_matrix(A);
      make_saddle_point(B, schur);
    }
    return run(saddle_ksp_, A.n + B.n, b, x, rtol, atol, max_iterations, true,
               "FGMRES, " + method_name() + " on the augmented block");
  }

 private:
  std::string method_name() const {
    switch (method_) {
      case KrylovMethod::cg_gamg:
        return "CG with GAMG";
      case KrylovMethod::cg_hypre:
        return "CG with BoomerAMG";
      case KrylovMethod::mumps:
        return "MUMPS Cholesky";
      case KrylovMethod::cg_multigrid:
        return "CG with geometric multigrid";
    }
    return "solver";
  }

  // solve() on MPI's world: the ranks' matrices summed into an MPIAIJ matrix (a new one when the
  // pattern is new), b's and x's blocks of rows in place, x gathered onto every rank.
  KrylovReport solve_distributed(const CsrView& A, bool new_pattern, const double* b, double* x,
                                 double rtol, double atol, int max_iterations) {
    if (new_pattern || !A_ || A.row_start != row_start_ || A.columns != columns_ || A.n != n_)
      make_distributed_matrix(A);
    sum_values(A);
    own_galerkin_ = method_ == KrylovMethod::cg_multigrid && !interpolation_views_.empty();
    if (own_galerkin_) form_level_operators(A);
    const bool first = !ksp_;
    if (!ksp_) make_ksp();
    if (own_galerkin_)
      attach_level_operators(first);
    else
      check(KSPSetOperators(ksp_, A_, A_), "KSPSetOperators");
    const RowBlock rows = rows_of(0);
    check(KSPSetTolerances(ksp_, rtol, atol, PETSC_DEFAULT, max_iterations), "KSPSetTolerances");
    Vec vb = nullptr, vx = nullptr;
    check(VecCreateMPIWithArray(PETSC_COMM_WORLD, 1, rows.size(), A.n, b + rows.begin, &vb),
          "VecCreateMPIWithArray");
    check(VecCreateMPIWithArray(PETSC_COMM_WORLD, 1, rows.size(), A.n, x + rows.begin, &vx),
          "VecCreateMPIWithArray");
    const PetscErrorCode code = KSPSolve(ksp_, vb, vx);
    VecDestroy(&vb);
    VecDestroy(&vx);
    check(code, "KSPSolve");
    // Every rank's block of x to every rank (the Newton update is replicated).
    const std::vector<PetscInt>& borders = borders_.front();
    std::vector<int> counts, starts(borders.begin(), borders.end() - 1);
    for (std::size_t r = 0; r + 1 < borders.size(); ++r)
      counts.push_back(borders[r + 1] - borders[r]);
    if (MPI_Allgatherv(MPI_IN_PLACE, 0, MPI_DATATYPE_NULL, x, counts.data(), starts.data(),
                       MPI_DOUBLE, PETSC_COMM_WORLD) != MPI_SUCCESS)
      throw std::runtime_error("MPI: gathering the solution failed");
    return report(ksp_, method_ != KrylovMethod::mumps, method_name());
  }

  // The distributed matrix of A's pattern: each rank's block of rows, preallocated from the
  // pattern (the same on every rank), values zero. The ranks' borders are chosen on the sum of
  // the ranks' |A_ij| (each rank's A holds its own elements' entries): a bending strip, summed by
  // rank 0 alone, lies within one rank.
  void make_distributed_matrix(const CsrView& A) {
    if (A_) check(MatDestroy(&A_), "MatDestroy");
    drop_levels();
    drop_interpolations();
    CutWeights weights(A.n);
    weights.add(A);
    borders_.assign(1, borders_of(weights));
    const RowBlock rows = rows_of(0);
    const std::vector<PetscInt> start = local_row_starts(A, rows);
    check(MatCreate(PETSC_COMM_WORLD, &A_), "MatCreate");
    check(MatSetSizes(A_, rows.size(), rows.size(), A.n, A.n), "MatSetSizes");
    check(MatSetType(A_, MATMPIAIJ), "MatSetType");
    check(MatMPIAIJSetPreallocationCSR(A_, start.data(), A.columns + A.row_start[rows.begin],
                                       nullptr),
          "MatMPIAIJSetPreallocationCSR");
    // An entry outside the pattern is a defect of the caller, not a reason to reallocate.
    check(MatSetOption(A_, MAT_NEW_NONZERO_LOCATION_ERR, PETSC_TRUE), "MatSetOption");
    check(MatSetOption(A_, MAT_SYMMETRIC, PETSC_TRUE), "MatSetOption");
    check(MatSetOption(A_, MAT_SPD, PETSC_TRUE), "MatSetOption");
    row_start_ = A.row_start;
    columns_ = A.columns;
    values_ = nullptr;
    n_ = A.n;
    if (!modes_.empty()) attach_distributed_null_space();
    if (ksp_) check(KSPDestroy(&ksp_), "KSPDestroy");
  }

  // This rank's rows of level `level` (0: A's).
  RowBlock rows_of(std::size_t level) const {
    const std::vector<PetscInt>& b = borders_[level];
    const auto rank = static_cast<std::size_t>(world().rank());
    return {b[rank], b[rank + 1]};
  }

  // The interpolations P_l on MPI's ranks and the levels' Galerkin products Pᵀ A P (after A's
  // values are summed), level by level. P_l's columns are split as level l + 1's rows, whose
  // borders are chosen on that level's Pᵀ A P: where the equal shares cut heavy coupling, P_l is
  // made again with the moved borders and its product formed again (once per pattern).
  void make_distributed_levels() {
    const int size = world().size();
    Mat fine = A_;
    for (std::size_t l = 0; l < interpolation_views_.size(); ++l) {
      const CsrView& P = interpolation_views_[l];
      std::vector<PetscInt> next{0};
      for (long long r = 1; r <= size; ++r)
        next.push_back(static_cast<PetscInt>(P.cols * r / size));
      Mat I = distributed_interpolation(P, l, next), C = nullptr;
      check(MatPtAP(fine, I, MAT_INITIAL_MATRIX, PETSC_DEFAULT, &C), "MatPtAP");
      const std::vector<PetscInt> chosen = borders_of(local_cut_weights(C, P.cols));
      if (chosen != next) {
        check(MatDestroy(&C), "MatDestroy");
        check(MatDestroy(&I), "MatDestroy");
        I = distributed_interpolation(P, l, chosen);
        check(MatPtAP(fine, I, MAT_INITIAL_MATRIX, PETSC_DEFAULT, &C), "MatPtAP");
      }
      borders_.push_back(chosen);
      interpolations_.push_back(I);
      coarse_.push_back(C);
      fine = C;
    }
  }

  // P_l with this rank's rows of level l and `columns` as the borders of its columns.
  Mat distributed_interpolation(const CsrView& P, std::size_t l,
                                const std::vector<PetscInt>& columns) const {
    const RowBlock rows = rows_of(l);
    const auto rank = static_cast<std::size_t>(world().rank());
    const std::vector<PetscInt> start = local_row_starts(P, rows);
    Mat I = nullptr;
    check(
        MatCreateMPIAIJWithArrays(PETSC_COMM_WORLD, rows.size(), columns[rank + 1] - columns[rank],
                                  P.n, P.cols, start.data(), P.columns + P.row_start[rows.begin],
                                  P.values + P.row_start[rows.begin], &I),
        "MatCreateMPIAIJWithArrays");
    return I;
  }

  // The cut weights of this rank's rows of the distributed n × n matrix M.
  static CutWeights local_cut_weights(Mat M, PetscInt n) {
    CutWeights weights(n);
    PetscInt begin = 0, end = 0;
    check(MatGetOwnershipRange(M, &begin, &end), "MatGetOwnershipRange");
    for (PetscInt i = begin; i < end; ++i) {
      PetscInt count = 0;
      const PetscInt* columns = nullptr;
      const PetscScalar* values = nullptr;
      check(MatGetRow(M, i, &count, &columns, &values), "MatGetRow");
      for (PetscInt k = 0; k < count; ++k) weights.add(i, columns[k], values[k]);
      check(MatRestoreRow(M, i, &count, &columns, &values), "MatRestoreRow");
    }
    return weights;
  }

  // A ← Σ over the ranks of their A's values: each rank adds its own rows whole and, of the
  // other ranks' rows, the entries its elements gave (non-zero: a zero adds nothing, and the
  // entries sent to other ranks are then those of the elements along the blocks' borders).
  void sum_values(const CsrView& A) {
    check(MatZeroEntries(A_), "MatZeroEntries");
    const RowBlock rows = rows_of(0);
    std::vector<PetscInt> cols;
    std::vector<PetscScalar> vals;
    for (PetscInt i = 0; i < A.n; ++i) {
      const PetscInt k0 = A.row_start[i], k1 = A.row_start[i + 1];
      if (i >= rows.begin && i < rows.end) {
        check(MatSetValues(A_, 1, &i, k1 - k0, A.columns + k0, A.values + k0, ADD_VALUES),
              "MatSetValues");
        continue;
      }
      cols.clear();
      vals.clear();
      for (PetscInt k = k0; k < k1; ++k)
        if (A.values[k] != 0.0) {
          cols.push_back(A.columns[k]);
          vals.push_back(A.values[k]);
        }
      if (!cols.empty())
        check(MatSetValues(A_, 1, &i, static_cast<PetscInt>(cols.size()), cols.data(), vals.data(),
                           ADD_VALUES),
              "MatSetValues");
    }
    check(MatAssemblyBegin(A_, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
    check(MatAssemblyEnd(A_, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
  }

  // The near null space of set_near_null_space on A's blocks of rows.
  void attach_distributed_null_space() {
    if (null_space_) check(MatNullSpaceDestroy(&null_space_), "MatNullSpaceDestroy");
    const RowBlock rows = rows_of(0);
    if (static_cast<long long>(modes_count_) * n_ != static_cast<long long>(modes_.size())) return;
    std::vector<Vec> vectors(static_cast<std::size_t>(modes_count_));
    for (int k = 0; k < modes_count_; ++k) {
      Vec& v = vectors[static_cast<std::size_t>(k)];
      check(VecCreateMPI(PETSC_COMM_WORLD, rows.size(), n_, &v), "VecCreateMPI");
      double* a = nullptr;
      check(VecGetArray(v, &a), "VecGetArray");
      const double* column = modes_.data() + static_cast<std::ptrdiff_t>(k) * n_;
      std::copy(column + rows.begin, column + rows.end, a);
      check(VecRestoreArray(v, &a), "VecRestoreArray");
    }
    check(MatNullSpaceCreate(PETSC_COMM_WORLD, PETSC_FALSE, modes_count_, vectors.data(),
                             &null_space_),
          "MatNullSpaceCreate");
    for (Vec& v : vectors) VecDestroy(&v);
    check(MatSetNearNullSpace(A_, null_space_), "MatSetNearNullSpace");
  }

  // The iterations, residual and reason of `ksp`'s last solve; throws if it failed.
  static KrylovReport report(KSP ksp, bool count, const std::string& name) {
    KrylovReport report;
    KSPConvergedReason reason;
    check(KSPGetConvergedReason(ksp, &reason), "KSPGetConvergedReason");
    report.reason = KSPConvergedReasons[reason];
    PetscInt its = 0;
    check(KSPGetIterationNumber(ksp, &its), "KSPGetIterationNumber");
    report.iterations = count ? static_cast<int>(its) : 0;
    check(KSPGetResidualNorm(ksp, &report.residual), "KSPGetResidualNorm");
    if (reason < 0)
      throw std::runtime_error("PETSc " + name + ": " + report.reason + " after " +
                               std::to_string(its) + " iterations");
    return report;
  }

  // x = A⁻¹ b by `ksp` from x = 0 (b and x: n entries, the caller's arrays).
  static KrylovReport run(KSP ksp, int n, const double* b, double* x, double rtol, double atol,
                          int max_iterations, bool count, const std::string& name) {
    check(KSPSetTolerances(ksp, rtol, atol, PETSC_DEFAULT, max_iterations), "KSPSetTolerances");
    Vec vb = nullptr, vx = nullptr;
    check(VecCreateSeqWithArray(PETSC_COMM_SELF, 1, n, b, &vb), "VecCreateSeqWithArray");
    check(VecCreateSeqWithArray(PETSC_COMM_SELF, 1, n, x, &vx), "VecCreateSeqWithArray");
    const PetscErrorCode code = KSPSolve(ksp, vb, vx);
    VecDestroy(&vb);
    VecDestroy(&vx);
    check(code, "KSPSolve");
    return report(ksp, count, name);
  }

  // The values in A's arrays changed: restoring the value array is what tells PETSc (it raises the
  // matrix's state, so that the preconditioner is set up again).
  void values_changed() {
    PetscScalar* values = nullptr;
    check(MatSeqAIJGetArray(A_, &values), "MatSeqAIJGetArray");
    check(MatSeqAIJRestoreArray(A_, &values), "MatSeqAIJRestoreArray");
  }

  // A's arrays in place: MatCreateSeqAIJWithArrays neither copies nor frees them.
  void make_matrix(const CsrView& A) {
    if (A_) check(MatDestroy(&A_), "MatDestroy");
    check(MatCreateSeqAIJWithArrays(PETSC_COMM_SELF, A.n, A.n, const_cast<PetscInt*>(A.row_start),
                                    const_cast<PetscInt*>(A.columns),
                                    const_cast<PetscScalar*>(A.values), &A_),
          "MatCreateSeqAIJWithArrays");
    check(MatSetOption(A_, MAT_SYMMETRIC, PETSC_TRUE), "MatSetOption");
    check(MatSetOption(A_, MAT_SPD, PETSC_TRUE), "MatSetOption");
    if (null_space_) check(MatSetNearNullSpace(A_, null_space_), "MatSetNearNullSpace");
    row_start_ = A.row_start;
    columns_ = A.columns;
    values_ = A.values;
    n_ = A.n;
    // A new pattern is a new hierarchy and a new symbolic factorization.
    if (ksp_) check(KSPDestroy(&ksp_), "KSPDestroy");
    drop_levels();
    own_galerkin_ = method_ == KrylovMethod::cg_multigrid && !interpolations_.empty() &&
                    UpperTriangle::possible(A);
  }

  // The multigrid's Galerkin products Pᵀ A P on A itself and, on one process, A's upper triangle
  // (SBAIJ, half the bytes of A's AIJ per product) for the products of CG and of the finest
  // level. PETSc forms the Galerkin products only from one matrix per level, so they are made
  // here, level by level; MAT_REUSE_MATRIX keeps their patterns across Newton iterations.
  void form_level_operators(const CsrView& A) {
    if (distributed_ && interpolations_.empty()) return make_distributed_levels();
    if (!distributed_ && !upper_.mat())
      upper_.make(A);
    else if (!distributed_)
      upper_.update(A);
    const MatReuse reuse = coarse_.empty() ? MAT_INITIAL_MATRIX : MAT_REUSE_MATRIX;
    coarse_.resize(interpolations_.size(), nullptr);
    Mat fine = A_;
    for (std::size_t l = 0; l < interpolations_.size(); ++l) {
      check(MatPtAP(fine, interpolations_[l], reuse, PETSC_DEFAULT, &coarse_[l]), "MatPtAP");
      fine = coarse_[l];
    }
  }

  // The levels' operators to the KSP and the smoothers; on the KSP's first solve (`first`) also
  // the smoothers' blocks (not of the coarsest level's factorization), before PETSc sets them up.
  void attach_level_operators(bool first) {
    check(KSPSetOperators(ksp_, distributed_ ? A_ : upper_.mat(), A_), "KSPSetOperators");
    PC pc = nullptr;
    check(KSPGetPC(ksp_, &pc), "KSPGetPC");
    const int count = static_cast<int>(coarse_.size());
    for (int l = 0; l <= count; ++l) {
      KSP smoother = nullptr;
      check(PCMGGetSmoother(pc, count - l, &smoother), "PCMGGetSmoother");
      const Mat M = l == 0 ? A_ : coarse_[static_cast<std::size_t>(l - 1)];
      if (l > 0) check(KSPSetOperators(smoother, M, M), "KSPSetOperators");
      if (first && l < count) set_smoother_blocks(smoother, M);
    }
  }

  // No block of a level's smoother ends inside a band of heavy coupling of its matrix
  // (row_cuts.hpp): a bending strip cut by a block border is left unrelaxed. On one process,
  // where no equal block ends there, PETSc's equal blocks stay. On MPI's ranks each rank's blocks
  // lie in its own rows (PCBJacobiSetLocalBlocks), cut where its diagonal block (the entries
  // between its own rows) is light; the rank borders are light already (make_distributed_levels).
  void set_smoother_blocks(KSP smoother, Mat M) const {
    Mat local = M;
    if (distributed_) {
      Mat off = nullptr;
      const PetscInt* colmap = nullptr;
      check(MatMPIAIJGetSeqAIJ(M, &local, &off, &colmap), "MatMPIAIJGetSeqAIJ");
    }
    PetscInt n = 0;
    const PetscInt *rows = nullptr, *columns = nullptr;
    PetscBool done = PETSC_FALSE;
    check(MatGetRowIJ(local, 0, PETSC_FALSE, PETSC_FALSE, &n, &rows, &columns, &done),
          "MatGetRowIJ");
    if (!done) return;
    const int local_rows = static_cast<int>(n);  // (MatRestoreRowIJ zeroes n)
    const PetscScalar* values = nullptr;
    check(MatSeqAIJGetArrayRead(local, &values), "MatSeqAIJGetArrayRead");
    std::vector<int> lengths =
        smoother_blocks(CsrView{local_rows, 0, rows, columns, values}, kSmootherBlock);
    check(MatSeqAIJRestoreArrayRead(local, &values), "MatSeqAIJRestoreArrayRead");
    check(MatRestoreRowIJ(local, 0, PETSC_FALSE, PETSC_FALSE, &n, &rows, &columns, &done),
          "MatRestoreRowIJ");
    PC block = nullptr;
    check(KSPGetPC(smoother, &block), "KSPGetPC");
    if (!distributed_) {
      if (!lengths.empty())
        check(PCBJacobiSetTotalBlocks(block, static_cast<PetscInt>(lengths.size()), lengths.data()),
              "PCBJacobiSetTotalBlocks");
      return;
    }
    if (lengths.empty()) {
      const int count = std::max(1, local_rows / static_cast<int>(kSmootherBlock));
      for (int k = 0; k < count; ++k)
        lengths.push_back(local_rows / count + (k < local_rows % count ? 1 : 0));
    }
    check(PCBJacobiSetLocalBlocks(block, static_cast<PetscInt>(lengths.size()), lengths.data()),
          "PCBJacobiSetLocalBlocks");
  }

  void drop_levels() {
    upper_.clear();
    for (Mat& M : coarse_) MatDestroy(&M);
    coarse_.clear();
  }

  // The interpolations' matrices (on MPI's ranks made again with the next levels' borders).
  void drop_interpolations() {
    for (Mat& P : interpolations_) MatDestroy(&P);
    interpolations_.clear();
    if (borders_.size() > 1) borders_.resize(1);
  }

  void make_ksp() {
    check(KSPCreate(comm_, &ksp_), "KSPCreate");
    check(KSPSetOptionsPrefix(ksp_, "isoflex_"), "KSPSetOptionsPrefix");
    PC pc = nullptr;
    check(KSPGetPC(ksp_, &pc), "KSPGetPC");
    check(KSPSetType(ksp_, method_ == KrylovMethod::mumps ? KSPPREONLY : KSPCG), "KSPSetType");
    set_preconditioner(pc, own_galerkin_);
    if (method_ != KrylovMethod::mumps)
      check(KSPSetNormType(ksp_, KSP_NORM_UNPRECONDITIONED), "KSPSetNormType");
    check(KSPSetFromOptions(ksp_), "KSPSetFromOptions");
  }

  // The method's preconditioner of A (of Â in the saddle point). own_galerkin: the multigrid's
  // levels get their operators from form_level_operators and attach_level_operators.
  void set_preconditioner(PC pc, bool own_galerkin = false) {
    switch (method_) {
      case KrylovMethod::cg_gamg:
        check(PCSetType(pc, PCGAMG), "PCSetType");
        // Newton's matrices change their values, not their graph: keep the aggregates and
        // prolongators, recompute the Galerkin products.
        check(PCGAMGSetReuseInterpolation(pc, PETSC_TRUE), "PCGAMGSetReuseInterpolation");
        break;
      case KrylovMethod::cg_hypre:
        check(PCSetType(pc, PCHYPRE), "PCSetType");
        check(PCHYPRESetType(pc, "boomeramg"), "PCHYPRESetType");
        break;
      case KrylovMethod::cg_multigrid:
        setup_multigrid(pc, own_galerkin);
        break;
      case KrylovMethod::mumps:
        check(PCSetType(pc, PCCHOLESKY), "PCSetType");
        check(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS), "PCFactorSetMatSolverType");
        break;
    }
  }

  // B_H's values and the Schur diagonal into the kept matrices (the same pattern).
  void set_rows(const CsrView& B, const double* schur) {
    PetscScalar* v = nullptr;
    check(MatSeqAIJGetArray(B_, &v), "MatSeqAIJGetArray");
    std::copy(B.values, B.values + B.row_start[B.n], v);
    check(MatSeqAIJRestoreArray(B_, &v), "MatSeqAIJRestoreArray");
    check(MatSeqAIJGetArray(S_, &v), "MatSeqAIJGetArray");
    std::copy(schur, schur + B.n, v);
    check(MatSeqAIJRestoreArray(S_, &v), "MatSeqAIJRestoreArray");
  }

  // The saddle point's operator, the nest [A Bᵀ; B 0] (Bᵀ not formed: MatCreateTranspose), and
  // its solver: FGMRES right-preconditioned by PCFIELDSPLIT's upper block triangle. A's block is
  // one application of the method's preconditioner (KSPPREONLY: PCFIELDSPLIT's default for it
  // is an inner GMRES), S's the inverse of the diagonal `schur` (PCJACOBI on a diagonal matrix is
  // exact). PETSC_OPTIONS overrides any of it (prefixes isoflex_fieldsplit_primal_, _rows_).
  void make_saddle_point(const CsrView& B, const double* schur) {
    destroy_saddle_point();
    const PetscInt h = B.n, p = B.cols;
    std::vector<PetscInt> diagonal(static_cast<std::size_t>(h) + 1);
    for (PetscInt i = 0; i <= h; ++i) diagonal[static_cast<std::size_t>(i)] = i;
    std::vector<PetscScalar> zeros(static_cast<std::size_t>(h), 0.0);
    check(MatCreateSeqAIJ(PETSC_COMM_SELF, h, p, 0, nullptr, &B_), "MatCreateSeqAIJ");
    check(MatSeqAIJSetPreallocationCSR(B_, B.row_start, B.columns, B.values),
          "MatSeqAIJSetPreallocationCSR");
    check(MatCreateTranspose(B_, &BT_), "MatCreateTranspose");
    check(MatCreateSeqAIJ(PETSC_COMM_SELF, h, h, 1, nullptr, &Z_), "MatCreateSeqAIJ");
    check(MatSeqAIJSetPreallocationCSR(Z_, diagonal.data(), diagonal.data(), zeros.data()),
          "MatSeqAIJSetPreallocationCSR");
    check(MatCreateSeqAIJ(PETSC_COMM_SELF, h, h, 1, nullptr, &S_), "MatCreateSeqAIJ");
    check(MatSeqAIJSetPreallocationCSR(S_, diagonal.data(), diagonal.data(), schur),
          "MatSeqAIJSetPreallocationCSR");
    const Mat blocks[4] = {A_, BT_, B_, Z_};
    check(MatCreateNest(PETSC_COMM_SELF, 2, nullptr, 2, nullptr, blocks, &nest_), "MatCreateNest");
    rows_ = h;
    rows_nonzeros_ = B.row_start[h];

    check(KSPCreate(PETSC_COMM_SELF, &saddle_ksp_), "KSPCreate");
    check(KSPSetOptionsPrefix(saddle_ksp_, "isoflex_"), "KSPSetOptionsPrefix");
    check(KSPSetType(saddle_ksp_, KSPFGMRES), "KSPSetType");
    // No restart in a solve that converges (its recurrence keeps falling past the round-off of
    // the true residual, as CG's does; a restart starts again from that round-off).
    check(KSPGMRESSetRestart(saddle_ksp_, kSaddlePointRestart), "KSPGMRESSetRestart");
    check(KSPSetOperators(saddle_ksp_, nest_, nest_), "KSPSetOperators");
    PC pc = nullptr;
    check(KSPGetPC(saddle_ksp_, &pc), "KSPGetPC");
    check(PCSetType(pc, PCFIELDSPLIT), "PCSetType");
    IS fields[2];
    check(MatNestGetISs(nest_, fields, nullptr), "MatNestGetISs");
    check(PCFieldSplitSetIS(pc, "primal", fields[0]), "PCFieldSplitSetIS");
    check(PCFieldSplitSetIS(pc, "rows", fields[1]), "PCFieldSplitSetIS");
    check(PCFieldSplitSetType(pc, PC_COMPOSITE_SCHUR), "PCFieldSplitSetType");
    check(PCFieldSplitSetSchurFactType(pc, PC_FIELDSPLIT_SCHUR_FACT_UPPER),
          "PCFieldSplitSetSchurFactType");
    check(PCFieldSplitSetSchurPre(pc, PC_FIELDSPLIT_SCHUR_PRE_USER, S_), "PCFieldSplitSetSchurPre");
    check(KSPSetFromOptions(saddle_ksp_), "KSPSetFromOptions");
    // The blocks' solvers exist once the field split is set up (not yet the blocks' own
    // preconditioners, which are set up on their first use).
    check(PCSetUp(pc), "PCSetUp");
    PetscInt count = 0;
    KSP* sub = nullptr;
    check(PCFieldSplitGetSubKSP(pc, &count, &sub), "PCFieldSplitGetSubKSP");
    const auto user_set = [](KSP ksp) {
      const char* prefix = nullptr;
      PetscBool set = PETSC_FALSE;
      check(KSPGetOptionsPrefix(ksp, &prefix), "KSPGetOptionsPrefix");
      check(PetscOptionsHasName(nullptr, prefix, "-pc_type", &set), "PetscOptionsHasName");
      return set == PETSC_TRUE;
    };
    for (PetscInt k = 0; k < count; ++k) {
      PC sub_pc = nullptr;
      check(KSPGetPC(sub[k], &sub_pc), "KSPGetPC");
      if (user_set(sub[k])) continue;
      check(KSPSetType(sub[k], KSPPREONLY), "KSPSetType");
      if (k == 0)
        set_preconditioner(sub_pc);
      else
        check(PCSetType(sub_pc, PCJACOBI), "PCSetType");
      check(KSPSetFromOptions(sub[k]), "KSPSetFromOptions");
    }
    PetscFree(sub);
  }

  void destroy_saddle_point() {
    if (saddle_ksp_) KSPDestroy(&saddle_ksp_);
    if (nest_) MatDestroy(&nest_);
    if (BT_) MatDestroy(&BT_);
    if (B_) MatDestroy(&B_);
    if (Z_) MatDestroy(&Z_);
    if (S_) MatDestroy(&S_);
    rows_ = rows_nonzeros_ = -1;
  }

  // PETSc numbers the levels from the coarsest (0) to the finest (count): P_l interpolates into
  // level count + 1 − l. The coarse matrices are the Galerkin products Pᵀ A P; the coarsest is
  // factorized (Cholesky). The smoother of the others is Chebyshev (PETSc's default, two steps)
  // on block Jacobi with blocks of about kSmootherBlock consecutive unknowns, each factorized:
  // strips of control-point rows. With point smoothers (SOR) the CG iterations doubled with every
  // level on a thin shell; with these blocks they barely grow (docs/theory/solvers.md §4 has the
  // counts). PETSC_OPTIONS overrides any of it.
  void setup_multigrid(PC pc, bool own_galerkin) {
    if (interpolations_.empty()) {
      // A model no larger than the coarsest level: that level's factorization is the solve.
      set_cholesky(pc);
      return;
    }
    const int count = static_cast<int>(interpolations_.size());
    check(PCSetType(pc, PCMG), "PCSetType");
    check(PCMGSetLevels(pc, count + 1, nullptr), "PCMGSetLevels");
    for (int l = 1; l <= count; ++l)
      check(
          PCMGSetInterpolation(pc, count + 1 - l, interpolations_[static_cast<std::size_t>(l - 1)]),
          "PCMGSetInterpolation");
    check(PCMGSetGalerkin(pc, own_galerkin ? PC_MG_GALERKIN_NONE : PC_MG_GALERKIN_BOTH),
          "PCMGSetGalerkin");
    // The finest level's products by the KSP's Amat (the upper triangle), its smoother's blocks
    // from the Pmat (A).
    if (own_galerkin) check(PCSetUseAmat(pc, PETSC_TRUE), "PCSetUseAmat");
    for (int l = 1; l <= count; ++l) {
      PetscInt n = 0;
      check(MatGetSize(interpolations_[static_cast<std::size_t>(l - 1)], &n, nullptr),
            "MatGetSize");
      KSP smoother = nullptr;
      check(PCMGGetSmoother(pc, count + 1 - l, &smoother), "PCMGGetSmoother");
      PC block = nullptr;
      check(KSPGetPC(smoother, &block), "KSPGetPC");
      check(PCSetType(block, PCBJACOBI), "PCSetType");
      if (!distributed_)  // else each rank's own (set_smoother_blocks)
        check(PCBJacobiSetTotalBlocks(block, std::max<PetscInt>(1, n / kSmootherBlock), nullptr),
              "PCBJacobiSetTotalBlocks");
    }
    // The option of the levels' blocks, under the PC's own prefix (isoflex_, or that of the
    // saddle point's primal block).
    const char* prefix = nullptr;
    check(PCGetOptionsPrefix(pc, &prefix), "PCGetOptionsPrefix");
    const std::string levels = std::string(prefix ? prefix : "") + "mg_levels_";
    PetscBool user_sub = PETSC_FALSE;
    check(PetscOptionsHasName(nullptr, levels.c_str(), "-sub_pc_type", &user_sub),
          "PetscOptionsHasName");
    if (!user_sub)
      check(PetscOptionsSetValue(nullptr, ("-" + levels + "sub_pc_type").c_str(), "cholesky"),
            "PetscOptionsSetValue");
    KSP coarse = nullptr;
    check(PCMGGetCoarseSolve(pc, &coarse), "PCMGGetCoarseSolve");
    check(KSPSetType(coarse, KSPPREONLY), "KSPSetType");
    PC coarse_pc = nullptr;
    check(KSPGetPC(coarse, &coarse_pc), "KSPGetPC");
    set_cholesky(coarse_pc);
  }

  // A Cholesky factorization as `pc`: PETSc's own on one process; on MPI's world a redundant one
  // (the matrix gathered onto every rank and factorized there, PCREDUNDANT): the coarsest level
  // is small, and PETSc's Cholesky is sequential.
  void set_cholesky(PC pc) {
    if (!distributed_) {
      check(PCSetType(pc, PCCHOLESKY), "PCSetType");
      return;
    }
    check(PCSetType(pc, PCREDUNDANT), "PCSetType");
    KSP inner = nullptr;
    check(PCRedundantGetKSP(pc, &inner), "PCRedundantGetKSP");
    PC inner_pc = nullptr;
    check(KSPGetPC(inner, &inner_pc), "KSPGetPC");
    check(PCSetType(inner_pc, PCCHOLESKY), "PCSetType");
  }

  KrylovMethod method_;
  bool distributed_;           // MPI's world has more than one rank: the matrices are distributed
  MPI_Comm comm_;              // PETSC_COMM_WORLD if distributed_, else PETSC_COMM_SELF
  std::vector<double> modes_;  // distributed_: the near null space's columns, whole
  int modes_count_ = 0;
  std::vector<Mat> interpolations_;
  std::vector<CsrView> interpolation_views_;  // distributed_: set_interpolations's, kept alive
  // distributed_: the first rows of the ranks and the end, on every level, the finest first
  // (rows_of).
  std::vector<std::vector<PetscInt>> borders_;
  Mat A_ = nullptr;
  // form_level_operators: A's upper triangle (one process) and the coarse levels' Pᵀ A P, finest
  // first.
  bool own_galerkin_ = false;
  UpperTriangle upper_;
  std::vector<Mat> coarse_;
  KSP ksp_ = nullptr;
  MatNullSpace null_space_ = nullptr;
  const int* row_start_ = nullptr;
  const int* columns_ = nullptr;
  const double* values_ = nullptr;
  int n_ = -1;
  // The saddle point (make_saddle_point): B_H, Bᵀ, the zero block, S's diagonal, the nest.
  Mat B_ = nullptr, BT_ = nullptr, Z_ = nullptr, S_ = nullptr, nest_ = nullptr;
  KSP saddle_ksp_ = nullptr;
  int rows_ = -1, rows_nonzeros_ = -1;
};

}  // namespace

}  // namespace isoflex::solve

extern "C" const isoflex::solve::ProcessGroup* isoflex_petsc_processes(std::string* error) {
  try {
    isoflex::solve::initialize();
    return &isoflex::solve::world();
  } catch (const std::exception& e) {
    if (error) *error = e.what();
    return nullptr;
  }
}

extern "C" isoflex::solve::KrylovBackend* isoflex_petsc_create(int method, int distributed,
                                                               std::string* error) {
  try {
    isoflex::solve::initialize();
    return new isoflex::solve::PetscKrylov(static_cast<isoflex::solve::KrylovMethod>(method),
                                           distributed != 0);
  } catch (const std::exception& e) {
    if (error) *error = e.what();
    return nullptr;
  }
}
