// The PETSc solvers (solve/krylov_solver.hpp, docs/theory/solvers.md §3) against CHOLMOD, on the
// stiffness of a 3D network of axial springs: the rigid-body modes are its exact null space, and
// held by ground springs at one face it is a positive definite elasticity-like matrix.
#include <gtest/gtest.h>

#include <random>
#include <stdexcept>

#include "isoflex/solve/krylov_solver.hpp"
#include "isoflex/solve/linear_solver.hpp"
#include "support/petsc.hpp"

using namespace isoflex;
using solve::KrylovMethod;
using solve::SpMat;

namespace {

struct Network {
  VecX q;                   // positions, 3 per point
  std::vector<int> points;  // their offsets
  SpMat K;
};

// Points on an nx × ny × nz grid (spacing 1, each moved by up to 0.2 at random so that no three
// are aligned), joined to every neighbour within the unit cube around it (axes, face and body
// diagonals) by springs of stiffness k n nᵀ; `ground` > 0: the points at x = 0 held by springs of
// that stiffness in all three directions.
Network spring_network(int nx, int ny, int nz, double ground) {
  std::mt19937 g(7);
  std::uniform_real_distribution<double> jitter(-0.2, 0.2);
  Network net;
  const int count = nx * ny * nz;
  net.q.resize(3 * count);
  const auto id = [&](int i, int j, int k) { return i + nx * (j + ny * k); };
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const int p = id(i, j, k);
        net.q.segment<3>(3 * p) = Vec3(i + jitter(g), j + jitter(g), k + jitter(g));
        net.points.push_back(3 * p);
      }
  std::vector<Eigen::Triplet<double>> t;
  const auto block = [&](int a, int b, const Mat3& B) {
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) t.emplace_back(3 * a + r, 3 * b + c, B(r, c));
  };
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        for (int dk = 0; dk <= 1; ++dk)
          for (int dj = -1; dj <= 1; ++dj)
            for (int di = -1; di <= 1; ++di) {
              if (dk == 0 && (dj < 0 || (dj == 0 && di <= 0))) continue;  // each pair once
              const int i2 = i + di, j2 = j + dj, k2 = k + dk;
              if (i2 < 0 || i2 >= nx || j2 < 0 || j2 >= ny || k2 >= nz) continue;
              const int a = id(i, j, k), b = id(i2, j2, k2);
              const Vec3 d = net.q.segment<3>(3 * b) - net.q.segment<3>(3 * a);
              const Mat3 B = 100.0 * d * d.transpose() / d.squaredNorm();
              block(a, a, B);
              block(b, b, B);
              block(a, b, -B);
              block(b, a, -B);
            }
  if (ground > 0.0)
    for (int k = 0; k < nz; ++k)
      for (int j = 0; j < ny; ++j) block(id(0, j, k), id(0, j, k), ground * Mat3::Identity());
  net.K.resize(3 * count, 3 * count);
  net.K.setFromTriplets(t.begin(), t.end());
  net.K.makeCompressed();
  return net;
}

VecX random_load(int n) {
  std::mt19937 g(11);
  std::normal_distribution<double> d;
  VecX b(n);
  for (int i = 0; i < n; ++i) b(i) = d(g);
  return b;
}

}  // namespace

TEST(RigidBodyModes, AreTheNullSpaceOfAFreeSpringNetwork) {
  const Network net = spring_network(4, 3, 3, 0.0);
  const MatX modes = solve::rigid_body_modes(net.q, net.points);
  ASSERT_EQ(modes.cols(), 6);
  EXPECT_EQ(Eigen::FullPivLU<MatX>(modes).rank(), 6);
  const double residual = (net.K * modes).cwiseAbs().maxCoeff();
  const double size = MatX(net.K).cwiseAbs().maxCoeff() * modes.cwiseAbs().maxCoeff();
  std::printf("max |K modes| = %.2e of %.2e\n", residual, size);
  EXPECT_LT(residual, 1e-13 * size);
}

TEST(RigidBodyModes, AreZeroOutsideThePoints) {
  VecX q = VecX::Zero(10);
  q.segment<3>(2) = Vec3(1, 2, 3);
  q.segment<3>(6) = Vec3(-1, 0, 5);
  const MatX modes = solve::rigid_body_modes(q, {2, 6});
  for (int i : {0, 1, 5, 9}) EXPECT_EQ(modes.row(i).norm(), 0.0) << "entry " << i;
  // The rotation about z moves point 2 by e_z × (r − c).
  const Vec3 c = (Vec3(1, 2, 3) + Vec3(-1, 0, 5)) / 2;
  EXPECT_LT((modes.block<3, 1>(2, 5) - Vec3::UnitZ().cross(Vec3(1, 2, 3) - c)).norm(), 1e-15);
}

// Each PETSc method solves the held network as CHOLMOD does (tolerance 10⁻¹², so that the
// solutions agree to the condition number times that).
TEST(KrylovSolver, EachMethodSolvesAsCholeskyDoes) {
  ISOFLEX_REQUIRE_PETSC();
  const Network net = spring_network(10, 6, 4, 50.0);
  const VecX b = random_load(static_cast<int>(net.K.rows()));
  solve::FixedPatternCholesky cholesky;
  const VecX expected = cholesky.solve(net.K, b);
  for (KrylovMethod method : {KrylovMethod::cg_gamg, KrylovMethod::cg_hypre, KrylovMethod::mumps}) {
    solve::KrylovSolver solver(method);
    solver.set_near_null_space(solve::rigid_body_modes(net.q, net.points));
    const VecX x = solver.solve(net.K, true, b, 1e-12, 0.0);
    const double error = (x - expected).norm() / expected.norm();
    std::printf("%-8s %3d iterations, relative difference %.2e (%s)\n",
                solve::krylov_method_name(method), solver.last().iterations, error,
                solver.last().reason.c_str());
    EXPECT_LT(error, 1e-8) << solve::krylov_method_name(method);
    EXPECT_LE((b - net.K * x).norm(), 1.01e-12 * b.norm() + 1e-12 * net.K.norm() * x.norm())
        << solve::krylov_method_name(method);
    if (method == KrylovMethod::mumps)
      EXPECT_EQ(solver.last().iterations, 0);
    else
      EXPECT_GT(solver.last().iterations, 0);
  }
}

// The tolerance is max(rtol ‖b‖₂, atol): a loose one stops earlier and is still met.
TEST(KrylovSolver, StopsAtTheToleranceItIsGiven) {
  ISOFLEX_REQUIRE_PETSC();
  const Network net = spring_network(10, 6, 4, 50.0);
  const VecX b = random_load(static_cast<int>(net.K.rows()));
  solve::KrylovSolver solver(KrylovMethod::cg_gamg);
  solver.set_near_null_space(solve::rigid_body_modes(net.q, net.points));
  const VecX tight = solver.solve(net.K, true, b, 1e-12, 0.0);
  const int tight_iterations = solver.last().iterations;
  const VecX loose = solver.solve(net.K, false, b, 1e-3, 0.0);
  EXPECT_LT(solver.last().iterations, tight_iterations);
  EXPECT_LE((b - net.K * loose).norm(), 1e-3 * b.norm());
  const double atol = 1e-4 * b.norm();
  const VecX absolute = solver.solve(net.K, false, b, 0.0, atol);
  EXPECT_LE((b - net.K * absolute).norm(), atol);
}

// A two-level interpolation for the network (cg_multigrid): coarse point c is fine points 2c and
// 2c + 1, component by component.
static SpMat pair_interpolation(const Network& net) {
  const int points = static_cast<int>(net.points.size());
  SpMat P(3 * points, 3 * ((points + 1) / 2));
  for (int p = 0; p < points; ++p)
    for (int r = 0; r < 3; ++r) P.insert(3 * p + r, 3 * (p / 2) + r) = 1.0;
  P.makeCompressed();
  return P;
}

// Newton's matrices change their values in the same arrays: the solver must see the new ones
// (the multigrid hierarchy recomputed on them; cg_multigrid's products by its own copy of the
// upper triangle, refreshed), and a new pattern when it is told of one.
TEST(KrylovSolver, SeesNewValuesInTheSameArraysAndANewPattern) {
  ISOFLEX_REQUIRE_PETSC();
  Network net = spring_network(8, 5, 3, 50.0);
  const VecX b = random_load(static_cast<int>(net.K.rows()));
  for (KrylovMethod method :
       {KrylovMethod::cg_gamg, KrylovMethod::mumps, KrylovMethod::cg_multigrid}) {
    SpMat K = net.K;
    solve::KrylovSolver solver(method);
    solver.set_near_null_space(solve::rigid_body_modes(net.q, net.points));
    if (method == KrylovMethod::cg_multigrid) solver.set_interpolations({pair_interpolation(net)});
    const VecX x1 = solver.solve(K, true, b, 1e-12, 0.0);
    // Twice as stiff, and more so along the diagonal: a different matrix in the same arrays.
    for (int k = 0; k < K.nonZeros(); ++k) K.valuePtr()[k] *= 2.0;
    K.diagonal().array() += 30.0;
    const VecX x2 = solver.solve(K, false, b, 1e-12, 0.0);
    solve::FixedPatternCholesky cholesky;
    const VecX expected = cholesky.solve(K, b);
    EXPECT_LT((x2 - expected).norm(), 1e-8 * expected.norm()) << solve::krylov_method_name(method);
    EXPECT_GT((x2 - x1).norm(), 0.1 * x1.norm());
    const Network other = spring_network(6, 5, 3, 20.0);
    const VecX b2 = random_load(static_cast<int>(other.K.rows()));
    if (method == KrylovMethod::cg_multigrid)
      solver.set_interpolations({pair_interpolation(other)});
    const VecX x3 = solver.solve(other.K, true, b2, 1e-12, 0.0);
    const VecX expected3 = cholesky.solve(other.K, b2);
    EXPECT_LT((x3 - expected3).norm(), 1e-8 * expected3.norm())
        << solve::krylov_method_name(method);
  }
}

// A solve that does not reach its tolerance throws (the static solver then falls back to the
// direct solvers), with PETSc's reason.
TEST(KrylovSolver, ThrowsWhenItDoesNotConverge) {
  ISOFLEX_REQUIRE_PETSC();
  const Network net = spring_network(10, 6, 4, 50.0);
  const VecX b = random_load(static_cast<int>(net.K.rows()));
  solve::KrylovSolver solver(KrylovMethod::cg_gamg);
  try {
    solver.solve(net.K, true, b, 1e-14, 0.0, 2);
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("DIVERGED_ITS"), std::string::npos) << e.what();
  }
}
