#include <gtest/gtest.h>

#include "isoflex/math/rotation.hpp"
#include "isoflex/math/skew.hpp"
#include "support/finite_difference.hpp"

using namespace isoflex;
using namespace isoflex::test;

TEST(Rodrigues, IsOrthogonalWithUnitDeterminant) {
  std::mt19937 g(1);
  for (int k = 0; k < 50; ++k) {
    const Mat3 R = rodrigues(random_vector(g, 3, 4.0));
    EXPECT_LT((R.transpose() * R - Mat3::Identity()).norm(), 1e-14);
    EXPECT_NEAR(R.determinant(), 1.0, 1e-14);
  }
}

TEST(Rodrigues, RotatesAboutItsAxisByItsNorm) {
  const Vec3 th(0.0, 0.0, 0.3);
  const Vec3 x = rodrigues(th) * Vec3::UnitX();
  EXPECT_NEAR(x.x(), std::cos(0.3), 1e-15);
  EXPECT_NEAR(x.y(), std::sin(0.3), 1e-15);
  EXPECT_LT((rodrigues(Vec3(1e-9, 0, 0)) - Mat3::Identity() - skew(Vec3(1e-9, 0, 0))).norm(),
            1e-17);
}

// (exp(θ̂) − I) v to the precision of its own size: against the series of exp(θ̂) v − v in long
// double (θ ⊥ v, |θ| ≤ 10⁻², 15 terms), where rodrigues(θ) v − v keeps only ε|v| absolute; the
// rotation from the same factors is rodrigues(θ)'s, bit for bit.
TEST(Rodrigues, IncrementIsAccurateWhereTheRotatedVectorLessItIsNot) {
  std::mt19937 g(3);
  for (double scale : {1e-2, 1e-5, 1e-9}) {
    const Vec3 v = random_vector(g, 3);
    const Vec3 th = Vec3(random_vector(g, 3)).cross(v).normalized() * scale;
    using LVec = Eigen::Matrix<long double, 3, 1>;
    const LVec tl = th.cast<long double>(), vl = v.cast<long double>();
    LVec term = vl, sum = LVec::Zero();
    for (int k = 1; k <= 15; ++k) {
      term = tl.cross(term) / static_cast<long double>(k);
      sum += term;
    }
    const Vec3 exact = sum.cast<double>();
    Mat3 A;
    const Mat3 R = rodrigues(th, A);
    EXPECT_LT((A * v - exact).norm(), 4e-16 * exact.norm()) << "scale " << scale;
    EXPECT_LT((A * v - (R * v - v)).norm(), 4e-16 * v.norm());
    EXPECT_TRUE(R == rodrigues(th));
  }
}

// δ(exp(θ̂) v) = (T(θ) δθ) × exp(θ̂) v, checked against central differences, also for small |θ|
// where the series branches are taken.
TEST(Rodrigues, TangentMatchesFiniteDifferences) {
  std::mt19937 g(2);
  for (double scale : {2.0, 1e-2, 5e-4, 1e-6}) {
    const VecX th = random_vector(g, 3, scale);
    const Vec3 v = random_vector(g, 3);
    auto f = [&](const VecX& t) -> VecX { return rodrigues(t) * v; };
    const MatX J = central_jacobian(f, th);
    const MatX Ja = -skew(rodrigues(th) * v) * rodrigues_tangent(th);
    EXPECT_LT(rel_diff(Ja, J), 1e-8) << "scale " << scale;
  }
}
