// FollowerBodyLoad (loads/follower_body_load.hpp): a force at a body point and a moment with
// components in the director frame. Its generalized force is BodyLoad's with F = F_J d_J and
// M = M_J d_J, it does virtual work F·ẋ + M·ω on the manifold, and its tangent (which, unlike
// BodyLoad's, depends on q) matches central differences.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <random>
#include <string>

#include "isoflex/loads/body_load.hpp"
#include "isoflex/loads/follower_body_load.hpp"
#include "isoflex/math/frame_node.hpp"
#include "support/finite_difference.hpp"

using namespace isoflex;
using namespace isoflex::test;

namespace {
std::array<loads::TimeFunction, 3> vec(const std::string& x, const std::string& y,
                                       const std::string& z) {
  return {loads::TimeFunction(x), loads::TimeFunction(y), loads::TimeFunction(z)};
}
std::array<loads::TimeFunction, 3> constant(const Vec3& a) {
  return vec(fmt::format("{:.17g}", a(0)), fmt::format("{:.17g}", a(1)),
             fmt::format("{:.17g}", a(2)));
}
Vec3 on_directors(const Vec<12>& q, const Vec3& a) {
  return a(0) * q.segment<3>(3) + a(1) * q.segment<3>(6) + a(2) * q.segment<3>(9);
}
}  // namespace

// At any q (on the manifold or not, as q_{n+½}) the follower load is the body load of the turned
// components F = F_J d_J(q), M = M_J d_J(q).
TEST(FollowerBodyLoad, IsTheBodyLoadOfTheTurnedComponents) {
  std::mt19937 g(21);
  const Vec3 X(0.4, -0.1, 0.25);
  const loads::FollowerBodyLoad load(0, X, vec("1+t", "-2", "3*t"), vec("0.5", "t", "-1"));
  const double t = 0.3;
  for (const Vec<12>& q : {Vec<12>(frame_node::make(random_vector(g, 3), random_rotation(g))),
                           Vec<12>(random_vector(g, 12))}) {
    const loads::BodyLoad dead(0, X, constant(on_directors(q, load.local_force(t))),
                               constant(on_directors(q, load.local_moment(t))));
    const Vec<12> f = load.generalized_force(q, t);
    EXPECT_LT((f - dead.generalized_force(q, t)).norm(), 1e-14 * f.norm());
  }
}

// On the manifold (q̇ = P t, directors R), f·q̇ = (R F)·ẋ + (R M)·ω for the force at X and the
// moment: the components are those of the body frame.
TEST(FollowerBodyLoad, VirtualWorkOfTheBodyFrameForceAndMoment) {
  std::mt19937 g(22);
  const Vec3 X(0.2, -0.4, 0.7);
  const loads::FollowerBodyLoad load(0, X, vec("1+t", "2", "-3*t"), vec("0.5", "-t", "2"));
  const double time = 0.7;
  for (int trial = 0; trial < 5; ++trial) {
    const Mat3 R = random_rotation(g);
    const auto q = frame_node::make(random_vector(g, 3), R);
    const VecX tw = random_vector(g, 6);
    const VecX qdot = frame_node::null_space(q) * tw;
    const Vec3 xdot = tw.head<3>() + tw.tail<3>().cross(R * X);
    const double work = load.generalized_force(q, time).dot(qdot);
    EXPECT_NEAR(
        work,
        (R * load.local_force(time)).dot(xdot) + (R * load.local_moment(time)).dot(tw.tail<3>()),
        1e-13);
  }
}

// ∂f/∂q against central differences at random q on the manifold (a body's or beam node's
// configuration) and off it (as q_{n+½}): force at an offset point, moment, and both. f is
// quadratic in q, so central differences are exact but for round-off (measured: relative errors
// 1.0e-11 … 1.8e-11).
TEST(FollowerBodyLoad, DerivativeMatchesFiniteDifferences) {
  std::mt19937 g(23);
  const Vec3 X(0.3, -0.7, 1.1);
  const loads::FollowerBodyLoad force(3, X, vec("2*sin(t)", "-1", "0.5"), std::nullopt);
  const loads::FollowerBodyLoad moment(3, Vec3::Zero(), std::nullopt, vec("1", "-2", "3*t"));
  const loads::FollowerBodyLoad both(3, X, vec("2*sin(t)", "-1", "0.5"), vec("1", "-2", "3*t"));
  const double t = 0.4;
  for (const auto* load : {&force, &moment, &both}) {
    for (const Vec<12>& q : {Vec<12>(frame_node::make(random_vector(g, 3), random_rotation(g))),
                             Vec<12>(random_vector(g, 12, 2.0))}) {
      const MatX K = load->generalized_force_derivative(q, t);
      const MatX fd = central_jacobian(
          [&](const VecX& x) -> VecX { return load->generalized_force(Vec<12>(x), t); }, q);
      EXPECT_GT(fd.norm(), 0.1);
      EXPECT_LT(rel_diff(K, fd), 1e-9);
      // The Load contract's add_tangent: scale · ∂f/∂q added to the dense values.
      MatX values = MatX::Ones(12, 12);
      load->add_tangent(q, t, -0.5, values.data());
      EXPECT_LT(rel_diff(values, MatX::Ones(12, 12) - 0.5 * K), 1e-15);
    }
  }
  EXPECT_TRUE(both.follower());
  EXPECT_TRUE(force.follower()) << "a follower force alone depends on q";
}
