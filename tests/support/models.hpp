#pragma once
// Small models built in C++ for tests (the same mechanisms as examples/).
#include <cmath>
#include <string>

#include "isoflex/math/rotation.hpp"
#include "isoflex/model/model.hpp"

namespace isoflex::test {

// DNSM-III style heavy top: tip on a spherical joint at the origin, centre of mass 1 from the tip.
inline model::Model heavy_top(model::Formulation f = model::Formulation::reparametrized) {
  model::Model m;
  m.name = "heavy_top";
  m.gravity = Vec3(0, 0, -9.81);
  model::Body b;
  b.name = "top";
  b.mass = 1.0;
  b.inertia = Vec3(0.625, 0.625, 0.25);
  b.orientation = rodrigues(Vec3(0.5, 0, 0));
  b.position = b.orientation.col(2);
  b.angular_velocity = 50.0 * b.orientation.col(2);
  b.velocity = b.angular_velocity.cross(b.position);
  m.bodies.push_back(b);
  model::Joint j;
  j.name = "tip";
  j.type = model::JointType::spherical;
  j.body_b = "top";
  j.point = Vec3::Zero();
  m.joints.push_back(j);
  m.solver.formulation = f;
  m.solver.dt = 0.01;
  return m;
}

inline model::Body rod(const std::string& name, const Vec3& from, const Vec3& to) {
  model::Body b;
  b.name = name;
  b.mass = 1.0;
  const double L = (to - from).norm();
  b.inertia = Vec3(0.01, L * L / 12.0, L * L / 12.0);
  const Vec3 d1 = (to - from) / L, d3 = Vec3::UnitZ();
  b.orientation << d1, d3.cross(d1), d3;
  b.position = 0.5 * (from + to);
  return b;
}

inline model::Joint joint(model::JointType t, const std::string& a, const std::string& b,
                          const Vec3& p, std::optional<Vec3> axis = std::nullopt) {
  model::Joint j;
  j.type = t;
  j.body_a = a;
  j.body_b = b;
  j.point = p;
  j.axis = axis;
  j.name = a + "-" + b;
  return j;
}

// Planar four-bar of four revolute joints (closed loop, three redundant rows in 3D).
inline model::Model four_bar(model::Formulation f = model::Formulation::reparametrized) {
  model::Model m;
  m.name = "four_bar";
  m.gravity = Vec3(0, -9.81, 0);
  const Vec3 O(0, 0, 0), A(0, 1, 0), B(3, 1.5, 0), C(3, 0, 0), z = Vec3::UnitZ();
  m.bodies = {rod("crank", O, A), rod("coupler", A, B), rod("rocker", C, B)};
  m.bodies[0].angular_velocity = Vec3(0, 0, 2.0);
  m.bodies[0].velocity = m.bodies[0].angular_velocity.cross(m.bodies[0].position);
  using T = model::JointType;
  m.joints = {
      joint(T::revolute, "ground", "crank", O, z), joint(T::revolute, "crank", "coupler", A, z),
      joint(T::revolute, "ground", "rocker", C, z), joint(T::revolute, "coupler", "rocker", B, z)};
  m.solver.formulation = f;
  m.solver.dt = 0.01;
  return m;
}

// A free body spinning near its intermediate principal axis (Dzhanibekov effect).
inline model::Model free_body_flip(model::Formulation f = model::Formulation::reparametrized) {
  model::Model m;
  m.name = "free_body_flip";
  model::Body b;
  b.name = "body";
  b.mass = 2.0;
  b.inertia = Vec3(1.0, 2.0, 3.0);
  b.position = Vec3(0.3, -0.2, 0.1);
  b.velocity = Vec3(0.1, 0.2, -0.05);
  b.angular_velocity = Vec3(0.02, 5.0, 0.02);
  m.bodies.push_back(b);
  m.solver.formulation = f;
  m.solver.dt = 0.01;
  return m;
}

}  // namespace isoflex::test

namespace isoflex::test {
// A chain of n slender bodies on spherical joints hanging from the ground, initially along +x.
inline model::Model chain(int n, model::Formulation f = model::Formulation::reparametrized) {
  model::Model m;
  m.name = "chain";
  m.gravity = Vec3(0, 0, -9.81);
  for (int i = 0; i < n; ++i) {
    m.bodies.push_back(rod("b" + std::to_string(i), Vec3(i, 0, 0), Vec3(i + 1, 0, 0)));
    m.joints.push_back(joint(model::JointType::spherical,
                             i == 0 ? "ground" : "b" + std::to_string(i - 1),
                             "b" + std::to_string(i), Vec3(i, 0, 0)));
  }
  m.bodies[0].angular_velocity = Vec3(0, 0, 0.5);
  m.bodies[0].velocity = Vec3(0, 0.25, 0);
  m.solver.formulation = f;
  m.solver.dt = 0.01;
  return m;
}
// A cantilever along x (L = 12, `elements` elements, the section of examples/beam_roll_up) clamped
// at beam[0] by a fixed joint to the ground, a tip force `force` (three time functions) at
// beam[elements], in a linear static analysis; `more` is appended (springs, probes).
inline std::string cantilever_yaml(int elements, const std::string& force,
                                   const std::string& more = "") {
  const std::string tip = "\"beam[" + std::to_string(elements) + "]\"";
  return R"(name: cantilever
solver: {analysis: static, dt: 1, t_end: 1, linear: true}
beams:
  - name: beam
    points: [[0, 0, 0], [12, 0, 0]]
    elements: )" +
         std::to_string(elements) + R"(
    d1: [0, 1, 0]
    section: {EA: 1.2e5, GA: 6.0e4, EI1: 100, EI2: 1.0e4, GJ: 187.4, A_rho: 0.1, M_rho1: 1e-2,
              M_rho2: 1e-4}
joints:
  - {name: clamp, type: fixed, body_a: ground, body_b: "beam[0]"}
loads:
  - {body: )" +
         tip + ", force: " + force + R"(}
probes:
  - {name: tip, body: )" +
         tip + "}\n" + more;
}

}  // namespace isoflex::test
