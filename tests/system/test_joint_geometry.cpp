// Joint points and axes in body coordinates describe the same joint as global data at t = 0.
#include <gtest/gtest.h>

#include <random>

#include "isoflex/math/rotation.hpp"
#include "isoflex/system/system.hpp"
#include "support/finite_difference.hpp"
#include "support/models.hpp"

using namespace isoflex;
using model::JointType;

namespace {
model::Model two_bodies() {
  model::Model m;
  for (int i = 0; i < 2; ++i) {
    model::Body b;
    b.name = i == 0 ? "a" : "b";
    b.mass = 1.0;
    b.inertia = Vec3(1, 2, 3);
    b.position = Vec3(0.3 + i, -0.2, 0.1 * i);
    b.orientation = rodrigues(Vec3(0.4 + i, -0.7, 0.2 * i));
    m.bodies.push_back(b);
  }
  return m;
}
}  // namespace

TEST(JointGeometry, BodyCoordinatesEqualGlobalData) {
  const Vec3 p(0.8, 0.1, 0.3), axis = Vec3(0.2, -0.5, 1.0).normalized();
  std::mt19937 g(11);
  for (JointType t :
       {JointType::revolute, JointType::point_on_line, JointType::universal, JointType::planar}) {
    model::Model global = two_bodies();
    auto j = test::joint(t, "a", "b", p, axis);
    const Vec3 axis2 = axis.cross(Vec3::UnitX()).normalized();
    if (t == JointType::universal) j.axis2 = axis2;
    global.joints.push_back(j);

    model::Model local = two_bodies();
    const Mat3 RA = local.bodies[0].orientation, RB = local.bodies[1].orientation;
    auto jl = j;
    jl.point.reset();
    jl.point_a = RA.transpose() * (p - local.bodies[0].position);
    jl.axis.reset();
    jl.axis_a = RA.transpose() * axis;
    if (t == JointType::universal) {
      jl.axis2.reset();
      jl.axis2_b = RB.transpose() * axis2;
    }
    local.joints.push_back(jl);

    const auto sg = system::System::compile(global), sl = system::System::compile(local);
    for (int trial = 0; trial < 3; ++trial) {
      const VecX q = sg.q0() + test::random_vector(g, sg.n(), 0.2);
      EXPECT_LT((sg.constraints(q, 0.0) - sl.constraints(q, 0.0)).norm(), 1e-13)
          << model::to_string(t);
      EXPECT_LT(MatX(sg.jacobian(q) - sl.jacobian(q)).norm(), 1e-13) << model::to_string(t);
    }
  }
}

TEST(JointGeometry, PointOfBodyBGivesTheCoincidentPoint) {
  const Vec3 p(0.8, 0.1, 0.3);
  model::Model global = two_bodies(), local = two_bodies();
  global.joints.push_back(test::joint(JointType::spherical, "a", "b", p));
  auto jl = test::joint(JointType::spherical, "a", "b", p);
  jl.point.reset();
  jl.point_b = local.bodies[1].orientation.transpose() * (p - local.bodies[1].position);
  local.joints.push_back(jl);
  const auto sg = system::System::compile(global), sl = system::System::compile(local);
  std::mt19937 g(5);
  const VecX q = sg.q0() + test::random_vector(g, sg.n(), 0.2);
  EXPECT_LT((sg.constraints(q, 0.0) - sl.constraints(q, 0.0)).norm(), 1e-13);
}

TEST(JointGeometry, NonPerpendicularAxesInBodyCoordinatesAreRejected) {
  model::Model m = two_bodies();
  auto j = test::joint(JointType::universal, "a", "b", Vec3::Zero());
  j.axis.reset();
  j.axis_a = Vec3::UnitX();
  j.axis2_b = m.bodies[1].orientation.transpose() * m.bodies[0].orientation * Vec3::UnitX();
  m.joints.push_back(j);
  try {
    system::System::compile(m);
    FAIL() << "expected a CompileError";
  } catch (const system::CompileError& e) {
    EXPECT_NE(std::string(e.what()).find("axis2 must be perpendicular to axis at t = 0"),
              std::string::npos)
        << e.what();
  }
}
