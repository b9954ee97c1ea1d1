#include <gtest/gtest.h>

#include "isoflex/math/director_node.hpp"
#include "support/finite_difference.hpp"

using namespace isoflex;
using namespace isoflex::test;
namespace dn = isoflex::director_node;

namespace {
dn::Q random_director_q(std::mt19937& g) {
  dn::Q q;
  q << random_vector(g, 3), random_vector(g, 3).normalized();
  return q;
}
}  // namespace

TEST(DirectorNode, NullSpacesAnnihilateJacobian) {
  std::mt19937 g(6);
  for (int k = 0; k < 20; ++k) {
    const dn::Q qn = random_director_q(g), qn1 = random_director_q(g);
    const auto B = dn::tangent_basis(qn.tail<3>());
    EXPECT_LT((dn::jacobian(qn) * dn::null_space(B)).norm(), 1e-14);
    // Discrete version (49)–(50): 𝖦 = G(q_{n+½}).
    const dn::Q qm = 0.5 * (qn + qn1);
    EXPECT_LT((dn::jacobian(qm) * dn::discrete_null_space(qn, B, qn1)).norm(), 1e-13);
    // 𝖯 → P as q_{n+1} → q_n (Remark 2.2).
    EXPECT_LT((dn::discrete_null_space(qn, B, qn) - dn::null_space(B)).norm(), 1e-14);
  }
}

TEST(DirectorNode, UpdateKeepsUnitLengthAndHasExactDerivative) {
  std::mt19937 g(7);
  for (double scale : {1.0, 1e-5}) {
    const dn::Q qn = random_director_q(g);
    const auto B = dn::tangent_basis(qn.tail<3>());
    const VecX u = random_vector(g, 5, scale);
    EXPECT_LT(std::abs(dn::constraint(dn::update(qn, B, u))), 1e-15);
    auto f = [&](const VecX& x) -> VecX { return dn::update(qn, B, x); };
    EXPECT_LT(rel_diff(dn::update_derivative(qn, B, u), central_jacobian(f, u)), 1e-8);
  }
}

#include "isoflex/math/point_node.hpp"

TEST(PointNode, UpdateIsTranslationWithIdentityNullSpace) {
  const Vec3 q(1, 2, 3), u(0.5, -1, 2);
  EXPECT_EQ(point_node::update(q, u), q + u);
  EXPECT_EQ(point_node::null_space(q), Mat3::Identity());
  EXPECT_EQ(point_node::update_derivative(q, u), Mat3::Identity());
}

// The system's twist form (68): G(q) P(q) = 0 on all of R⁶; at the midpoint its director columns
// span the same plane as those of (49)–(50), and equal them times dₙ·d_{n+½}.
TEST(DirectorNode, TwistFormIsThePapersDiscreteNullSpace) {
  std::mt19937 g(8);
  for (int k = 0; k < 20; ++k) {
    const VecX q = random_vector(g, 6, 2.0);
    EXPECT_LT((dn::jacobian(q) * dn::twist_null_space(q)).norm(), 1e-14);
    const dn::Q qn = random_director_q(g);
    const dn::Q qn1 = dn::root_update(qn, random_vector(g, 5, 0.3), nullptr);
    const dn::Q qm = 0.5 * (qn + qn1);
    const Mat<6, 5> P = dn::twist_null_space(qm) * dn::root_block(qn);
    const Mat<6, 5> Ppaper = dn::discrete_null_space(qn, dn::tangent_basis(qn.tail<3>()), qn1);
    const double s = qn.tail<3>().dot(qm.tail<3>());
    EXPECT_LT((P.leftCols<3>() - Ppaper.leftCols<3>()).norm(), 1e-15);
    EXPECT_LT((P.rightCols<2>() - s * Ppaper.rightCols<2>()).norm(), 1e-14);
  }
}

TEST(DirectorNode, RootUpdateIsThePapersMapWithExactTwistDerivative) {
  std::mt19937 g(9);
  for (double scale : {1.0, 1e-6}) {
    const dn::Q qn = random_director_q(g);
    const VecX u = random_vector(g, 5, scale);
    Mat3 step;
    const dn::Q q1 = dn::root_update(qn, u, &step);
    EXPECT_LT((q1 - dn::update(qn, dn::tangent_basis(qn.tail<3>()), u)).norm(), 1e-15);
    EXPECT_LT((step * qn.tail<3>() - q1.tail<3>()).norm(), 1e-15);
    auto f = [&](const VecX& x) -> VecX { return dn::root_update(qn, x, nullptr); };
    const MatX D = dn::twist_null_space(q1) * dn::root_update_block(qn, u);
    EXPECT_LT(rel_diff(D, central_jacobian(f, u)), 1e-8);
  }
}
