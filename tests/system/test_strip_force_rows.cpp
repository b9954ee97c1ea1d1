// AF-BS rows of a nonlinear analysis (system/strip_force_rows.hpp, IGA-thesis (5.5b)) through the
// constraint contract, on a strip over three triples bent at 90°: zero at the reference, the
// Jacobian (the strip's tangent) against central differences of the rows, the Hessian term
// (a central difference of the tangent) against central differences of Gᵀλ, and the rows move
// with a rigid motion as forces do (unchanged by a translation, turned by a rotation).
#include <gtest/gtest.h>

#include <random>

#include "isoflex/elements/bending_strip.hpp"
#include "isoflex/system/strip_force_rows.hpp"
#include "support/finite_difference.hpp"

using namespace isoflex;
using namespace isoflex::test;

namespace {

struct Strip {
  system::StripForceRows rows;
  VecX X;
};

Strip strip() {
  std::vector<std::array<Vec3, 3>> T;
  VecX X(27);
  for (int k = 0; k < 3; ++k) {
    const double x = 0.5 * k;
    T.push_back({Vec3(x, 0.3, 0), Vec3(x, 0, 0), Vec3(x, 0, -0.4)});
    for (int i = 0; i < 3; ++i) X.segment<3>(9 * k + 3 * i) = T.back()[static_cast<std::size_t>(i)];
  }
  std::vector<int> nodes(9);
  for (int i = 0; i < 9; ++i) nodes[static_cast<std::size_t>(i)] = i;
  return {system::StripForceRows(elements::bending_strip(T, 1e3, 0.05), nodes, 2.0), X};
}

}  // namespace

TEST(StripForceRows, ZeroAtTheReferenceWithTheStripTangentAndItsDerivative) {
  std::mt19937 g(3);
  const Strip s = strip();
  const auto& C = s.rows;
  EXPECT_EQ(C.constraint_count(), 27);
  EXPECT_TRUE(C.reselected());
  EXPECT_LT(C.constraints(s.X).cwiseAbs().maxCoeff(), 1e-12);
  const VecX q = s.X + random_vector(g, 27, 0.05);
  const MatX G = C.jacobian(q);
  EXPECT_GT(C.constraints(q).norm(), 1e-3);
  EXPECT_LT(rel_diff(G, central_jacobian([&](const VecX& y) { return C.constraints(y); }, q)),
            1e-7);
  const VecX lambda = random_vector(g, 27);
  MatX H = MatX::Zero(27, 27);
  C.add_constraint_hessian(q, lambda, H);
  const MatX H_fd =
      central_jacobian([&](const VecX& y) { return VecX(C.jacobian(y).transpose() * lambda); }, q);
  EXPECT_GT(H_fd.norm(), 1e-3 * G.norm());
  EXPECT_LT(rel_diff(H, H_fd), 1e-6);
}

TEST(StripForceRows, RowsAreForcesUnderRigidMotions) {
  std::mt19937 g(5);
  const Strip s = strip();
  const VecX q = s.X + random_vector(g, 27, 0.05);
  const Mat3 R = random_rotation(g);
  const Vec3 c = random_vector(g, 3);
  VecX moved(27), shifted(27);
  for (int a = 0; a < 9; ++a) {
    moved.segment<3>(3 * a) = R * q.segment<3>(3 * a) + c;
    shifted.segment<3>(3 * a) = q.segment<3>(3 * a) + c;
  }
  const VecX f = s.rows.constraints(q), fm = s.rows.constraints(moved);
  VecX turned(27);
  for (int a = 0; a < 9; ++a) turned.segment<3>(3 * a) = R * f.segment<3>(3 * a);
  EXPECT_LT((fm - turned).norm(), 1e-9 * f.norm());
  EXPECT_LT((s.rows.constraints(shifted) - f).norm(), 1e-9 * f.norm());
}
