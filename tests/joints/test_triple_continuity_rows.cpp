// AF-D rows (joints/triple_continuity_rows.hpp, IGA-thesis (5.36)–(5.37)) through the constraint
// contract, on one straight and two kinked triples: zero at the reference; Jacobian and Hessian
// against central differences off the manifold; the discrete derivative's property
// G̃ (q_b − q_a) = Φ(q_b) − Φ(q_a) to round-off and G̃ → G; rigid motions: the angle rows are
// invariant and their (discrete) derivative annihilates the rigid velocities at the midpoint.
#include <gtest/gtest.h>

#include <random>

#include "isoflex/joints/triple_continuity_rows.hpp"
#include "isoflex/math/skew.hpp"
#include "support/finite_difference.hpp"

using namespace isoflex;
using namespace isoflex::test;
using joints::TripleContinuityRows;

namespace {

// Triple 0 straight (legs 1 and 0.5 along x), triples 1 and 2 kinked (90° and 30°).
VecX reference() {
  VecX X(27);
  X << 0, 0, 0, 1, 0, 0, 1.5, 0, 0,  //
      0, 1, 0, 1, 1, 0, 1, 1, 2,     //
      0, 2, 0, 1, 2, 0, 1 + std::cos(M_PI / 6), 2, 0.5 * std::sin(M_PI / 6);
  return X;
}

TripleContinuityRows rows() {
  std::vector<int> nodes(9);
  for (int i = 0; i < 9; ++i) nodes[static_cast<std::size_t>(i)] = 10 + i;
  return TripleContinuityRows(nodes, reference(), 3.0);
}

// The rigid velocities at q: translations and rotations about the origin, 27 × 6.
MatX rigid_velocities(const VecX& q) {
  MatX P(q.size(), 6);
  for (int a = 0; a < q.size() / 3; ++a) {
    P.block<3, 3>(3 * a, 0) = Mat3::Identity();
    P.block<3, 3>(3 * a, 3) = -skew(Vec3(q.segment<3>(3 * a)));
  }
  return P;
}

}  // namespace

TEST(TripleContinuityRows, RowsPerTripleAndZeroAtTheReference) {
  const TripleContinuityRows C = rows();
  EXPECT_EQ(C.constraint_count(), 3 + 1 + 1);
  EXPECT_EQ(C.kinks(), 2);
  EXPECT_LT(C.constraints(reference()).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_THROW(TripleContinuityRows({1, 2}, VecX::Zero(6)), std::invalid_argument);
  EXPECT_THROW(TripleContinuityRows({1, 2, 3}, VecX::Zero(9)), std::invalid_argument);
}

TEST(TripleContinuityRows, JacobianAndHessianMatchCentralDifferences) {
  std::mt19937 g(7);
  const TripleContinuityRows C = rows();
  const VecX q = reference() + random_vector(g, 27, 0.2);
  const MatX G = C.jacobian(q);
  EXPECT_LT(rel_diff(G, central_jacobian([&](const VecX& y) { return C.constraints(y); }, q)),
            1e-8);
  const VecX lambda = random_vector(g, C.constraint_count());
  MatX H = MatX::Zero(27, 27);
  C.add_constraint_hessian(q, lambda, H);
  const MatX H_fd =
      central_jacobian([&](const VecX& y) { return VecX(C.jacobian(y).transpose() * lambda); }, q);
  EXPECT_GT(H_fd.norm(), 1e-2);  // the kinked rows are not linear
  EXPECT_LT(rel_diff(H, H_fd), 1e-7);
  EXPECT_LT((H - H.transpose()).norm(), 1e-14 * H.norm());
}

TEST(TripleContinuityRows, DiscreteDerivativeIsExactAndConsistent) {
  std::mt19937 g(11);
  const TripleContinuityRows C = rows();
  for (double size : {1e-6, 1e-2, 0.3, 1.0}) {
    const VecX qa = reference() + random_vector(g, 27, 0.1);
    const VecX qb = qa + random_vector(g, 27, size);
    const VecX dphi = C.constraints(qb) - C.constraints(qa);
    const VecX Gdq = C.discrete_jacobian(qa, qb) * (qb - qa);
    EXPECT_LT((Gdq - dphi).cwiseAbs().maxCoeff(), 1e-14 * std::max(1.0, dphi.norm()))
        << "step " << size;
    if (size == 1e-6) {
      EXPECT_LT(rel_diff(C.discrete_jacobian(qa, qb), C.jacobian(0.5 * (qa + qb))), 1e-11);
    }
  }
  const VecX q = reference() + random_vector(g, 27, 0.1);
  EXPECT_LT(rel_diff(C.discrete_jacobian(q, q), C.jacobian(q)), 1e-15);
}

TEST(TripleContinuityRows, AngleRowsAreInvariantUnderRigidMotions) {
  std::mt19937 g(5);
  const TripleContinuityRows C = rows();
  const VecX qa = reference() + random_vector(g, 27, 0.1);
  const VecX qb = qa + random_vector(g, 27, 0.2);
  const Mat3 R = random_rotation(g);
  const Vec3 c = random_vector(g, 3);
  VecX moved(27);
  for (int a = 0; a < 9; ++a) moved.segment<3>(3 * a) = R * qa.segment<3>(3 * a) + c;
  EXPECT_LT((C.constraints(moved) - C.constraints(qa)).tail(2).cwiseAbs().maxCoeff(), 1e-13);
  // The kinked rows (3, 4): G P = 0 at q and G̃ P(q_{½}) = 0.
  const MatX GP = C.jacobian(qa).bottomRows(2) * rigid_velocities(qa);
  const MatX GdP = C.discrete_jacobian(qa, qb).bottomRows(2) * rigid_velocities(0.5 * (qa + qb));
  EXPECT_LT(GP.cwiseAbs().maxCoeff(), 1e-14 * C.jacobian(qa).norm());
  EXPECT_LT(GdP.cwiseAbs().maxCoeff(), 1e-14 * C.jacobian(qa).norm());
  // The straight rows a = c b are rotated with the pair (translation invariant).
  for (int a = 0; a < 9; ++a) moved.segment<3>(3 * a) = qa.segment<3>(3 * a) + c;
  EXPECT_LT((C.constraints(moved) - C.constraints(qa)).head(3).cwiseAbs().maxCoeff(), 1e-13);
}
