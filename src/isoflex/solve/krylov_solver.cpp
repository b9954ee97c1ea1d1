#include "isoflex/solve/krylov_solver.hpp"

#include <Eigen/QR>
#include <stdexcept>

#include "isoflex/solve/petsc_module.hpp"

namespace isoflex::solve {

namespace {

using CreateFn = KrylovBackend* (*)(int, int, std::string*);

CreateFn load_module(std::string* tried) {
  return reinterpret_cast<CreateFn>(petsc_module_symbol("isoflex_petsc_create", tried));
}

}  // namespace

bool krylov_available(std::string* why) {
  std::string tried;
  if (load_module(&tried)) return true;
  if (why) *why = "cannot load the PETSc module (" + tried + ")";
  return false;
}

const char* krylov_method_name(KrylovMethod method) {
  switch (method) {
    case KrylovMethod::cg_gamg:
      return "cg_gamg";
    case KrylovMethod::cg_hypre:
      return "cg_hypre";
    case KrylovMethod::mumps:
      return "mumps";
    case KrylovMethod::cg_multigrid:
      return "cg_multigrid";
  }
  return "?";
}

MatX rigid_body_modes(const VecX& q, const std::vector<int>& points) {
  MatX modes = MatX::Zero(q.size(), 6);
  if (points.empty()) return modes;
  Vec3 c = Vec3::Zero();
  for (int o : points) c += q.segment<3>(o);
  c /= static_cast<double>(points.size());
  for (int o : points) {
    const Vec3 r = q.segment<3>(o) - c;
    for (int k = 0; k < 3; ++k) modes(o + k, k) = 1.0;
    // Rotation about axis k: e_k × r.
    modes.block<3, 1>(o, 3) = Vec3(0.0, -r.z(), r.y());
    modes.block<3, 1>(o, 4) = Vec3(r.z(), 0.0, -r.x());
    modes.block<3, 1>(o, 5) = Vec3(-r.y(), r.x(), 0.0);
  }
  return modes;
}

KrylovSolver::KrylovSolver(KrylovMethod method, bool distributed) : method_(method) {
  std::string tried;
  const CreateFn create = load_module(&tried);
  if (!create) throw std::runtime_error("cannot load the PETSc module (" + tried + ")");
  std::string error;
  backend_.reset(create(static_cast<int>(method), distributed ? 1 : 0, &error));
  if (!backend_) throw std::runtime_error("the PETSc module failed to start: " + error);
}

KrylovSolver::~KrylovSolver() = default;
KrylovSolver::KrylovSolver(KrylovSolver&&) noexcept = default;
KrylovSolver& KrylovSolver::operator=(KrylovSolver&&) noexcept = default;

void KrylovSolver::set_near_null_space(const MatX& modes) {
  if (modes.cols() == 0) return;
  // Orthonormal columns of the same span (PETSc's MatNullSpace requires them); a mode that the
  // others span (points on a line: the rotation about it) is dropped.
  Eigen::ColPivHouseholderQR<MatX> qr(modes);
  qr.setThreshold(1e-10);
  const Eigen::Index rank = qr.rank();
  MatX Q = qr.householderQ() * MatX::Identity(modes.rows(), rank);
  backend_->set_near_null_space(static_cast<int>(Q.rows()), static_cast<int>(rank), Q.data());
}

void KrylovSolver::set_interpolations(const std::vector<Eigen::SparseMatrix<double>>& P) {
  interpolations_.assign(P.begin(), P.end());
  std::vector<CsrView> views;
  for (auto& M : interpolations_) {
    M.makeCompressed();
    views.push_back({static_cast<int>(M.rows()), static_cast<int>(M.cols()), M.outerIndexPtr(),
                     M.innerIndexPtr(), M.valuePtr()});
  }
  backend_->set_interpolations(static_cast<int>(views.size()), views.data());
}

VecX KrylovSolver::solve(const Eigen::SparseMatrix<double>& A, bool new_pattern, const VecX& b,
                         double rtol, double atol, int max_iterations) {
  if (!A.isCompressed() || A.rows() != A.cols() || A.rows() != b.size())
    throw std::invalid_argument("KrylovSolver: A must be square, compressed and of b's size");
  const CsrView view{static_cast<int>(A.rows()), 0, A.outerIndexPtr(), A.innerIndexPtr(),
                     A.valuePtr()};
  VecX x = VecX::Zero(b.size());
  last_ = backend_->solve(view, new_pattern, b.data(), x.data(), rtol, atol, max_iterations);
  return x;
}

VecX KrylovSolver::solve_saddle_point(const Eigen::SparseMatrix<double>& A, bool new_pattern,
                                      bool new_values,
                                      const Eigen::SparseMatrix<double, Eigen::RowMajor>& B,
                                      const VecX& schur, const VecX& b, double rtol, double atol,
                                      int max_iterations) {
  if (!A.isCompressed() || !B.isCompressed() || A.rows() != A.cols() || B.cols() != A.rows() ||
      schur.size() != B.rows() || b.size() != A.rows() + B.rows())
    throw std::invalid_argument(
        "KrylovSolver: inconsistent saddle point (A square and compressed, B with A's columns)");
  const CsrView a{static_cast<int>(A.rows()), 0, A.outerIndexPtr(), A.innerIndexPtr(),
                  A.valuePtr()};
  const CsrView rows{static_cast<int>(B.rows()), static_cast<int>(B.cols()), B.outerIndexPtr(),
                     B.innerIndexPtr(), B.valuePtr()};
  VecX x = VecX::Zero(b.size());
  last_ = backend_->solve_saddle_point(a, new_pattern, new_values, rows, schur.data(), b.data(),
                                       x.data(), rtol, atol, max_iterations);
  return x;
}

}  // namespace isoflex::solve
