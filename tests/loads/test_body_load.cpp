#include <gtest/gtest.h>

#include "isoflex/loads/body_load.hpp"
#include "isoflex/math/frame_node.hpp"
#include "support/finite_difference.hpp"

using namespace isoflex;
using namespace isoflex::test;

namespace {
std::array<loads::TimeFunction, 3> vec(const char* x, const char* y, const char* z) {
  return {loads::TimeFunction(std::string(x)), loads::TimeFunction(std::string(y)),
          loads::TimeFunction(std::string(z))};
}
}  // namespace

// Virtual work of the generalized force on an admissible velocity q̇ = P t equals F·ẋ + M·ω
// (force at body point X, moment M) on the constraint manifold.
TEST(BodyLoad, VirtualWorkOfForceAndMoment) {
  std::mt19937 g(13);
  const Vec3 X(0.2, -0.4, 0.7);
  loads::BodyLoad load(0, X, vec("1+t", "2", "-3*t"), vec("0.5", "-t", "2"));
  const auto q = frame_node::make(random_vector(g, 3), random_rotation(g));
  const VecX t = random_vector(g, 6);
  const double time = 0.7;
  const VecX qdot = frame_node::null_space(q) * t;
  const Vec3 xdot = t.head<3>() + t.tail<3>().cross(frame_node::directors(q) * X);
  const double work = load.generalized_force(q, time).dot(qdot);
  EXPECT_NEAR(work, load.force(time).dot(xdot) + load.moment(time).dot(t.tail<3>()), 1e-13);
}

TEST(BodyLoad, DerivativeMatchesFiniteDifferences) {
  std::mt19937 g(14);
  loads::BodyLoad load(0, Vec3(0.1, 0.2, 0.3), vec("sin(t)", "0", "1"), vec("1", "2", "3*t"));
  const VecX q = random_vector(g, 12);
  auto f = [&](const VecX& x) -> VecX { return load.generalized_force(x, 0.4); };
  EXPECT_LT(rel_diff(load.generalized_force_derivative(0.4), central_jacobian(f, q)), 1e-9);
}
