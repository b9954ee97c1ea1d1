// The load contract (loads/load.hpp) over every load kind: a body load (global components or, a
// follower, in the director frame), a director-node load and a Kirchhoff–Love patch's loads
// (PatchLoadSet), a spring's actuator (LineActuator). For each: the tangent given in its own
// pattern against central differences of generalized_force (followers), no dependence on x and no
// tangent (dead loads), and the pattern's size.
#include <gtest/gtest.h>

#include <array>
#include <memory>
#include <optional>
#include <random>
#include <string>

#include "isoflex/geometry/builders.hpp"
#include "isoflex/loads/body_load.hpp"
#include "isoflex/loads/director_node_load.hpp"
#include "isoflex/loads/follower_body_load.hpp"
#include "isoflex/loads/line_actuator.hpp"
#include "isoflex/loads/patch_load_set.hpp"
#include "support/finite_difference.hpp"

using namespace isoflex;
using namespace isoflex::loads;
using isoflex::test::central_jacobian;
using isoflex::test::random_vector;
using isoflex::test::rel_diff;

namespace {

using Fn3 = std::array<TimeFunction, 3>;

Fn3 fn3(const std::string& a, const std::string& b, const std::string& c) {
  return {TimeFunction(a), TimeFunction(b), TimeFunction(c)};
}

// A load of each kind, dead and follower, with a configuration x of its size.
struct Case {
  std::string name;
  std::shared_ptr<const Load> load;
  int size;
  bool follower;
};

std::vector<Case> cases() {
  std::vector<Case> out;
  const Vec3 X(0.3, -0.2, 0.5);
  out.push_back({"body force",
                 std::make_shared<BodyLoad>(4, X, fn3("1+t", "-2*t", "3"), std::nullopt), 12,
                 false});
  out.push_back({"body force and moment",
                 std::make_shared<BodyLoad>(4, X, fn3("1", "2", "t"), fn3("0.5", "-1+t", "2*t")),
                 12, true});
  out.push_back({"director force",
                 std::make_shared<DirectorNodeLoad>(2, fn3("1", "t", "0"), std::nullopt), 6,
                 false});
  out.push_back({"director force and moment",
                 std::make_shared<DirectorNodeLoad>(2, fn3("1", "t", "0"), fn3("2", "-1", "3*t")),
                 6, true});
  // A 2 × 2-span quadratic patch (16 control points): dead pressure, then a follower pressure
  // and a line load on it; the follower's tangent in a dense pattern.
  static const geometry::NurbsSurface s = [] {
    geometry::NurbsSurface p = geometry::cylinder_sector(2.0, 3.0, 1.0);
    return p;
  }();
  const int ncp = static_cast<int>(s.points.size());
  std::vector<int> nodes(static_cast<std::size_t>(ncp));
  for (int a = 0; a < ncp; ++a) nodes[static_cast<std::size_t>(a)] = 10 + a;
  PatchLoads dead{std::make_shared<DeadPressure>(s, 2.5, TimeFunction(std::string("2*t")))};
  out.push_back({"patch dead pressure", std::make_shared<PatchLoadSet>(nodes, dead, Load::SpMat()),
                 3 * ncp, false});
  PatchLoads follower{
      std::make_shared<DeadPressure>(s, 1.0),
      std::make_shared<FollowerPressure>(s, -3.0, TimeFunction(std::string("1+t")))};
  out.push_back(
      {"patch follower pressure",
       std::make_shared<PatchLoadSet>(nodes, follower, MatX::Ones(3 * ncp, 3 * ncp).sparseView()),
       3 * ncp, true});
  // A force at X and a moment with components in the director frame (follower).
  out.push_back(
      {"follower body force and moment",
       std::make_shared<FollowerBodyLoad>(4, X, fn3("1", "2", "t"), fn3("0.5", "-1+t", "2*t")), 12,
       true});
  // An actuator from a body point (frame node, body coordinates X) to a point node, F = 2 + t.
  Eigen::Matrix<double, 3, Eigen::Dynamic> D =
      Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, 15);
  D.middleCols<3>(0) = Mat3::Identity();
  for (int i = 0; i < 3; ++i) D.middleCols<3>(3 + 3 * i) = X(i) * Mat3::Identity();
  D.middleCols<3>(12) = -Mat3::Identity();
  out.push_back({"line actuator",
                 std::make_shared<LineActuator>(std::vector<int>{3, 8}, D, Vec3::Zero(),
                                                TimeFunction(std::string("2+t")), VecX::Ones(15)),
                 15, true});
  return out;
}

MatX dense_tangent(const Load& L, const VecX& x, double t, double scale) {
  const Load::SpMat P = L.tangent_pattern(static_cast<int>(x.size()));
  std::vector<double> values(static_cast<std::size_t>(P.nonZeros()), 0.0);
  L.add_tangent(x, t, scale, values.data());
  MatX K = MatX::Zero(x.size(), x.size());
  for (int c = 0, k = 0; c < P.outerSize(); ++c)
    for (Load::SpMat::InnerIterator it(P, c); it; ++it, ++k) K(it.row(), c) = values[k];
  return K;
}

}  // namespace

TEST(LoadContract, FollowerTangentsMatchCentralDifferences) {
  std::mt19937 g(7);
  for (const Case& c : cases()) {
    SCOPED_TRACE(c.name);
    ASSERT_EQ(c.load->follower(), c.follower);
    const VecX x = random_vector(g, c.size, 2.0);
    const double t = 0.7;
    const VecX f = c.load->generalized_force(x, t);
    ASSERT_EQ(f.size(), c.size);
    EXPECT_GT(f.norm(), 0.0);
    const MatX fd =
        central_jacobian([&](const VecX& y) { return c.load->generalized_force(y, t); }, x);
    if (!c.follower) {
      EXPECT_LT(fd.norm(), 1e-9 * f.norm()) << "a dead load does not depend on x";
      continue;
    }
    EXPECT_GT(fd.norm(), 1e-3 * f.norm());
    // add_tangent adds scale ∂f/∂x to what the values hold.
    const MatX K = dense_tangent(*c.load, x, t, -0.5);
    EXPECT_LT(rel_diff(K, -0.5 * fd), 1e-7);
  }
}

TEST(LoadContract, TheNodesAreTheLoadsNodesAndTheTimeFunctionsApply) {
  const auto all = cases();
  EXPECT_EQ(all[0].load->nodes(), std::vector<int>{4});
  EXPECT_EQ(all[2].load->nodes(), std::vector<int>{2});
  EXPECT_EQ(all[4].load->nodes().size() * 3, static_cast<std::size_t>(all[4].size));
  // Body force (1 + t, −2t, 3) at t = 2 on φ: the first three entries.
  const VecX f = all[0].load->generalized_force(VecX::Zero(12), 2.0);
  EXPECT_EQ(f.head<3>(), Vec3(3.0, -4.0, 3.0));
  // The patch's dead pressure scales with its factor 2t.
  const VecX x = VecX::Random(all[4].size);
  EXPECT_LT((all[4].load->generalized_force(x, 1.5) - 3.0 * all[4].load->generalized_force(x, 0.5))
                .norm(),
            1e-13 * all[4].load->generalized_force(x, 1.5).norm());
}

// The actuator is a pair of opposite forces F(t) on the line of its points: the force on the
// frame node's φ and the one on the point node cancel, their moments about the origin too, and
// it pulls the points together (tension > 0) with magnitude F.
TEST(LoadContract, TheActuatorIsAPairOfForcesOnItsLine) {
  const Case c = cases().back();
  std::mt19937 g(3);
  const VecX x = random_vector(g, 15, 1.0);
  const double t = 0.5;
  const VecX f = c.load->generalized_force(x, t);
  const Vec3 X(0.3, -0.2, 0.5);
  const Vec3 xa =
      x.segment<3>(0) + X(0) * x.segment<3>(3) + X(1) * x.segment<3>(6) + X(2) * x.segment<3>(9);
  const Vec3 xb = x.segment<3>(12);
  const Vec3 n = (xa - xb).normalized();
  EXPECT_LT((f.segment<3>(0) + 2.5 * n).norm(), 1e-14);  // on a: −F n, towards b
  EXPECT_LT((f.segment<3>(12) - 2.5 * n).norm(), 1e-14);
  Vec3 moment = Vec3::Zero();
  for (int b = 0; b < 5; ++b) moment += x.segment<3>(3 * b).cross(f.segment<3>(3 * b));
  EXPECT_LT((f.segment<3>(0) + f.segment<3>(12)).norm(), 1e-14);
  EXPECT_LT(moment.norm(), 1e-13);
}
