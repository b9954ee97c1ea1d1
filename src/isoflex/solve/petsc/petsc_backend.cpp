// The PETSc module (libisoflex_petsc.so): KrylovBackend on PETSc's KSP and PC
// (solve/krylov_backend.hpp, docs/theory/solvers.md §3).
#include <petscksp.h>

#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include "isoflex/solve/krylov_backend.hpp"

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

class PetscKrylov final : public KrylovBackend {
 public:
  explicit PetscKrylov(KrylovMethod method) : method_(method) {}
  ~PetscKrylov() override {
    if (ksp_) KSPDestroy(&ksp_);
    if (A_) MatDestroy(&A_);
    if (null_space_) MatNullSpaceDestroy(&null_space_);
    for (Mat& P : interpolations_) MatDestroy(&P);
  }
  PetscKrylov(const PetscKrylov&) = delete;
  PetscKrylov& operator=(const PetscKrylov&) = delete;

  void set_near_null_space(int n, int count, const double* columns) override {
    if (null_space_) check(MatNullSpaceDestroy(&null_space_), "MatNullSpaceDestroy");
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
    for (Mat& M : interpolations_) check(MatDestroy(&M), "MatDestroy");
    interpolations_.assign(static_cast<std::size_t>(count), nullptr);
    for (int l = 0; l < count; ++l)
      check(MatCreateSeqAIJWithArrays(
                PETSC_COMM_SELF, P[l].n, P[l].cols, const_cast<PetscInt*>(P[l].row_start),
                const_cast<PetscInt*>(P[l].columns), const_cast<PetscScalar*>(P[l].values),
                &interpolations_[static_cast<std::size_t>(l)]),
            "MatCreateSeqAIJWithArrays");
    if (ksp_) check(KSPDestroy(&ksp_), "KSPDestroy");
  }

  KrylovReport solve(const CsrView& A, bool new_pattern, const double* b, double* x, double rtol,
                     double atol, int max_iterations) override {
    if (new_pattern || !A_ || A.row_start != row_start_ || A.columns != columns_ ||
        A.values != values_ || A.n != n_)
      make_matrix(A);
    else
      values_changed();
    if (!ksp_) make_ksp();
    check(KSPSetOperators(ksp_, A_, A_), "KSPSetOperators");
    check(KSPSetTolerances(ksp_, rtol, atol, PETSC_DEFAULT, max_iterations), "KSPSetTolerances");
    Vec vb = nullptr, vx = nullptr;
    check(VecCreateSeqWithArray(PETSC_COMM_SELF, 1, A.n, b, &vb), "VecCreateSeqWithArray");
    check(VecCreateSeqWithArray(PETSC_COMM_SELF, 1, A.n, x, &vx), "VecCreateSeqWithArray");
    const PetscErrorCode code = KSPSolve(ksp_, vb, vx);
    VecDestroy(&vb);
    VecDestroy(&vx);
    check(code, "KSPSolve");
    KrylovReport report;
    KSPConvergedReason reason;
    check(KSPGetConvergedReason(ksp_, &reason), "KSPGetConvergedReason");
    report.reason = KSPConvergedReasons[reason];
    PetscInt its = 0;
    check(KSPGetIterationNumber(ksp_, &its), "KSPGetIterationNumber");
    // MUMPS is a factorization: its one "iteration" is the triangular solves.
    report.iterations = method_ == KrylovMethod::mumps ? 0 : static_cast<int>(its);
    check(KSPGetResidualNorm(ksp_, &report.residual), "KSPGetResidualNorm");
    if (reason < 0)
      throw std::runtime_error("PETSc " + method_name() + ": " + report.reason + " after " +
                               std::to_string(its) + " iterations");
    return report;
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
  }

  void make_ksp() {
    check(KSPCreate(PETSC_COMM_SELF, &ksp_), "KSPCreate");
    check(KSPSetOptionsPrefix(ksp_, "isoflex_"), "KSPSetOptionsPrefix");
    PC pc = nullptr;
    check(KSPGetPC(ksp_, &pc), "KSPGetPC");
    switch (method_) {
      case KrylovMethod::cg_gamg:
        check(KSPSetType(ksp_, KSPCG), "KSPSetType");
        check(PCSetType(pc, PCGAMG), "PCSetType");
        // Newton's matrices change their values, not their graph: keep the aggregates and
        // prolongators, recompute the Galerkin products.
        check(PCGAMGSetReuseInterpolation(pc, PETSC_TRUE), "PCGAMGSetReuseInterpolation");
        break;
      case KrylovMethod::cg_hypre:
        check(KSPSetType(ksp_, KSPCG), "KSPSetType");
        check(PCSetType(pc, PCHYPRE), "PCSetType");
        check(PCHYPRESetType(pc, "boomeramg"), "PCHYPRESetType");
        break;
      case KrylovMethod::cg_multigrid:
        check(KSPSetType(ksp_, KSPCG), "KSPSetType");
        setup_multigrid(pc);
        break;
      case KrylovMethod::mumps:
        check(KSPSetType(ksp_, KSPPREONLY), "KSPSetType");
        check(PCSetType(pc, PCCHOLESKY), "PCSetType");
        check(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS), "PCFactorSetMatSolverType");
        break;
    }
    if (method_ != KrylovMethod::mumps)
      check(KSPSetNormType(ksp_, KSP_NORM_UNPRECONDITIONED), "KSPSetNormType");
    check(KSPSetFromOptions(ksp_), "KSPSetFromOptions");
  }

  // PETSc numbers the levels from the coarsest (0) to the finest (count): P_l interpolates into
  // level count + 1 − l. The coarse matrices are the Galerkin products Pᵀ A P; the coarsest is
  // factorized (Cholesky). The smoother of the others is Chebyshev (PETSc's default, two steps)
  // on block Jacobi with blocks of about kSmootherBlock consecutive unknowns, each factorized:
  // strips of control-point rows. With point smoothers (SOR) the CG iterations doubled with every
  // level on a thin shell; with these blocks they barely grow (docs/theory/solvers.md §4 has the
  // counts). PETSC_OPTIONS overrides any of it.
  void setup_multigrid(PC pc) {
    if (interpolations_.empty()) {
      // A model no larger than the coarsest level: that level's factorization is the solve.
      check(PCSetType(pc, PCCHOLESKY), "PCSetType");
      return;
    }
    const int count = static_cast<int>(interpolations_.size());
    check(PCSetType(pc, PCMG), "PCSetType");
    check(PCMGSetLevels(pc, count + 1, nullptr), "PCMGSetLevels");
    for (int l = 1; l <= count; ++l)
      check(
          PCMGSetInterpolation(pc, count + 1 - l, interpolations_[static_cast<std::size_t>(l - 1)]),
          "PCMGSetInterpolation");
    check(PCMGSetGalerkin(pc, PC_MG_GALERKIN_BOTH), "PCMGSetGalerkin");
    for (int l = 1; l <= count; ++l) {
      PetscInt n = 0;
      check(MatGetSize(interpolations_[static_cast<std::size_t>(l - 1)], &n, nullptr),
            "MatGetSize");
      KSP smoother = nullptr;
      check(PCMGGetSmoother(pc, count + 1 - l, &smoother), "PCMGGetSmoother");
      PC block = nullptr;
      check(KSPGetPC(smoother, &block), "KSPGetPC");
      check(PCSetType(block, PCBJACOBI), "PCSetType");
      check(PCBJacobiSetTotalBlocks(block, std::max<PetscInt>(1, n / kSmootherBlock), nullptr),
            "PCBJacobiSetTotalBlocks");
    }
    PetscBool user_sub = PETSC_FALSE;
    check(PetscOptionsHasName(nullptr, "isoflex_mg_levels_", "-sub_pc_type", &user_sub),
          "PetscOptionsHasName");
    if (!user_sub)
      check(PetscOptionsSetValue(nullptr, "-isoflex_mg_levels_sub_pc_type", "cholesky"),
            "PetscOptionsSetValue");
    KSP coarse = nullptr;
    check(PCMGGetCoarseSolve(pc, &coarse), "PCMGGetCoarseSolve");
    check(KSPSetType(coarse, KSPPREONLY), "KSPSetType");
    PC coarse_pc = nullptr;
    check(KSPGetPC(coarse, &coarse_pc), "KSPGetPC");
    check(PCSetType(coarse_pc, PCCHOLESKY), "PCSetType");
  }

  KrylovMethod method_;
  std::vector<Mat> interpolations_;
  Mat A_ = nullptr;
  KSP ksp_ = nullptr;
  MatNullSpace null_space_ = nullptr;
  const int* row_start_ = nullptr;
  const int* columns_ = nullptr;
  const double* values_ = nullptr;
  int n_ = -1;
};

}  // namespace

}  // namespace isoflex::solve

extern "C" isoflex::solve::KrylovBackend* isoflex_petsc_create(int method, std::string* error) {
  try {
    isoflex::solve::initialize();
    return new isoflex::solve::PetscKrylov(static_cast<isoflex::solve::KrylovMethod>(method));
  } catch (const std::exception& e) {
    if (error) *error = e.what();
    return nullptr;
  }
}
