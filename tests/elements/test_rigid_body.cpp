#include <gtest/gtest.h>

#include "isoflex/elements/rigid_body.hpp"
#include "isoflex/math/frame_node.hpp"
#include "support/finite_difference.hpp"

using namespace isoflex;
using namespace isoflex::test;

// Euler tensor of a homogeneous box a × b × c: E₁ = ∫ρ X₁² dV = m a²/12 from the principal moments
// J₁ = m (b² + c²)/12 etc.
TEST(RigidBody, EulerTensorOfABox) {
  const double m = 2.0, a = 0.3, b = 0.5, c = 0.7;
  const Vec3 J(m * (b * b + c * c) / 12, m * (a * a + c * c) / 12, m * (a * a + b * b) / 12);
  const Vec3 E = elements::RigidBody::euler_tensor(J);
  EXPECT_NEAR(E(0), m * a * a / 12, 1e-15);
  EXPECT_NEAR(E(1), m * b * b / 12, 1e-15);
  EXPECT_NEAR(E(2), m * c * c / 12, 1e-15);
}

// ½ q̇ᵀ M q̇ equals ½ m |φ̇|² + ½ ωᵀ J ω for every rigid motion (ω in the body frame: J diagonal).
TEST(RigidBody, KineticEnergyMatchesClassicalForm) {
  std::mt19937 g(11);
  const Vec3 J(1.0, 2.0, 2.5);
  elements::RigidBody body(0, 3.0, J, Vec3::Zero());
  const auto q = frame_node::make(random_vector(g, 3), random_rotation(g));
  const VecX t = random_vector(g, 6);
  const VecX qdot = frame_node::null_space(q) * t;
  const double T = 0.5 * qdot.dot(body.mass() * qdot);
  const Vec3 w_body = frame_node::directors(q).transpose() * t.tail<3>();
  const double T_classic =
      0.5 * 3.0 * t.head<3>().squaredNorm() + 0.5 * w_body.dot(J.asDiagonal() * w_body);
  EXPECT_NEAR(T, T_classic, 1e-13 * T_classic);
}

TEST(RigidBody, GravityGradientAndDiscreteGradient) {
  std::mt19937 g(12);
  elements::RigidBody body(0, 2.0, Vec3(1, 1, 1), Vec3(0, 0, -9.81));
  const VecX qn = random_vector(g, 12), qn1 = random_vector(g, 12);
  auto V = [&](const VecX& q) -> VecX { return VecX::Constant(1, body.potential(q)); };
  EXPECT_LT(rel_diff(body.gradient(qn).transpose(), central_jacobian(V, qn)), 1e-9);
  MatX K;
  const VecX dv = body.discrete_gradient(qn, qn1, &K);
  EXPECT_NEAR(dv.dot(qn1 - qn), body.potential(qn1) - body.potential(qn), 1e-12);
  EXPECT_EQ(K.norm(), 0.0);
  // A rigid translation changes V by −m g·Δφ only; a rotation about φ not at all.
  const auto q = frame_node::make(Vec3(1, 2, 3), random_rotation(g));
  const auto qr = frame_node::update(q, (Vec<6>() << 0, 0, 0, 0.3, -0.2, 0.5).finished());
  EXPECT_NEAR(body.potential(qr), body.potential(q), 1e-14);
}
